"""``python -m gjkd serve [flags]``: the gjkd server, as ``gjkd serve``."""

from __future__ import annotations

import sys
from typing import Optional, Sequence

from . import _native

USAGE = """usage: python -m gjkd serve [FLAGS]

Runs the gjkd distance server until SIGINT or SIGTERM; the flags are those of
`gjkd serve` (`python -m gjkd serve --help` lists them)."""


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Runs the command line ``argv`` (default ``sys.argv[1:]``); returns the
    exit status."""
    args = list(sys.argv[1:] if argv is None else argv)
    if not args or args[0] in ("-h", "--help", "help"):
        print(USAGE)
        return 0 if args else 2
    if args[0] != "serve":
        print(f"unknown command {args[0]!r}\n\n{USAGE}", file=sys.stderr)
        return 2
    return _native.serve(args[1:])


if __name__ == "__main__":
    sys.exit(main())

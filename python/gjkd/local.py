"""``gjkd.local``: distances between shapes and robots held in this
process, with no server. :class:`Local` has the methods of
:class:`gjkd.Client` (robots and scene questions included) and answers bit
for bit what a server answers for the same inputs."""

from ._native import Local

__all__ = ["Local"]

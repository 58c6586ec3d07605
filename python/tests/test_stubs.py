"""The type stubs describe the native module as it is, and type-check."""

from __future__ import annotations

import pathlib
import subprocess
import sys

import pytest

HERE = pathlib.Path(__file__).resolve().parent


def run(*args: str) -> subprocess.CompletedProcess[str]:
    # Away from the source tree, so that the installed package is checked.
    return subprocess.run(
        [sys.executable, "-m", *args], capture_output=True, text=True, cwd=HERE.parent / "tests"
    )


def test_stubs_match_the_native_module() -> None:
    pytest.importorskip("mypy", reason="run-tests.sh installs mypy")
    result = run("mypy.stubtest", "gjkd._native")
    assert result.returncode == 0, result.stdout + result.stderr


def test_package_type_checks() -> None:
    pytest.importorskip("mypy", reason="run-tests.sh installs mypy")
    result = run(
        "mypy", "--config-file", str(HERE.parent / "pyproject.toml"), str(HERE.parent / "gjkd")
    )
    assert result.returncode == 0, result.stdout + result.stderr

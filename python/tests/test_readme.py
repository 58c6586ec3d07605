"""The README's Python examples run as written."""

from __future__ import annotations

import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
README = ROOT / "README.md"


def section_code(title: str) -> str:
    text = README.read_text(encoding="utf-8")
    section = text.split(f"\n## {title}\n", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 1, f"the {title} section has one example"
    return blocks[0]


def python_section_code() -> str:
    return section_code("Python")


def test_readme_example_runs() -> None:
    code = python_section_code()
    exec(compile(code, str(README), "exec"), {"__name__": "readme_example"})


def test_readme_signed_rows_example_runs() -> None:
    code = section_code("Signed distance in batches and scene rows")
    exec(compile(code, str(README), "exec"), {"__name__": "readme_signed_rows_example"})


def test_readme_ompl_example_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip(
        "ompl", reason="OMPL's Python bindings are not installed (pip install ompl)"
    )
    code = section_code("Planning with OMPL")
    # Its paths are relative to the repository's root, where it says to run it.
    monkeypatch.chdir(ROOT)
    exec(compile(code, str(README), "exec"), {"__name__": "readme_ompl_example"})


def test_readme_signed_distance_example_runs() -> None:
    code = section_code("Signed distance")
    exec(compile(code, str(README), "exec"), {"__name__": "readme_signed_example"})


def test_readme_gradients_example_runs() -> None:
    code = section_code("Gradients")
    exec(compile(code, str(README), "exec"), {"__name__": "readme_gradients_example"})

"""The benchmark's problems: MotionBenchMaker's Panda scenes as gjkd scene
files (``problems/``, written by ``problems/convert.py``), read here for the
checkers that are not a gjkd server, and the vendored Panda they are planned
for."""

from __future__ import annotations

import dataclasses
import json
import pathlib
from typing import Any

import numpy as np

try:
    import tomllib
except ImportError:  # Python < 3.11
    import tomli as tomllib  # type: ignore[no-redef]

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
PROBLEMS = HERE / "problems"
PACKAGES = ROOT / "model" / "tests" / "data"
PANDA_URDF = (
    PACKAGES / "example-robot-data" / "robots" / "panda_description" / "urdf" / "panda.urdf"
)
PANDA_SRDF = PROBLEMS / "panda.srdf"


@dataclasses.dataclass
class Obstacle:
    """One object of a scene file: a box (``half_extents``), a cylinder
    (``radius``, ``length``, about z) or a sphere (``radius``), at
    ``translation`` and ``quaternion`` ``[x, y, z, w]``."""

    name: str
    kind: str
    size: dict[str, Any]
    translation: np.ndarray
    quaternion: np.ndarray

    @property
    def pose(self) -> list[float]:
        """``[x, y, z, qx, qy, qz, qw]``."""
        return [*self.translation.tolist(), *self.quaternion.tolist()]


@dataclasses.dataclass
class Problem:
    """A start and a goal (the arm's seven joints) in a scene file."""

    scene: str
    index: int
    scene_file: pathlib.Path
    start: np.ndarray
    goal: np.ndarray


def panda_urdf(finger_opening: float) -> str:
    """The vendored Panda's URDF text with its fingers' upper limit raised to
    ``finger_opening``: MotionBenchMaker's requests (and VAMP's Panda) open
    the fingers to 0.065, beyond franka_description's 0.04, and some goals
    straddle an object with them. Its meshes are ``package://`` URLs, found
    in :data:`PACKAGES`."""
    text = PANDA_URDF.read_text()
    old = 'lower="0.0" upper="0.04"'
    if text.count(old) != 2:
        raise ValueError(f"{PANDA_URDF}: expected two finger limits {old!r}")
    return text.replace(old, f'lower="0.0" upper="{max(finger_opening, 0.04)!r}"')


def read_scene(path: pathlib.Path) -> list[Obstacle]:
    """The objects of a scene file as ``convert.py`` writes them."""
    doc = tomllib.loads(path.read_text())
    out = []
    for o in doc["object"]:
        pose = o.get("pose", {})
        q = np.array(pose.get("quaternion", [0.0, 0.0, 0.0, 1.0]), dtype=np.float64)
        size = {k: v for k, v in o.items() if k not in ("name", "type", "pose")}
        out.append(
            Obstacle(
                o["name"],
                o["type"],
                size,
                np.array(pose.get("translation", [0.0, 0.0, 0.0]), dtype=np.float64),
                q / np.linalg.norm(q),
            )
        )
    return out


def load_problems(scenes: list[str], per_scene: int) -> tuple[list[Problem], dict[str, Any]]:
    """The first ``per_scene`` problems of each of ``scenes``, and the
    joints planned and held fixed (``{"joints": [...], "fixed": {...}}``)."""
    doc = json.loads((PROBLEMS / "problems.json").read_text())
    problems = [
        Problem(
            scene,
            p["index"],
            PROBLEMS / p["scene"],
            np.array(p["start"], dtype=np.float64),
            np.array(p["goal"], dtype=np.float64),
        )
        for scene in scenes
        for p in doc["scenes"][scene][:per_scene]
    ]
    return problems, {"joints": doc["joints"], "fixed": doc["fixed"]}

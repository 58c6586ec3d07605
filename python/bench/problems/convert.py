"""Converts MotionBenchMaker's Panda problems, as VAMP ships them, into gjkd
scene files and start/goal configurations.

VAMP's ``resources/panda/problems.tar.bz2`` holds, per problem, MoveIt's
``sceneNNNN.yaml`` (collision objects: boxes, cylinders and spheres, each
one primitive at a pose, in the robot's base frame) and ``requestNNNN.yaml``
(a start state and a joint goal); ``resources/problem_tar_to_pkl_json.py``
reads them the same way. This writes, under this folder:

- ``SCENE/NNNN.toml``: the problem's obstacles as a gjkd scene file
  (``docs/scene-files.md``; a box's dimensions are full sizes, a cylinder's
  ``[length, radius]`` about its z axis, as MoveIt's primitives);
- ``problems.json``: per scene, each problem's index, scene file, start and
  goal (the seven arm joints, in the URDF's order), and the finger opening
  held fixed while planning (0.065, as every start state has it);
- ``panda.srdf``: the allowed collision matrix the problems were made with
  (identical in every scene file), as ``disable_collisions`` pairs.

Run once (needs PyYAML)::

    python python/bench/problems/convert.py problems.tar.bz2
"""

from __future__ import annotations

import argparse
import io
import json
import pathlib
import re
import tarfile
from typing import Any

import yaml

HERE = pathlib.Path(__file__).resolve().parent
SCENES = ["box", "cage", "table_pick", "table_under_pick", "bookshelf_small"]
ARM = [f"panda_joint{i}" for i in range(1, 8)]
FINGER = "panda_finger_joint1"
# Every request's start state opens the fingers to 0.065 (VAMP's Panda
# fixes them there): beyond the vendored URDF's limit of 0.04, which the
# benchmark raises to it (scenes.py), since at 0.04 the fingers close onto
# the objects some goals straddle.
FINGER_OPENING = 0.065


def quat_mul(a: list[float], b: list[float]) -> list[float]:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]


def rotate(q: list[float], v: list[float]) -> list[float]:
    x, y, z, w = q
    r = quat_mul(quat_mul(q, [v[0], v[1], v[2], 0.0]), [-x, -y, -z, w])
    return r[:3]


def compose(parent: dict[str, Any], child: dict[str, Any]) -> tuple[list[float], list[float]]:
    """The pose ``parent * child`` of MoveIt's object and primitive poses."""
    pq, cq = list(parent["orientation"]), list(child["orientation"])
    t = rotate(pq, list(child["position"]))
    return [a + b for a, b in zip(parent["position"], t)], quat_mul(pq, cq)


IDENTITY = {"position": [0.0, 0.0, 0.0], "orientation": [0.0, 0.0, 0.0, 1.0]}


def fmt(v: list[float]) -> str:
    return "[" + ", ".join(repr(float(x)) for x in v) + "]"


def scene_toml(data: dict[str, Any], title: str) -> str:
    out = [f"# {title}: MotionBenchMaker's scene as VAMP ships it (convert.py)."]
    for co in data["world"]["collision_objects"]:
        (prim,) = co["primitives"]
        (ppose,) = co["primitive_poses"]
        t, q = compose(co.get("pose", IDENTITY), ppose)
        dims = prim["dimensions"]
        out += ["", "[[object]]", f'name = "{co["id"]}"']
        if prim["type"] == "box":
            out += ['type = "box"', f"half_extents = {fmt([d / 2 for d in dims])}"]
        elif prim["type"] == "cylinder":
            out += ['type = "cylinder"', f"radius = {dims[1]!r}", f"length = {dims[0]!r}"]
        elif prim["type"] == "sphere":
            out += ['type = "sphere"', f"radius = {dims[0]!r}"]
        else:
            raise ValueError(f"{title}: unknown primitive {prim['type']!r}")
        out.append(f"pose = {{ translation = {fmt(t)}, quaternion = {fmt(q)} }}")
    return "\n".join(out) + "\n"


def srdf(acm: dict[str, Any]) -> str:
    names = acm["entry_names"]
    lines = ['<?xml version="1.0"?>', '<robot name="panda">']
    for i, a in enumerate(names):
        for j in range(i + 1, len(names)):
            if acm["entry_values"][i][j]:
                b = names[j]
                lines.append(f'  <disable_collisions link1="{a}" link2="{b}" reason="MBM"/>')
    return "\n".join(lines + ["</robot>"]) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("archive", type=pathlib.Path, help="VAMP's problems.tar.bz2")
    args = parser.parse_args()
    files: dict[tuple[str, str, int], dict[str, Any]] = {}
    with tarfile.open(args.archive, "r:bz2") as tar:
        for member in tar.getmembers():
            parts = member.name.split("/")
            if not member.isfile() or len(parts) != 3:
                continue
            scene = parts[1].removesuffix("_panda")
            if scene not in SCENES:
                continue
            kind = "scene" if parts[2].startswith("scene") else "request"
            index = int(re.findall(r"\d+", parts[2])[0])
            f = tar.extractfile(member)
            assert f is not None
            files[(scene, kind, index)] = yaml.safe_load(io.TextIOWrapper(f, encoding="utf-8"))
    acms = set()
    problems: dict[str, list[dict[str, Any]]] = {}
    for scene in SCENES:
        (HERE / scene).mkdir(exist_ok=True)
        indices = sorted(i for (s, k, i) in files if s == scene and k == "scene")
        problems[scene] = []
        for index in indices:
            data, req = files[(scene, "scene", index)], files[(scene, "request", index)]
            acms.add(json.dumps(data["allowed_collision_matrix"], sort_keys=True))
            rel = f"{scene}/{index:04d}.toml"
            (HERE / rel).write_text(scene_toml(data, f"{scene} {index}"))
            js = req["start_state"]["joint_state"]
            start = [js["position"][js["name"].index(j)] for j in ARM]
            if js["position"][js["name"].index(FINGER)] != FINGER_OPENING:
                raise ValueError(f"{rel}: the fingers are not at {FINGER_OPENING}")
            goals = {
                c["joint_name"]: c["position"]
                for c in req["goal_constraints"][0]["joint_constraints"]
            }
            problems[scene].append(
                {"index": index, "scene": rel, "start": start, "goal": [goals[j] for j in ARM]}
            )
    if len(acms) != 1:
        raise ValueError(f"the scenes hold {len(acms)} different allowed collision matrices")
    (HERE / "panda.srdf").write_text(srdf(json.loads(acms.pop())))
    doc = {
        "source": "VAMP resources/panda/problems.tar.bz2 (MotionBenchMaker)",
        "joints": ARM,
        "fixed": {FINGER: FINGER_OPENING},
        "scenes": problems,
    }
    (HERE / "problems.json").write_text(json.dumps(doc, indent=1) + "\n")
    print({s: len(p) for s, p in problems.items()})


if __name__ == "__main__":
    main()

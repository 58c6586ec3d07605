"""Answers with known values, from a server and from gjkd.Local."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

import gjkd

TOL = 1e-9


def quat_about_z(angle: float) -> list[float]:
    return [0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2)]


def pose(x: float, y: float, z: float, q: Any = (0.0, 0.0, 0.0, 1.0)) -> list[float]:
    return [x, y, z, *q]


def matrix(x: float, y: float, z: float, angle_z: float = 0.0) -> np.ndarray:
    c, s = math.cos(angle_z), math.sin(angle_z)
    m = np.eye(4)
    m[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
    m[:3, 3] = [x, y, z]
    return m


def test_sphere_sphere(objects: Any) -> None:
    a = objects.register_sphere(0.5)
    b = objects.register_sphere(0.25, pose=pose(1.0, 2.0, 2.0))
    # Centres 3 apart: 3 - 0.75.
    answer = objects.distance(a, b)
    assert abs(answer.distance - 2.25) < TOL
    assert answer.lower <= 2.25 + TOL and answer.upper >= 2.25 - TOL
    assert np.allclose(answer.normal, [1 / 3, 2 / 3, 2 / 3], atol=TOL)
    assert np.allclose(answer.point_a, [0.5 / 3, 1 / 3, 1 / 3], atol=TOL)
    assert np.allclose(answer.point_b, [1 - 0.25 / 3, 2 - 0.5 / 3, 2 - 0.5 / 3], atol=TOL)
    assert answer.status == gjkd.Status.CONVERGED

    gaps = np.array([0.1, 1.0, 10.0, 1e3])
    poses_b = np.zeros((4, 7))
    poses_b[:, 0] = 0.75 + gaps
    poses_b[:, 6] = 1.0
    result = objects.distances(np.array([[a, b]] * 4), poses_b=poses_b)
    assert np.all(result.error == 0)
    assert np.allclose(result.distance, gaps, rtol=0, atol=TOL * 1e3)
    assert np.all(result.lower <= result.distance) and np.all(result.distance <= result.upper)
    assert np.allclose(result.point_a, [[0.5, 0, 0]] * 4, atol=TOL)
    assert np.allclose(result.normal, [[1, 0, 0]] * 4, atol=TOL)


def test_box_sphere_along_each_axis(objects: Any) -> None:
    half = [1.0, 2.0, 3.0]
    box = objects.register_box(half)
    ball = objects.register_sphere(0.5)
    n = 6
    poses_b = np.zeros((n, 7))
    poses_b[:, 6] = 1.0
    expected = np.empty(n)
    for i, (axis, sign) in enumerate((a, s) for a in range(3) for s in (1, -1)):
        poses_b[i, axis] = sign * (half[axis] + 0.5 + 1.25 * (i + 1))
        expected[i] = 1.25 * (i + 1)
    result = objects.distances(np.array([[box, ball]] * n), poses_b=poses_b)
    assert np.all(result.error == 0)
    assert np.max(np.abs(result.distance - expected)) < TOL
    for i in range(n):
        axis = i // 2
        sign = 1 if i % 2 == 0 else -1
        want_a = np.zeros(3)
        want_a[axis] = sign * half[axis]
        assert np.allclose(result.point_a[i], want_a, atol=TOL)
        assert np.allclose(result.normal[i], np.sign(want_a), atol=TOL)


def test_box_sphere_with_rotated_box_as_matrices(objects: Any) -> None:
    box = objects.register_box([1.0, 2.0, 3.0])
    ball = objects.register_sphere(0.5)
    # The box turned a quarter about z: its y half extent now lies along x.
    poses_a = np.stack([matrix(0, 0, 0, math.pi / 2)] * 2)
    poses_b = np.stack([matrix(4.0, 0, 0), matrix(0, 3.0, 0)])
    result = objects.distances([[box, ball], [box, ball]], poses_a, poses_b)
    assert np.all(result.error == 0)
    assert np.max(np.abs(result.distance - [4.0 - 2.0 - 0.5, 3.0 - 1.0 - 0.5])) < TOL


def test_parallel_capsules(objects: Any) -> None:
    a = objects.register_capsule([-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.1)
    b = objects.register_capsule([-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.2)
    for d, shift in ((2.0, 0.5), (0.5, -1.5), (5.0, 0.0)):
        q = quat_about_z(0.3)
        rot = np.array(
            [[math.cos(0.3), -math.sin(0.3), 0], [math.sin(0.3), math.cos(0.3), 0], [0, 0, 1]]
        )
        # Both turned alike: still parallel, d apart across their axis.
        t_b = rot @ np.array([shift, d, 0.0])
        answer = objects.distance(a, b, pose(0, 0, 0, q), pose(*t_b, q))
        assert abs(answer.distance - (d - 0.3)) < TOL
        assert abs(np.dot(answer.normal, rot @ [0, 1, 0]) - 1.0) < TOL


def test_set_poses_then_stored_poses(objects: Any) -> None:
    balls = [objects.register_sphere(0.5) for _ in range(3)]
    objects.set_poses(np.array(balls), np.array([pose(0, 0, 0), pose(2, 0, 0), pose(0, 5, 0)]))
    result = objects.distances(np.array([[balls[0], balls[1]], [balls[0], balls[2]]]))
    assert np.max(np.abs(result.distance - [1.0, 4.0])) < TOL
    objects.set_poses(balls[1:], np.stack([matrix(0, 0, 3), matrix(0, 0, -7)]))
    result = objects.distances(np.array([[balls[0], balls[1]], [balls[0], balls[2]]]))
    assert np.max(np.abs(result.distance - [2.0, 6.0])) < TOL


def test_compound_names_its_piece(objects: Any) -> None:
    ball = gjkd.Shape.sphere(0.3)
    bar = gjkd.Shape.capsule([-1, 0, 0], [1, 0, 0], 0.05)
    dumbbell = objects.register_compound(
        [(pose(-1, 0, 0), ball), (pose(0, 0, 0), bar), (pose(1, 0, 0), ball)]
    )
    target = objects.register_sphere(0.2, pose=pose(4.0, 0.0, 0.0))
    answer = objects.distance(dumbbell, target)
    assert abs(answer.distance - (4.0 - 1.0 - 0.3 - 0.2)) < TOL
    assert answer.pieces == (2, 0)


def test_named_objects_are_found(objects: Any) -> None:
    name = f"crate-{id(objects)}"
    crate = objects.register_box([0.5, 0.5, 0.5], name=name)
    assert objects.lookup(name) == crate
    objects.remove(crate)
    with pytest.raises(gjkd.NotFound) as e:
        objects.lookup(name)
    assert e.value.code == gjkd.ErrorCode.UNKNOWN_NAME


def test_margin_and_warm_start(objects: Any) -> None:
    a = objects.register_sphere(1.0)
    b = objects.register_sphere(1.0, pose=pose(10.0, 0.0, 0.0))
    # Two balls converge at once: the margin may or may not stop earlier,
    # but the answer must say which side of it the distance lies.
    far = objects.distance(a, b, margin=1.0)
    assert far.status in (gjkd.Status.FARTHER, gjkd.Status.CONVERGED) and far.lower > 1.0
    close = objects.distance(a, b, margin=100.0)
    assert close.status in (gjkd.Status.CLOSER, gjkd.Status.CONVERGED) and close.upper <= 100.0
    pairs = np.array([[a, b]])
    first = objects.distances(pairs, warm_start=False)
    assert not first.warm_started[0]
    objects.distances(pairs)
    again = objects.distances(pairs)
    assert again.warm_started[0]
    assert abs(again.distance[0] - 8.0) < TOL


def test_out_is_reused(objects: Any) -> None:
    a = objects.register_sphere(1.0)
    b = objects.register_sphere(1.0, pose=pose(5.0, 0.0, 0.0))
    out = gjkd.Distances(2)
    back = objects.distances([[a, b], [b, a]], out=out)
    assert back is out
    assert np.allclose(out.distance, [3.0, 3.0], atol=TOL)
    with pytest.raises(gjkd.InvalidInput) as e:
        objects.distances([[a, b]], out=out)
    assert e.value.field == "out"


def test_result_as_dict(objects: Any) -> None:
    a = objects.register_sphere(1.0)
    d = objects.distances([[a, a]]).as_dict()
    assert set(d) == {
        "distance", "lower", "upper", "penetration", "point_a", "point_b", "normal",
        "status", "iterations", "pieces", "error", "warm_started",
        "signed_distance", "signed_lower", "signed_upper",
        "gradient", "gradient_flags", "gradient_error",
    }  # fmt: skip
    assert d["pieces"].shape == (1, 2) and d["point_a"].shape == (1, 3)
    assert d["distance"][0] == 0.0 and d["penetration"][0] > 1.9

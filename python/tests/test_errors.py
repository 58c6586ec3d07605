"""Every bad input gets its own error, changes nothing, and the server keeps
serving. Run on a server's Client and on gjkd.Local alike."""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np
import pytest

import gjkd

NAN = math.nan
IDENTITY = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]


def raises(
    kind: type,
    call: Callable[[], Any],
    *,
    code: "gjkd.ErrorCode | None" = None,
    field: "str | None" = None,
    index: "int | None" = None,
) -> gjkd.Error:
    with pytest.raises(kind) as e:
        call()
    err = e.value
    assert isinstance(err, gjkd.Error)
    assert err.code == code, err
    assert err.field == field, err
    assert err.index == index, err
    return err


@pytest.fixture()
def pair(objects: Any) -> tuple[int, int]:
    a = objects.register_sphere(0.5)
    b = objects.register_box([1.0, 1.0, 1.0], pose=[4.0, 0, 0, 0, 0, 0, 1])
    return a, b


def still_serves(objects: Any, pair: tuple[int, int]) -> None:
    a, b = pair
    assert abs(objects.distance(a, b).distance - 2.5) < 1e-9


def test_nan_pose(objects: Any, pair: tuple[int, int]) -> None:
    a, b = pair
    bad = [NAN, 0, 0, 0, 0, 0, 1]
    poses = np.array([IDENTITY, bad, IDENTITY])
    result = objects.distances(np.array([pair] * 3), poses_a=poses)
    assert list(result.error) == [0, gjkd.ErrorCode.NON_FINITE_POSE, 0]
    assert result.distance[1] == 0.0 and result.status[1] == gjkd.Status.NONE
    assert abs(result.distance[2] - 2.5) < 1e-9
    code = gjkd.ErrorCode.NON_FINITE_POSE
    raises(gjkd.InvalidInput, lambda: objects.distance(a, b, bad), code=code, field="pose")
    raises(
        gjkd.InvalidInput,
        lambda: objects.set_poses([a, b], np.array([IDENTITY, bad])),
        code=code,
        field="poses",
        index=1,
    )
    raises(gjkd.InvalidInput, lambda: objects.set_pose(a, bad), code=code, field="pose")
    inf_matrix = np.eye(4)
    inf_matrix[0, 3] = math.inf
    raises(gjkd.InvalidInput, lambda: objects.set_pose(a, inf_matrix), code=code, field="pose")
    raises(
        gjkd.InvalidInput,
        lambda: objects.register_sphere(1.0, pose=bad),
        code=code,
        field="pose",
    )
    # Nothing changed: the stored poses are the old ones.
    still_serves(objects, pair)


def test_non_unit_quaternion(objects: Any, pair: tuple[int, int]) -> None:
    a, b = pair
    bad = [0, 0, 0, 0, 0, 0.5, 0.5]
    code = gjkd.ErrorCode.BAD_QUATERNION
    result = objects.distances(np.array([pair, pair]), poses_b=np.array([bad, IDENTITY]))
    assert list(result.error) == [code, 0]
    raises(gjkd.InvalidInput, lambda: objects.distance(a, b, None, bad), code=code, field="pose")
    raises(
        gjkd.InvalidInput,
        lambda: objects.set_poses([b], np.array([bad])),
        code=code,
        field="poses",
        index=0,
    )
    sheared = np.eye(4)
    sheared[0, 1] = 0.5
    result = objects.distances([pair], poses_a=sheared[None])
    assert list(result.error) == [code]
    raises(gjkd.InvalidInput, lambda: objects.set_pose(a, sheared), code=code, field="pose")
    mirrored = np.diag([-1.0, 1.0, 1.0, 1.0])
    raises(gjkd.InvalidInput, lambda: objects.set_pose(a, mirrored), code=code, field="pose")
    # Off unit length by less than 1e-6 is taken (and normalised).
    objects.set_pose(a, [0, 0, 0, 0, 0, 0, 1 + 1e-8])
    still_serves(objects, pair)


@pytest.mark.parametrize(
    "pairs, field",
    [
        (np.zeros((3, 3), dtype=np.uint64), "pairs"),
        (np.zeros(4, dtype=np.uint64), "pairs"),
        (np.zeros((2, 2), dtype=np.float64), "pairs"),
        (np.zeros((2, 2), dtype=np.int32), "pairs"),
        (np.array([[1, -2]], dtype=np.int64), "pairs"),
        ([["a", "b"]], "pairs"),
    ],
)
def test_bad_pairs(objects: Any, pair: tuple[int, int], pairs: Any, field: str) -> None:
    negative = isinstance(pairs, np.ndarray) and pairs.dtype == np.int64
    raises(
        gjkd.InvalidInput,
        lambda: objects.distances(pairs),
        field=field,
        index=0 if negative else None,
    )
    still_serves(objects, pair)


@pytest.mark.parametrize(
    "poses",
    [
        np.zeros((2, 6)),
        np.zeros((2, 3, 3)),
        np.zeros((3, 7)),
        np.zeros((2, 7), dtype=np.float32),
        np.zeros((2, 7), dtype=np.int64),
        np.zeros((2, 4, 4), dtype=object),
        "pose",
    ],
)
def test_bad_pose_arrays(objects: Any, pair: tuple[int, int], poses: Any) -> None:
    pairs = np.array([pair, pair])
    raises(gjkd.InvalidInput, lambda: objects.distances(pairs, poses_a=poses), field="poses_a")
    raises(gjkd.InvalidInput, lambda: objects.distances(pairs, None, poses), field="poses_b")
    raises(gjkd.InvalidInput, lambda: objects.set_poses(list(pair), poses), field="poses")
    still_serves(objects, pair)


def test_bad_single_poses(objects: Any, pair: tuple[int, int]) -> None:
    a, b = pair
    for bad in ([0.0] * 6, np.zeros((3, 4)), np.zeros(7, dtype=np.float32)):
        raises(gjkd.InvalidInput, lambda: objects.distance(a, b, bad), field="pose_a")
        raises(gjkd.InvalidInput, lambda: objects.set_pose(a, bad), field="pose")
        raises(gjkd.InvalidInput, lambda: objects.register_sphere(1.0, pose=bad), field="pose")
    raises(gjkd.InvalidInput, lambda: objects.set_poses([[a]], [IDENTITY]), field="ids")
    still_serves(objects, pair)


def test_unknown_id(objects: Any, pair: tuple[int, int]) -> None:
    a, b = pair
    gone = objects.register_sphere(1.0)
    objects.remove(gone)
    code = gjkd.ErrorCode.UNKNOWN_OBJECT
    result = objects.distances(np.array([[a, gone], pair, [gone, b]]))
    assert list(result.error) == [code, 0, code]
    assert abs(result.distance[1] - 2.5) < 1e-9
    raises(gjkd.NotFound, lambda: objects.distance(a, gone), code=code, field="id")
    raises(gjkd.NotFound, lambda: objects.remove(gone), code=code, field="id")
    raises(
        gjkd.NotFound,
        lambda: objects.set_poses([a, gone], np.array([IDENTITY, IDENTITY])),
        code=code,
        field="ids",
        index=1,
    )
    raises(gjkd.NotFound, lambda: objects.set_pose(gone, IDENTITY), code=code, field="ids")
    still_serves(objects, pair)


def test_bad_geometry(objects: Any, pair: tuple[int, int]) -> None:
    E = gjkd.ErrorCode
    raises(
        gjkd.InvalidInput,
        lambda: objects.register_polytope(np.zeros((0, 3))),
        code=E.EMPTY_VERTICES,
        field="vertices",
    )
    raises(
        gjkd.InvalidInput,
        lambda: objects.register_polytope(np.zeros((4, 2))),
        field="vertices",
    )
    raises(
        gjkd.InvalidInput,
        lambda: objects.register_polytope(np.zeros((4, 3), dtype=np.float32)),
        field="vertices",
    )
    raises(
        gjkd.InvalidInput,
        lambda: objects.register_polytope(np.array([[0.0, NAN, 0.0]])),
        code=E.NON_FINITE_VERTEX,
        field="vertices",
    )
    raises(
        gjkd.InvalidInput,
        lambda: objects.register_sphere(-1.0),
        code=E.INVALID_RADIUS,
        field="radius",
    )
    raises(
        gjkd.InvalidInput,
        lambda: objects.register_box([1.0, -1.0, 1.0]),
        field="half_extents",
    )
    raises(gjkd.InvalidInput, lambda: objects.register_capsule([0, 0], [1, 0, 0], 0.1), field="a")
    raises(
        gjkd.InvalidInput,
        lambda: objects.register_compound([]),
        code=E.EMPTY_COMPOUND,
        field="pieces",
    )
    raises(gjkd.InvalidInput, lambda: objects.register_compound([(IDENTITY, 1.0)]), field="pieces",
           index=0)  # fmt: skip
    ball = gjkd.Shape.sphere(0.1)
    raises(
        gjkd.InvalidInput,
        lambda: objects.register_compound([(IDENTITY, ball)] * 65),
        field="pieces",
    )
    raises(
        gjkd.InvalidInput,
        lambda: objects.register_compound([(IDENTITY, ball), ([NAN] * 7, ball)]),
        code=E.NON_FINITE_POSE,
        field="pieces",
        index=1,
    )
    raises(gjkd.InvalidInput, lambda: objects.register_sphere(1.0, name="x" * 65), field="name")
    still_serves(objects, pair)


def test_taken_name(objects: Any, pair: tuple[int, int]) -> None:
    name = f"taken-{id(objects)}"
    objects.register_sphere(1.0, name=name)
    raises(
        gjkd.Refused,
        lambda: objects.register_sphere(2.0, name=name),
        code=gjkd.ErrorCode.NAME_TAKEN,
        field="name",
    )
    still_serves(objects, pair)


def test_bad_options(objects: Any, pair: tuple[int, int]) -> None:
    a, b = pair
    for kwargs, field in (
        ({"tolerance": -1.0}, "tolerance"),
        ({"tolerance": NAN}, "tolerance"),
        ({"max_iterations": 0}, "max_iterations"),
        ({"margin": math.inf}, "margin"),
    ):
        raises(gjkd.InvalidInput, lambda: objects.distance(a, b, **kwargs), field=field)
        raises(gjkd.InvalidInput, lambda: objects.distances([pair], **kwargs), field=field)
    with pytest.raises(OverflowError):
        objects.distance(a, b, max_iterations=-1)
    still_serves(objects, pair)


def test_server_counts_no_failed_registration(client: gjkd.Client) -> None:
    before = client.stats()["objects"]
    for call in (
        lambda: client.register_polytope(np.zeros((0, 3))),
        lambda: client.register_sphere(-1.0),
        lambda: client.register_sphere(1.0, pose=[NAN] * 7),
    ):
        with pytest.raises(gjkd.InvalidInput):
            call()
    assert client.stats()["objects"] == before


def test_error_codes_match_the_native_table() -> None:
    from gjkd import _native

    table = _native.error_codes()
    assert len(table) == len(gjkd.ErrorCode)
    for (name, value, _), code in zip(table, gjkd.ErrorCode):
        snake = "".join("_" + c if c.isupper() else c for c in name).lstrip("_").upper()
        assert (snake, value) == (code.name, code.value)

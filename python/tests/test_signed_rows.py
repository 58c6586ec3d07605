"""Signed distances in Python batches (``distances(signed_distance=True)``)
and scene rows (``SceneRows(n, signed_distance=True)``), against closed
forms: a ball of radius 0.5 whose centre is inside the box ``[-1, 1]³`` is
``0.5 +`` the centre's distance to the nearest face deep; apart, its
signed distance is its distance. Also the tie flag of an overlapping
pair's gradient (a ball's centre on the box's medial axis)."""

from __future__ import annotations

from typing import Any, Iterator

import numpy as np
import pytest

import gjkd
from conftest import unique_service

XS = [0.8, 0.5, -0.3, 2.0, 3.25, 0.95]


def expected(x: float) -> float:
    """The signed distance of the ball at ``(x, 0.1, 0)`` to the box."""
    if abs(x) <= 1.0:
        return -(0.5 + min(1.0 - abs(x), 0.9))
    return abs(x) - 1.5


@pytest.fixture(params=["client", "local"])
def alone(request: pytest.FixtureRequest) -> Iterator[gjkd.Client]:
    """A client of a server of its own (a scene question sees every object
    stored, so no other test's may be there), then a Local."""
    if request.param == "local":
        with gjkd.Local() as local:
            yield local  # type: ignore[misc]
        return
    with gjkd.Server(service=unique_service("signed"), wait="spin") as server:
        with gjkd.Client(server.service) as client:
            yield client


def scene(objects: Any) -> tuple[int, list[int]]:
    box = objects.register_box([1.0, 1.0, 1.0])
    balls = [objects.register_sphere(0.5, pose=[x, 0.1, 0.0, 0, 0, 0, 1.0]) for x in XS]
    return box, balls


def test_distances_answer_the_signed_distance_when_asked(objects: Any) -> None:
    box, balls = scene(objects)
    pairs = np.array([[box, b] for b in balls] + [[box, 10**9]], dtype=np.uint64)
    d = objects.distances(pairs, signed_distance=True, warm_start=False)
    want = np.array([expected(x) for x in XS])
    n = len(XS)
    np.testing.assert_allclose(d.signed_distance[:n], want, rtol=0, atol=1e-9)
    assert np.all(d.signed_lower[:n] <= want) and np.all(want <= d.signed_upper[:n])
    # The distance: the signed one apart, 0 overlapping.
    np.testing.assert_allclose(d.distance[:n], np.maximum(want, 0.0), rtol=0, atol=1e-9)
    # Each row's witnesses agree with its value.
    gap = d.point_b[:n] - d.point_a[:n] - d.normal[:n] * d.signed_distance[:n, None]
    assert np.abs(gap).max() < 1e-9
    # The failed row (an unknown id) has none.
    assert d.error[n] != 0 and np.isnan(d.signed_distance[n])
    assert "signed_distance" in d.as_dict()
    # Not asked: NaN everywhere, the arrays reused through `out`.
    again = objects.distances(pairs, out=d)
    assert again is d
    assert np.all(np.isnan(d.signed_distance)) and np.all(np.isnan(d.signed_upper))
    assert d.distance[0] == 0.0


def test_scene_rows_carry_the_signed_distance_when_asked(alone: gjkd.Client) -> None:
    client = alone
    box, balls = scene(client)
    rows = gjkd.SceneRows(8, signed_distance=True)
    s = client.within([box], 10.0, out=rows, exact=True)
    assert s.written == len(XS)
    for i in range(s.written):
        x = XS[balls.index(int(rows.b[i]))]
        want = expected(x)
        assert abs(rows.signed_distance[i] - want) < 1e-9, (x, rows.signed_distance[i])
        assert rows.signed_lower[i] <= want <= rows.signed_upper[i]
    # A margin of 0 reports the overlapping pairs however deep, not the
    # ones apart: the question compares the distance, 0 inside.
    s = client.within([box], 0.0, out=rows)
    inside = {b for b, x in zip(balls, XS) if abs(x) <= 1.0}
    assert {int(b) for b in rows.b[: s.written]} == inside
    assert np.all(rows.signed_distance[: s.written] < -0.5)
    # Nearest rows too: overlapping objects are all at distance 0, so
    # the two nearest are two of the overlapping balls, each with its own
    # depth.
    s = client.nearest(box, 2, out=rows)
    assert s.written == 2
    for i in range(2):
        x = XS[balls.index(int(rows.b[i]))]
        assert abs(x) <= 1.0
        assert rows.signed_distance[i] == pytest.approx(expected(x), abs=1e-9)
    # A room that does not ask: NaN.
    plain = gjkd.SceneRows(8)
    s = client.within([box], 10.0, out=plain)
    assert np.all(np.isnan(plain.signed_distance[: s.written]))
    # A continuous path refuses the flag.
    moving = [balls[3]]
    poses = np.array([[2.1, 0.1, 0, 0, 0, 0, 1.0], [2.1, 3.0, 0, 0, 0, 0, 1.0]])
    with pytest.raises(gjkd.InvalidInput):
        client.path(moving, moving, poses, out=rows, question="continuous", margin=0.1)
    s = client.path(moving, moving, poses, out=plain, question="continuous", margin=0.1)
    assert s.written == 0


def test_a_tied_depth_direction_is_flagged(alone: gjkd.Client) -> None:
    client = alone
    box = client.register_box([1.0, 1.0, 1.0])
    ball = client.register_sphere(0.5)
    rows = gjkd.SceneRows(2, gradient_columns=6, signed_distance=True)
    for centre, tied in [([0.5, 0.5, 0.0], True), ([0.8, 0.1, 0.0], False)]:
        client.set_pose(ball, [*centre, 0, 0, 0, 1.0])
        a = client.distance(box, ball, signed_distance=True, gradient=True, warm_start=False)
        assert a.gradient_not_unique == tied, centre
        s = client.within([box], 0.0, out=rows)
        assert s.written == 1
        assert bool(rows.gradient_flags[0] & 2) == tied, centre
        depth = 0.5 + min(1.0 - abs(c) for c in centre)
        assert rows.signed_distance[0] == pytest.approx(-depth, abs=1e-9)

"""Scene queries from Python: clearance, within, nearest and paths into a
caller-owned ``SceneRows``, against the same server's per-pair answers and
closed forms. Every test runs on a ``gjkd.Client`` of a server of its own
and on a ``gjkd.Local``."""

from __future__ import annotations

from typing import Iterator

import numpy as np
import pytest

import gjkd
from conftest import unique_service

IDENTITY = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]


def at(x: float, y: float = 0.0, z: float = 0.0) -> list[float]:
    return [x, y, z, 0.0, 0.0, 0.0, 1.0]


@pytest.fixture(params=["client", "local"])
def client(request: pytest.FixtureRequest) -> Iterator[gjkd.Client]:
    """A server of the test's own (scene queries see every object), then a
    Local."""
    if request.param == "local":
        with gjkd.Local() as local:
            yield local  # type: ignore[misc]
        return
    with gjkd.Server(service=unique_service("scene"), wait="spin") as server:
        with gjkd.Client(server.service) as c:
            yield c


@pytest.fixture()
def scene(client: gjkd.Client) -> tuple[list[int], list[int]]:
    """Two balls of radius 0.5 at y = 0 and y = 6, and three unit boxes
    along x: distances are analytic."""
    group = [client.register_sphere(0.5), client.register_sphere(0.5)]
    client.set_pose(group[0], at(0.0))
    client.set_pose(group[1], at(0.0, 6.0))
    boxes = [client.register_box([0.5, 0.5, 0.5]) for _ in range(3)]
    for i, b in enumerate(boxes):
        client.set_pose(b, at(2.0 + 2.0 * i))
    return group, boxes


def exact(client: gjkd.Client, a: int, b: int) -> float:
    return client.distance(a, b, warm_start=False).distance


def test_clearance_gives_each_members_nearest(client: gjkd.Client, scene) -> None:
    group, boxes = scene
    rows = gjkd.SceneRows(8)
    s = client.clearance(np.array(group, dtype=np.uint64), out=rows)
    assert s.written == 2 and s.total == 2 and not s.truncated and s.steps == 1
    assert list(rows.a[:2]) == group
    assert list(rows.b[:2]) == [boxes[0], boxes[0]]
    # Ball at the origin to the box face at x = 1.5: 1.0.
    assert rows.distance[0] == pytest.approx(1.0, abs=1e-9)
    want = exact(client, group[1], boxes[0])
    assert rows.distance[1] == pytest.approx(want, abs=1e-9)
    assert np.all(rows.lower[:2] <= rows.distance[:2] + 1e-12)
    assert np.all(rows.error[:2] == gjkd.ErrorCode.OK)


def test_within_truncates_into_a_short_buffer(client: gjkd.Client, scene) -> None:
    group, boxes = scene
    rows = gjkd.SceneRows(16)
    s = client.within(group, 3.2, out=rows)
    want = sorted((a, b) for a in group for b in boxes if exact(client, a, b) <= 3.2)
    assert sorted(zip(rows.a[: s.written].tolist(), rows.b[: s.written].tolist())) == want
    short = gjkd.SceneRows(1)
    t = client.within(group, 3.2, out=short)
    assert t.truncated and t.written == 1 and t.total == len(want)


def test_nearest_and_allowed_pairs(client: gjkd.Client, scene) -> None:
    group, boxes = scene
    rows = gjkd.SceneRows(2)
    s = client.nearest(group[0], 2, out=rows)
    assert s.written == 2
    assert list(rows.b) == [boxes[0], boxes[1]]
    assert rows.distance[0] == pytest.approx(1.0, abs=1e-9)
    assert rows.distance[1] == pytest.approx(3.0, abs=1e-9)
    client.nearest(group[0], 1, out=rows, allow=np.array([[group[0], boxes[0]]]))
    assert rows.b[0] != boxes[0]


def test_path_moves_nothing_and_finds_the_first_hit(client: gjkd.Client, scene) -> None:
    group, boxes = scene
    ball = group[0]
    steps = np.array([at(-3.0 + 0.5 * s) for s in range(6)])
    rows = gjkd.SceneRows(16)
    s = client.path([ball], [ball], steps, out=rows)
    assert s.steps == 6 and s.written == 6
    for k in range(6):
        # The ball at x = -3 + 0.5 k, the first box face at x = 1.5.
        assert rows.step[k] == k
        assert rows.distance[k] == pytest.approx(4.0 - 0.5 * k, abs=1e-9)
    hit = client.path([ball], [ball], steps, out=rows, question="first_hit", margin=2.1)
    assert hit.first_hit == 4
    assert np.all(rows.step[: hit.written] == 4)
    # Nothing moved: the ball is still at the origin.
    assert exact(client, ball, boxes[0]) == pytest.approx(1.0, abs=1e-9)


def test_whole_request_errors_raise(client: gjkd.Client, scene) -> None:
    group, _ = scene
    rows = gjkd.SceneRows(4)
    with pytest.raises(gjkd.Error) as e:
        client.clearance(0xDEAD00000001, out=rows)
    assert e.value.code == gjkd.ErrorCode.UNKNOWN_OBJECT
    with pytest.raises(gjkd.Error) as e:
        client.within(group, float("nan"), out=rows)
    assert e.value.code == gjkd.ErrorCode.INVALID_OPTIONS
    with pytest.raises(gjkd.InvalidInput):
        client.path(group, group, np.zeros((3, 7)), out=rows)
    with pytest.raises(gjkd.InvalidInput):
        client.path(group, group, np.array([IDENTITY, IDENTITY]), out=rows, question="nope")
    assert gjkd.Status.BOUNDED == 6


# A rod of radius 0.1 and length 1 hanging from the origin along -z, swung
# about y by one joint limited to [-2, 2].
PENDULUM = """<robot name="pendulum">
  <link name="mount"/>
  <link name="rod"><collision><origin xyz="0 0 -0.5"/>
    <geometry><cylinder radius="0.1" length="1"/></geometry></collision></link>
  <joint name="swing" type="revolute"><parent link="mount"/><child link="rod"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
</robot>"""

BALL = np.array([0.0, 0.0, -3.0])


def rod_to_ball(q: float) -> float:
    """Closed form: the rod's axis is u = (-sin q, 0, -cos q) from the
    origin; the ball (radius 0.5) is nearest its side or a cap's rim."""
    u = np.array([-np.sin(q), 0.0, -np.cos(q)])
    t = float(BALL @ u)
    radial = float(np.linalg.norm(BALL - t * u))
    axial = -t if t < 0.0 else max(t - 1.0, 0.0)
    return float(np.hypot(axial, max(radial - 0.1, 0.0))) - 0.5


@pytest.fixture()
def pendulum(client: gjkd.Client) -> tuple[gjkd.Robot, int, int]:
    robot = client.register_robot(unique_service("pendulum"), urdf_text=PENDULUM)
    ball = client.register_sphere(0.5, pose=BALL.tolist() + [0.0, 0.0, 0.0, 1.0])
    return robot, robot.link("rod"), ball


def test_path_along_joint_positions_matches_the_closed_form(client: gjkd.Client, pendulum) -> None:
    robot, rod, ball = pendulum
    level = np.pi / 2
    client.set_joints(robot, [level])
    assert exact(client, rod, ball) == pytest.approx(2.4, abs=1e-9)
    qs = np.array([[0.0], [0.5], [level], [-1.0], [2.0]])
    rows = gjkd.SceneRows(8)
    s = client.path_joints(robot, robot, qs, out=rows)
    assert s.steps == 5 and s.written == 5
    assert rod_to_ball(0.0) == pytest.approx(1.5, abs=1e-12)
    for k, q in enumerate(qs[:, 0]):
        assert (rows.a[k], rows.b[k], rows.step[k]) == (rod, ball, k)
        assert rows.distance[k] == pytest.approx(rod_to_ball(q), abs=1e-9)
        assert rows.lower[k] <= rows.distance[k] <= rows.upper[k]
    # Nothing moved on the server: the rod is still level.
    assert exact(client, rod, ball) == pytest.approx(2.4, abs=1e-9)
    np.testing.assert_array_equal(robot.positions, [level])
    # First hit within 1.6: at q = 0.2 (about 1.50 from the ball).
    steps = np.array([[level], [1.0], [0.2], [0.0]])
    assert rod_to_ball(1.0) > 1.6 > rod_to_ball(0.2)
    hit = client.path_joints(robot.id, robot, steps, out=rows, question="first_hit", margin=1.6)
    assert hit.first_hit == 2 and hit.written == 1
    assert rows.distance[0] == pytest.approx(rod_to_ball(0.2), abs=1e-9)
    # One step may be given as a (dof,) row; clamp moves 2.5 to the limit 2.
    one = client.path_joints(robot, robot, np.array([2.5]), out=rows, clamp=True)
    assert one.steps == 1
    assert rows.distance[0] == pytest.approx(rod_to_ball(2.0), abs=1e-9)


def test_path_along_joint_positions_refuses_bad_positions(client: gjkd.Client, pendulum) -> None:
    robot, _, _ = pendulum
    rows = gjkd.SceneRows(4)
    with pytest.raises(gjkd.InvalidInput) as e:
        client.path_joints(robot, robot, np.array([[0.0], [2.5]]), out=rows)
    assert e.value.code == gjkd.ErrorCode.OUT_OF_LIMITS
    assert e.value.field == "positions" and e.value.index == 1
    assert "swing" in str(e.value)
    with pytest.raises(gjkd.InvalidInput) as e:
        client.path_joints(robot, robot, np.array([[np.nan]]), out=rows)
    assert e.value.code == gjkd.ErrorCode.NON_FINITE_POSE and e.value.index == 0
    for shape in [(3, 2), (0, 1), (2,)]:
        with pytest.raises(gjkd.InvalidInput) as e:
            client.path_joints(robot, robot, np.zeros(shape), out=rows)
        assert e.value.field == "positions"
    with pytest.raises(gjkd.InvalidInput):
        client.path_joints(robot, robot, np.zeros((1, 1), dtype=np.float32), out=rows)
    with pytest.raises(gjkd.InvalidInput) as e:
        client.path_joints(robot, robot, [[0.0]], out=rows, question="nope")
    assert e.value.field == "question"
    with pytest.raises(TypeError):
        client.path_joints(robot, robot.id, [[0.0]], out=rows)  # type: ignore[arg-type]


# Two balls of radius 0.1 joined by a bar: l0 at the origin, l2 at the end
# of a second 1 m segment that folds back over the first about j2.
FOLD = """<robot name="fold">
  <link name="l0"><collision><geometry><sphere radius="0.1"/></geometry></collision></link>
  <link name="l1"><collision><origin xyz="0.5 0 0"/>
    <geometry><box size="0.8 0.05 0.05"/></geometry></collision></link>
  <link name="l2"><collision><origin xyz="1 0 0"/>
    <geometry><sphere radius="0.1"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="l0"/><child link="l1"/>
    <axis xyz="0 0 1"/><limit lower="-3.1" upper="3.1" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="1 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3.1" upper="3.1" effort="1" velocity="1"/></joint>
</robot>"""


def folded(theta: float) -> float:
    """Closed form: l2's centre is at (1 + cos θ, sin θ), 2|cos(θ/2)| from
    l0's; both balls have radius 0.1."""
    return 2.0 * abs(np.cos(theta / 2.0)) - 0.2


def test_self_pairs_report_a_robots_own_collisions(client: gjkd.Client) -> None:
    robot = client.register_robot(unique_service("fold"), urdf_text=FOLD)
    l0, l2 = robot.link("l0"), robot.link("l2")
    rows = gjkd.SceneRows(16)
    margin = 0.1
    for theta in [0.0, 2.5, 2.9, -3.0]:
        client.set_joints(robot, [0.0, theta])
        own = client.within(robot, margin, out=rows, self_pairs=True)
        pairs = {tuple(sorted((int(rows.a[k]), int(rows.b[k])))) for k in range(own.written)}
        d = max(folded(theta), 0.0)  # overlapping balls are at distance 0
        # l1 touches both balls but is adjacent to them: never reported.
        assert pairs == ({tuple(sorted((l0, l2)))} if d <= margin else set()), theta
        if pairs:
            assert rows.lower[0] <= d <= rows.upper[0]
        assert client.within(robot, margin, out=rows).written == 0
    steps = np.array([[0.0, t] for t in [0.0, 1.0, 2.0, 2.9, 3.0]])
    assert folded(2.0) > margin >= folded(2.9)
    hit = client.path_joints(
        robot, robot, steps, out=rows, question="first_hit", margin=margin, self_pairs=True
    )
    assert hit.first_hit == 3
    assert {int(rows.a[0]), int(rows.b[0])} == {l0, l2}
    assert rows.lower[0] <= folded(2.9) <= rows.upper[0]
    # Clearance too: each ball's nearest is the other ball (the bar is
    # adjacent to both), at the closed-form distance.
    c = client.path_joints(robot, robot, steps, out=rows, self_pairs=True)
    l1 = robot.link("l1")
    for k in range(c.written):
        theta = steps[rows.step[k], 1]
        partner = {l0: l2, l2: l0}.get(int(rows.a[k]))
        if partner is None:
            assert int(rows.a[k]) == l1 and rows.b[k] == 0
            continue
        assert rows.b[k] == partner
        assert rows.distance[k] == pytest.approx(max(folded(theta), 0.0), abs=1e-9)
    assert c.written == 3 * len(steps)

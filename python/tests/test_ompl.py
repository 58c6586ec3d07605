"""gjkd.ompl: OMPL's checks answered by a real server, against distances
computed here by hand (a planar arm of balls among balls), and a small
planning problem end to end. Skipped where OMPL's Python bindings (pip
``ompl``) cannot be imported; :class:`gjkd.ompl.RobotChecker` itself needs
no OMPL and is tested everywhere."""

from __future__ import annotations

import json
import math
import pathlib
import sys
from typing import Iterator

import numpy as np
import pytest

import gjkd
import gjkd.ompl
from conftest import unique_service

ROOT = pathlib.Path(__file__).resolve().parents[2]

# Three links about parallel z axes, each a ball of radius R at the middle
# of a link of length 1 (the links themselves have no other geometry).
# Links joined by a joint are allowed pairs; link1 and link3 are not.
R = 0.2
ARM = """<robot name="balls">
  <link name="base"/>
  {links}
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="1 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/>
    <origin xyz="1 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-2.5" upper="2.5" effort="1" velocity="1"/></joint>
</robot>""".format(
    links="\n  ".join(
        f'<link name="l{i}"><collision><origin xyz="0.5 0 0"/>'
        f'<geometry><sphere radius="{R}"/></geometry></collision></link>'
        for i in (1, 2, 3)
    )
)
# Obstacle balls (centre x, y; radius), in the arm's plane.
OBSTACLES = [((1.6, 1.2), 0.3), ((-1.0, -1.4), 0.4), ((0.2, -1.8), 0.25)]


def centres(q: np.ndarray) -> np.ndarray:
    """The links' ball centres in the plane, by hand."""
    out, x, y, a = [], 0.0, 0.0, 0.0
    for qi in q:
        a += qi
        out.append((x + 0.5 * math.cos(a), y + 0.5 * math.sin(a)))
        x, y = x + math.cos(a), y + math.sin(a)
    return np.array(out)


def exact_clearance(q: np.ndarray) -> float:
    """The smallest distance of a link's ball to an obstacle or to its
    non-adjacent link: sphere to sphere, by hand."""
    c = centres(q)
    d = [float(np.linalg.norm(c[0] - c[2])) - 2 * R]
    for p, r in OBSTACLES:
        d += [float(np.linalg.norm(ci - p)) - R - r for ci in c]
    return min(d)


@pytest.fixture(scope="module")
def client() -> Iterator[gjkd.Client]:
    with gjkd.Server(service=unique_service("ompl")) as server:
        with gjkd.Client(server.service) as c:
            for (x, y), r in OBSTACLES:
                c.register_sphere(r, pose=[x, y, 0.0, 0.0, 0.0, 0.0, 1.0])
            yield c


@pytest.fixture()
def checker(client: gjkd.Client) -> Iterator[gjkd.ompl.RobotChecker]:
    with gjkd.ompl.RobotChecker(client, unique_service("arm"), urdf_text=ARM, margin=0.05) as c:
        yield c


def test_states_agree_with_the_exact_answer(checker: gjkd.ompl.RobotChecker) -> None:
    assert checker.self_pairs == 1 and checker.dof == 3
    rng = np.random.default_rng(7)
    qs = rng.uniform(checker.lower, checker.upper, size=(300, 3))
    exact = np.array([exact_clearance(q) for q in qs])
    # Away from the margin's edge, where rounding could decide either way.
    keep = np.abs(exact - checker.margin) > 1e-9
    qs, exact = qs[keep], exact[keep]
    want = exact > checker.margin
    assert 30 < want.sum() < len(want) - 30, "both answers are exercised"
    got = np.array([checker.is_valid(q) for q in qs])
    np.testing.assert_array_equal(got, want)
    np.testing.assert_array_equal(checker.are_valid(qs), want)
    # Overlapping shapes are at distance 0.
    for q, d in zip(qs[:40], exact[:40]):
        assert checker.clearance(q) == pytest.approx(max(d, 0.0), abs=1e-9)
    assert checker.state_checks == 2 * len(qs)
    assert checker.clearance_checks == 40


def test_self_collision_is_seen(checker: gjkd.ompl.RobotChecker) -> None:
    # Folded back: link3's ball comes onto link1's, far from every obstacle.
    q = np.array([0.3, 2.4, 2.4])
    c = centres(q)
    gap = float(np.linalg.norm(c[0] - c[2])) - 2 * R
    assert gap < 0.0 and exact_clearance(q) == gap
    assert checker.clearance(q) == 0.0
    assert not checker.is_valid(q)
    # Unfolded a little: the same pair is the nearest, apart.
    q = np.array([0.3, 2.2, 2.2])
    c = centres(q)
    gap = float(np.linalg.norm(c[0] - c[2])) - 2 * R
    assert 0.0 < gap < checker.margin and exact_clearance(q) == gap
    assert checker.clearance(q) == pytest.approx(gap, abs=1e-9)
    assert not checker.is_valid(q)


def test_motion_checks_the_sampled_segment(checker: gjkd.ompl.RobotChecker) -> None:
    # Swinging the stretched arm through the first obstacle: both ends are
    # free, the middle is not.
    a, b = np.array([0.0, 0.0, 0.0]), np.array([1.4, 0.0, 0.0])
    assert checker.is_valid(a) and checker.is_valid(b)
    steps = checker.segment(a, b)
    n = math.ceil(1.4 / (checker.resolution * checker.extent))
    assert len(steps) == n and np.array_equal(steps[-1], b)
    assert checker.extent == pytest.approx(math.sqrt(6.0**2 * 2 + 5.0**2))
    want = all(exact_clearance(q) > checker.margin for q in steps)
    assert not want
    assert checker.motion_valid(a, b) is False
    assert checker.motion_valid(a, np.array([0.2, 0.0, 0.0])) is True
    assert checker.edge_checks == 2


def test_continuous_edges_agree_with_dense_exact_checks(
    checker: gjkd.ompl.RobotChecker,
) -> None:
    """Random edges: certified clear exactly when no pose of the edge comes
    within the margin (10 000 poses an edge, by hand), and an edge that
    slips between the sampled validator's states is still refused."""
    assert checker.motion == "continuous"
    rng = np.random.default_rng(11)
    t = np.linspace(0.0, 1.0, 10_001)[:, None]
    seen = {True: 0, False: 0}
    for _ in range(60):
        a = rng.uniform(checker.lower, checker.upper)
        b = a + rng.uniform(-0.6, 0.6, size=3)
        b = np.clip(b, checker.lower, checker.upper)
        least = min(exact_clearance(q) for q in a + t * (b - a))
        if abs(least - checker.margin) < 1e-6:
            continue  # a grazing edge: either answer is right within round-off
        got = checker.motion_valid(a, b)
        assert got == (least > checker.margin), (a, b, least)
        seen[got] += 1
    assert seen[True] > 5 and seen[False] > 5, seen
    # Both ends clear, the middle overlapping: the sampled validator at a
    # coarse step checks the end only and passes it, the continuous one not.
    a, b = np.array([-1.2, -1.4, 1.2]), np.array([-1.0, -0.6, 1.6])
    assert min(exact_clearance(q) for q in a + t * (b - a)) < 0.0
    with gjkd.ompl.RobotChecker(
        checker.client,
        unique_service("coarse"),
        urdf_text=ARM,
        margin=0.05,
        resolution=1.0,
        motion="sampled",
    ) as coarse:
        assert coarse.is_valid(a) and coarse.is_valid(b)
        assert coarse.motion_valid(a, b) is True
    assert checker.motion_valid(a, b) is False


def test_long_edges_take_several_requests(client: gjkd.Client) -> None:
    with gjkd.ompl.RobotChecker(
        client,
        unique_service("fine"),
        urdf_text=ARM,
        margin=0.05,
        resolution=2e-5,
        motion="sampled",
    ) as fine:
        a, b = np.array([-0.5, 0.0, 0.0]), np.array([-0.5, 0.0, 1.0])
        steps = fine.segment(a, b)
        assert len(steps) > 3 * fine.steps_per_request
        want = all(exact_clearance(q) > fine.margin for q in steps)
        assert fine.motion_valid(a, b) is want
        assert fine.edge_steps == len(steps) if want else fine.edge_steps < len(steps)


def test_bad_input_raises_and_registers_nothing(client: gjkd.Client) -> None:
    name = unique_service("bad")
    with pytest.raises(gjkd.InvalidInput) as e:
        gjkd.ompl.RobotChecker(client, name, urdf_text=ARM, margin=-1.0)
    assert e.value.field == "margin"
    with pytest.raises(gjkd.InvalidInput) as e:
        gjkd.ompl.RobotChecker(client, name, urdf_text=ARM, joints=["j1", "elbow"])
    assert e.value.field == "joints"
    with pytest.raises(gjkd.InvalidInput):
        gjkd.ompl.RobotChecker(client, name, urdf_text="<robot")
    with pytest.raises(gjkd.NotFound):
        client.lookup(f"{name}/l1")
    with gjkd.ompl.RobotChecker(client, name, urdf_text=ARM, joints=["j3", "j1"]) as c:
        assert c.joint_names == ["j3", "j1"] and list(c.lower) == [-2.5, -3.0]
        with pytest.raises(gjkd.InvalidInput):
            c.is_valid([0.0, 0.0, 0.0])
        with pytest.raises(gjkd.InvalidInput):
            c.is_valid([math.nan, 0.0])
        with pytest.raises(gjkd.InvalidInput) as e:
            c.is_valid([2.9, 0.0])  # beyond j3's limit
        assert e.value.code == gjkd.ErrorCode.OUT_OF_LIMITS


# -- with OMPL ---------------------------------------------------------------


@pytest.fixture()
def ompl() -> None:
    pytest.importorskip(
        "ompl", reason="OMPL's Python bindings are not installed (pip install ompl)"
    )


@pytest.mark.usefixtures("ompl")
def test_plans_around_the_obstacles_end_to_end(client: gjkd.Client) -> None:
    from ompl import geometric as og
    from ompl import util as ou

    ou.setLogLevel(ou.LOG_WARN)
    ou.RNG.setSeed(3)
    # Fine steps: a link moves at most 3 * 1e-3 * extent (0.03) between two
    # states checked, less than the margin, so that the whole path is free.
    with gjkd.ompl.RobotChecker(
        client, unique_service("plan"), urdf_text=ARM, margin=0.05, resolution=1e-3
    ) as checker:
        ss = gjkd.ompl.simple_setup(checker)
        bounds = ss.getStateSpace().getBounds()
        assert list(bounds.low) == [-3.0, -3.0, -2.5] and list(bounds.high) == [3.0, 3.0, 2.5]
        start, goal = np.array([0.0, 0.0, 0.0]), np.array([2.0, 0.0, 0.0])
        assert not checker.motion_valid(start, goal)
        path = gjkd.ompl.plan(ss, checker, start, goal, time=5.0)
        assert path is not None and path.shape[1] == 3
        np.testing.assert_allclose(path[0], start)
        np.testing.assert_allclose(path[-1], goal)
        for a, b in zip(path[:-1], path[1:]):
            for t in np.linspace(0.0, 1.0, 200):
                assert exact_clearance(a + t * (b - a)) > 0.0
        assert checker.state_checks > 0 and checker.edge_checks > 0
        # The clearance objective's cost is 1 / clearance.
        obj = gjkd.ompl.clearance_objective(ss, checker)
        state = ss.getSpaceInformation().allocState()
        for i, v in enumerate(start):
            state[i] = float(v)
        assert obj.stateCost(state).value() == pytest.approx(1.0 / exact_clearance(start), 1e-6)
        validity = ss.getSpaceInformation().getStateValidityChecker()
        assert validity.clearance(state) == pytest.approx(exact_clearance(start), abs=1e-9)
        # An optimising planner pays it: each motion's cost is the trapezoid
        # of its ends' costs (the objective the planner sees, not the path
        # length the bindings would fall back to).
        goal_state = ss.getSpaceInformation().allocState()
        for i, v in enumerate(goal):
            goal_state[i] = float(v)
        cost = obj.motionCost(state, goal_state).value()
        length = ss.getSpaceInformation().distance(state, goal_state)
        want = 0.5 * (1.0 / exact_clearance(start) + 1.0 / exact_clearance(goal)) * length
        assert cost == pytest.approx(want, rel=1e-6)
        checker.clearance_checks = 0
        ss.setPlanner(og.RRTstar(ss.getSpaceInformation()))
        ss.setOptimizationObjective(obj)
        assert gjkd.ompl.plan(ss, checker, start, goal, time=0.5) is not None
        assert checker.clearance_checks > 0, "the planner never asked the objective"


@pytest.mark.usefixtures("ompl")
def test_a_server_gone_stops_the_planner_and_raises() -> None:
    server = gjkd.Server(service=unique_service("gone"))
    with server, gjkd.Client(server.service, timeout=0.5) as c:
        checker = gjkd.ompl.RobotChecker(c, "arm", urdf_text=ARM)
        ss = gjkd.ompl.simple_setup(checker)
        server.stop()
        with pytest.raises(gjkd.Error):
            gjkd.ompl.plan(ss, checker, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], time=5.0)
        assert checker.error is None  # raised, and forgotten
        # The callbacks themselves never raise into OMPL: they say invalid.
        state = ss.getSpaceInformation().allocState()
        validity = ss.getSpaceInformation().getStateValidityChecker()
        assert validity.isValid(state) is False
        assert isinstance(checker.error, gjkd.Error)


def test_without_ompl_the_error_says_what_to_install(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "ompl", None)
    with pytest.raises(ImportError, match="pip install ompl"):
        gjkd.ompl.simple_setup(None)  # type: ignore[arg-type]


# -- the benchmark's problems -------------------------------------------------

PROBLEMS = ROOT / "python" / "bench" / "problems"
PACKAGES = ROOT / "model" / "tests" / "data"


def test_problem_scene_files_load_and_their_ends_are_free() -> None:
    """Each scene's first problem: its scene file loads in a server, and its
    start and goal are free for the vendored Panda (fingers opened as the
    problems have them, see python/bench/scenes.py)."""
    doc = json.loads((PROBLEMS / "problems.json").read_text())
    assert {s: len(p) for s, p in doc["scenes"].items()} == {
        "box": 100,
        "cage": 100,
        "table_pick": 100,
        "table_under_pick": 100,
        "bookshelf_small": 100,
    }
    urdf = PACKAGES / "example-robot-data/robots/panda_description/urdf/panda.urdf"
    text = urdf.read_text().replace('upper="0.04"', 'upper="0.065"')
    for scene, problems in doc["scenes"].items():
        p = problems[0]
        with gjkd.Server(service=unique_service(scene), scene=PROBLEMS / p["scene"]) as s:
            with gjkd.Client(s.service) as c:
                with gjkd.ompl.RobotChecker(
                    c,
                    "panda",
                    urdf_text=text,
                    srdf=PROBLEMS / "panda.srdf",
                    package_path=[PACKAGES],
                    joints=doc["joints"],
                    fixed=doc["fixed"],
                ) as checker:
                    assert checker.self_pairs > 0
                    assert checker.is_valid(p["start"]), scene
                    assert checker.is_valid(p["goal"]), scene

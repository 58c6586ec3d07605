"""``gjkd.Local`` answers a robot script as ``gjkd.Client`` does: the same
robot, obstacles and calls on a server of the test's own and on a Local,
every answer compared bit for bit (ids mapped through the objects' names,
since the two stores number objects apart), every failure with the same
exception class and code; link poses against pinocchio where it is
installed and against the hand kinematics of ``test_robots``."""

from __future__ import annotations

import math
import pathlib
from typing import Any, Callable, Iterator

import numpy as np
import pytest
from test_meshes import write_binary_stl
from test_robots import ARM_URDF, box_mesh, hand_fk, matrix

import gjkd
from conftest import unique_service

SRDF = '<robot name="testarm"><disable_collisions link1="base" link2="fore" reason="x"/></robot>'
BASE = [0.1, -0.2, 0.05, 0.0, 0.0, math.sin(0.15), math.cos(0.15)]


@pytest.fixture(scope="module")
def arm_urdf(tmp_path_factory: pytest.TempPathFactory) -> pathlib.Path:
    d = tmp_path_factory.mktemp("arm_local")
    (d / "meshes").mkdir()
    v, t = box_mesh([0.0, -0.05, -0.05], [0.4, 0.05, 0.05])
    write_binary_stl(d / "meshes" / "fore.stl", v, t)
    (d / "arm.urdf").write_text(ARM_URDF)
    return d / "arm.urdf"


@pytest.fixture()
def pair() -> Iterator[tuple[gjkd.Client, gjkd.Local]]:
    """A Client of a server of its own (scene questions see every object)
    and a Local."""
    with gjkd.Server(service=unique_service("twin"), wait="spin") as server:
        with gjkd.Client(server.service) as client, gjkd.Local() as local:
            yield client, local


class World:
    """The same robot and obstacles in one store, and a map from its ids to
    names that both stores share."""

    def __init__(self, store: Any, urdf: pathlib.Path) -> None:
        self.store = store
        self.robot = store.register_robot("arm", urdf, srdf_text=SRDF, base=BASE)
        self.obstacles = [
            store.register_box([0.1, 0.2, 0.3], name="crate", pose=[0.9, 0.3, 0.2, 0, 0, 0, 1.0]),
            store.register_sphere(0.15, name="ball", pose=[-0.3, 0.7, 0.4, 0, 0, 0, 1.0]),
            store.register_cylinder(0.05, 0.4, name="post", pose=[0.5, -0.6, 0.4, 0, 0, 0, 1.0]),
        ]
        self.names = {0: "-"}
        for name, link in zip(self.robot.link_names, self.robot.link_ids):
            if link:
                self.names[int(link)] = f"arm/{name}"
        for name, o in zip(["crate", "ball", "post"], self.obstacles):
            self.names[o] = name

    def named(self, ids: np.ndarray) -> list[str]:
        return [self.names[int(i)] for i in ids]


def same_rows(a: World, rows_a: gjkd.SceneRows, b: World, rows_b: gjkd.SceneRows, n: int) -> None:
    assert a.named(rows_a.a[:n]) == b.named(rows_b.a[:n])
    assert a.named(rows_a.b[:n]) == b.named(rows_b.b[:n])
    for field in ("step", "s_lo", "s_hi", "gradient", "gradient_flags", "gradient_error"):
        np.testing.assert_array_equal(getattr(rows_a, field)[:n], getattr(rows_b, field)[:n])
    da, db = rows_a.answers.as_dict(), rows_b.answers.as_dict()
    assert da.keys() == db.keys()
    for key in da:
        np.testing.assert_array_equal(da[key][:n], db[key][:n], err_msg=key)


def same_summary(x: gjkd.SceneSummary, y: gjkd.SceneSummary) -> None:
    keys = ("written", "total", "truncated", "steps", "first_hit", "gjk_runs", "bounded")
    assert [getattr(x, k) for k in keys] == [getattr(y, k) for k in keys]


def both(worlds: list[World], ask: Callable[[World, gjkd.SceneRows], Any], **rows: Any) -> None:
    """Asks one scene question of both stores into rows of their own and
    compares summaries and rows."""
    outs = [gjkd.SceneRows(64, **rows) for _ in worlds]
    summaries = [ask(w, out) for w, out in zip(worlds, outs)]
    same_summary(*summaries)
    same_rows(worlds[0], outs[0], worlds[1], outs[1], summaries[0].written)
    assert summaries[0].written > 0


def test_a_robot_script_gets_the_same_answers(pair: Any, arm_urdf: pathlib.Path) -> None:
    worlds = [World(store, arm_urdf) for store in pair]
    c, w = worlds
    assert c.robot.link_names == w.robot.link_names
    assert c.robot.joint_names == w.robot.joint_names and c.robot.dof == 3
    rng = np.random.default_rng(41)
    sent = BASE
    for step in range(5):
        q = rng.uniform(c.robot.lower, c.robot.upper)
        base = [0.2 * step, 0.1, 0.0, 0.0, 0.0, math.sin(0.1 * step), math.cos(0.1 * step)]
        for world in worlds:
            world.store.set_joints(world.robot, q, base=base if step % 2 else None)
        np.testing.assert_array_equal(c.robot.positions, w.robot.positions)
        links = [[int(i) for i in x.robot.link_ids if i] for x in worlds]
        stored = [x.store.poses(ids) for x, ids in zip(worlds, links)]
        np.testing.assert_array_equal(stored[0], stored[1])
        # Where the hand kinematics put the links (the base last sent).
        sent = base if step % 2 else sent
        frames = hand_fk(q, matrix(np.array(sent)))
        named = [n for n, i in zip(c.robot.link_names, c.robot.link_ids) if i]
        for row, name in zip(stored[1], named):
            assert np.max(np.abs(matrix(row) - frames[name])) < 1e-12, name
        pairs = [
            np.array([[link, o] for link in ids for o in x.obstacles], dtype=np.uint64)
            for x, ids in zip(worlds, links)
        ]
        got = [x.store.distances(p, signed_distance=True).as_dict() for x, p in zip(worlds, pairs)]
        for key in got[0]:
            np.testing.assert_array_equal(got[0][key], got[1][key], err_msg=key)
        tip = [x.robot.link("tip") for x in worlds]
        grads = [
            x.store.distance(t, x.obstacles[0], gradient=True, gradient_base=True)
            for x, t in zip(worlds, tip)
        ]
        np.testing.assert_array_equal(grads[0].gradient, grads[1].gradient)
        assert grads[0].distance == grads[1].distance

    # Scene questions: clearance, within (self pairs, signed distances and
    # gradients), nearest.
    both(worlds, lambda x, out: x.store.clearance(x.robot, out=out))
    both(
        worlds,
        lambda x, out: x.store.within(x.robot, 2.0, out=out, self_pairs=True, exact=True),
        gradient_columns=9,
        gradient_base=True,
    )
    both(
        worlds,
        lambda x, out: x.store.within(x.robot, 2.0, out=out, all_pairs=True),
        signed_distance=True,
    )
    both(worlds, lambda x, out: x.store.nearest(x.robot.link("tip"), 3, out=out))

    # Paths of poses (every step, first hit, continuous) and of joints.
    moves = np.array([[0.2 + 0.1 * s, 0.3, 0.2, 0, 0, 0, 1.0] for s in range(8)])
    for question in ("clearance", "within", "first_hit", "continuous"):
        both(
            worlds,
            lambda x, out: x.store.path(
                [x.obstacles[1]], [x.obstacles[1]], moves, out=out, question=question, margin=0.8
            ),
        )
    qs = np.linspace(c.robot.lower, c.robot.upper, 6)
    for question in ("clearance", "within", "first_hit", "continuous"):
        both(
            worlds,
            lambda x, out: x.store.path_joints(
                x.robot, x.robot, qs, out=out, question=question, margin=0.6, self_pairs=True
            ),
        )
    both(
        worlds,
        lambda x, out: x.store.path_joints(
            x.robot, x.robot, qs, out=out, question="within", margin=0.6
        ),
        gradient_columns=3,
    )
    # Nothing a path asked moved: the stores still agree.
    stored = [x.store.poses(x.obstacles) for x in worlds]
    np.testing.assert_array_equal(stored[0], stored[1])

    # A robot opened by name, then removed whole.
    for x in worlds:
        found = x.store.open_robot("arm", ARM_URDF)
        assert found.id == x.robot.id and list(found.link_ids) == list(x.robot.link_ids)
        x.store.remove_robot(found)
        with pytest.raises(gjkd.NotFound) as e:
            x.store.lookup("arm/base")
        assert e.value.code == gjkd.ErrorCode.UNKNOWN_NAME


def failure(call: Callable[[], Any]) -> tuple[type, Any, Any, Any]:
    with pytest.raises(gjkd.Error) as e:
        call()
    return type(e.value), e.value.code, e.value.field, e.value.index


def test_failures_raise_the_same_errors(pair: Any, arm_urdf: pathlib.Path) -> None:
    worlds = [World(store, arm_urdf) for store in pair]
    rows = gjkd.SceneRows(8)
    calls: list[Callable[[World], Any]] = [
        lambda x: x.store.set_joints(x.robot, [0.0, 2.5, 0.0]),
        lambda x: x.store.set_joints(x.robot, [0.0, 0.0, math.nan]),
        lambda x: x.store.set_joints(x.robot, [0.0, 0.0]),
        lambda x: x.store.set_joints(x.robot, {"wrist": 0.0}),
        lambda x: x.store.set_joints(x.robot, [0.0] * 3, base=[0, 0, 0, 0, 0, 0, 2.0]),
        lambda x: x.store.set_joints(x.robot, [0.0] * 3, base=[math.nan, 0, 0, 0, 0, 0, 1.0]),
        lambda x: x.store.register_robot("arm", arm_urdf),
        lambda x: x.store.register_robot("other", urdf_text="<robot"),
        lambda x: x.store.register_robot("other", arm_urdf.parent / "none.urdf"),
        lambda x: x.store.register_robot("other", arm_urdf, srdf_text=SRDF.replace("fore", "x")),
        lambda x: x.store.register_robot("x" * 300, arm_urdf),
        lambda x: x.store.open_robot("no-such-robot", ARM_URDF),
        lambda x: x.store.open_robot("arm", "<robot"),
        lambda x: x.store.remove_robot("no-such-robot"),
        lambda x: x.store.clearance(0xDEAD00000001, out=rows),
        lambda x: x.store.within(x.robot, math.nan, out=rows),
        lambda x: x.store.path_joints(x.robot, x.robot, [[0.0, 2.5, 0.0]], out=rows),
        lambda x: x.store.path(x.robot, [x.obstacles[0]], np.zeros((2, 7)), out=rows),
        lambda x: x.store.path(x.robot, [x.obstacles[0]], np.zeros((0, 7)), out=rows),
    ]
    for k, call in enumerate(calls):
        got = [failure(lambda: call(x)) for x in worlds]
        assert got[0] == got[1], (k, got)
    # Nothing moved, and the failed registrations left nothing behind.
    for x in worlds:
        np.testing.assert_array_equal(x.robot.positions, [0.0, 0.0, 0.0])
        with pytest.raises(gjkd.NotFound):
            x.store.lookup("other/base")
    stored = [x.store.poses([int(i) for i in x.robot.link_ids if i] + x.obstacles) for x in worlds]
    np.testing.assert_array_equal(stored[0], stored[1])


def test_link_poses_match_pinocchio(pair: Any, arm_urdf: pathlib.Path) -> None:
    """The links the stores place, read back, against pinocchio's forward
    kinematics of the same URDF (an independent library)."""
    pin = pytest.importorskip(
        "pinocchio", reason="pinocchio is not installed (pip install pin): skipping its check"
    )
    model = pin.buildModelFromXML(ARM_URDF)
    data = model.createData()
    rng = np.random.default_rng(8)
    worlds = [World(store, arm_urdf) for store in pair]
    robot = worlds[0].robot
    names = [n for n, i in zip(robot.link_names, robot.link_ids) if i]
    base_m = matrix(np.array(BASE))
    for _ in range(4):
        q = rng.uniform(robot.lower, robot.upper)
        config = np.zeros(model.nq)
        for name, value in zip(robot.joint_names, q):
            joint = model.joints[model.getJointId(name)]
            config[joint.idx_q] = value
        pin.forwardKinematics(model, data, config)
        pin.updateFramePlacements(model, data)
        for x in worlds:
            x.store.set_joints(x.robot, q)
            got = x.store.poses([x.robot.link(n) for n in names])
            for row, name in zip(got, names):
                want = base_m @ data.oMf[model.getFrameId(name)].homogeneous
                assert np.max(np.abs(matrix(row) - want)) < 1e-12, name


def test_a_long_path_comes_back_whole_from_a_local() -> None:
    """1 000 steps of three balls (3 000 items and rows, over a server's
    default limits) in one call, against the closed form."""
    with gjkd.Local() as local:
        group = [local.register_sphere(0.1) for _ in range(3)]
        wall = local.register_box([0.1, 3.0, 3.0], pose=[2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
        steps = 1000
        poses = np.zeros((steps * 3, 7))
        poses[:, 6] = 1.0
        poses[:, 0] = np.repeat(1.5 * np.arange(steps) / steps, 3)
        poses[:, 1] = np.tile(0.5 * np.arange(3), steps)
        rows = gjkd.SceneRows(steps * 3 + 8)
        s = local.path(group, group, poses, out=rows, exact=True)
        assert (s.steps, s.written, s.total, s.truncated) == (steps, steps * 3, steps * 3, False)
        assert np.all(rows.b[: steps * 3] == wall)
        assert np.allclose(rows.distance[: steps * 3], 1.9 - poses[:, 0] - 0.1, atol=1e-9)

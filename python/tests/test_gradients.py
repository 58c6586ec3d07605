"""Distance gradients through the Python client: the Panda's link-obstacle
gradients, single and batched, against pinocchio's frame Jacobians at
gjkd's witness points (an independent kinematics library) and against
central differences of the distance; batch rows and scene rows against
the pair query; and the trajectory optimisation example (gjkd, and
pinocchio + coal as the baseline) run small."""

from __future__ import annotations

import importlib.util
import itertools
import pathlib
import sys
from types import ModuleType
from typing import Any, Iterator

import numpy as np
import pytest
from test_robots import matrix

import gjkd

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "model" / "tests" / "data"
PANDA = DATA / "example-robot-data" / "robots" / "panda_description" / "urdf" / "panda.urdf"
EXAMPLE = ROOT / "python" / "examples" / "trajopt_panda.py"

_names = itertools.count()


@pytest.fixture(scope="module", params=["client", "local"])
def panda(
    request: pytest.FixtureRequest, server: gjkd.Server
) -> Iterator[tuple[gjkd.Client, Any, list[int]]]:
    """One Panda among obstacles for the module (a second robot at the same
    base would overlap the first everywhere), on the module's server, then
    on a Local."""
    if request.param == "local":
        client: Any = gjkd.Local()
    else:
        client = gjkd.Client(server.service, timeout=30.0)
    robot = client.register_robot(f"panda{next(_names)}", PANDA, package_path=[DATA])
    rng = np.random.default_rng(5)
    obstacles = []
    for i in range(6):
        pose = np.array([*rng.uniform([-0.6, -0.6, 0.0], [0.6, 0.6, 0.9]), 0, 0, 0, 1.0])
        if i % 2:
            obstacles.append(client.register_sphere(0.05, pose=pose))
        else:
            obstacles.append(client.register_box([0.04, 0.03, 0.05], pose=pose))
    yield client, robot, obstacles
    client.close()


def random_positions(robot: Any, rng: np.random.Generator) -> np.ndarray:
    return rng.uniform(robot.lower, robot.upper)


def link_pairs(robot: Any, obstacles: list[int]) -> np.ndarray:
    """``(K, 2)``: every link with geometry against every obstacle."""
    return np.array([[int(k), o] for k in robot.link_ids if k for o in obstacles], dtype=np.uint64)


def padded(answer: Any, columns: int) -> np.ndarray:
    """A single answer's gradient as a row of ``columns`` entries."""
    row = np.zeros(columns)
    if answer.gradient is not None:
        row[: len(answer.gradient)] = answer.gradient
    return row


def judge_differences(rows: gjkd.Distances, differences: np.ndarray, pairs: np.ndarray) -> int:
    """Checks each row's gradient against its central differences where
    the gradient exists (apart, unique nearest points); returns how many
    rows were judged."""
    judged = 0
    for i in range(len(pairs)):
        if rows.distance[i] <= 1e-6 or rows.gradient_flags[i] & 2:
            continue
        got, want = rows.gradient[i], differences[i]
        # The step's rounding: the distance to about 1e-14 over 2h.
        assert np.linalg.norm(got - want) <= 1e-6 * np.linalg.norm(want) + 1e-7, (
            pairs[i],
            got,
            want,
        )
        judged += 1
    return judged


def turned(m: np.ndarray, k: int, t: float) -> np.ndarray:
    """``m`` moved by ``t`` along twist column ``k`` (``[v, ω]``, world
    frame, turning about ``m``'s origin)."""
    out = m.copy()
    if k < 3:
        out[:3, 3] += t * np.eye(3)[k]
        return out
    axis = np.eye(3)[k - 3]
    cross = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    turn = np.eye(3) + np.sin(t) * cross + (1 - np.cos(t)) * cross @ cross
    out[:3, :3] = turn @ m[:3, :3]
    return out


def test_gradients_match_pinocchio_frame_jacobians(
    panda: tuple[gjkd.Client, Any, list[int]],
) -> None:
    pin = pytest.importorskip(
        "pinocchio", reason="pinocchio is not installed (pip install pin): skipping its check"
    )
    client, robot, obstacles = panda
    model = pin.buildModelFromUrdf(str(PANDA))
    data = model.createData()
    # gjkd's joint order against pinocchio's velocity indices, by name.
    columns = {}
    for k, name in enumerate(robot.joint_names):
        if model.existJointName(name):
            columns[k] = model.joints[model.getJointId(name)].idx_v
    rng = np.random.default_rng(11)
    judged = 0
    for _ in range(4):
        q = random_positions(robot, rng)
        client.set_joints(robot, q)
        q_pin = pin.neutral(model)
        for k, name in enumerate(robot.joint_names):
            if model.existJointName(name):
                joint = model.joints[model.getJointId(name)]
                q_pin[joint.idx_q] = q[k]
        # The second finger mimics the first (multiplier 1): pinocchio may
        # hold it as a joint of its own.
        if model.existJointName("panda_finger_joint2"):
            joint = model.joints[model.getJointId("panda_finger_joint2")]
            if joint.nq == 1:
                q_pin[joint.idx_q] = q[robot.joint_names.index("panda_finger_joint1")]
        pin.computeJointJacobians(model, data, q_pin)
        pin.framesForwardKinematics(model, data, q_pin)
        # The batch of every link-obstacle pair, one (rows, dof) array.
        pairs = link_pairs(robot, obstacles)
        rows = client.distances(
            pairs, warm_start=False, out=gjkd.Distances(len(pairs), gradient_columns=robot.dof)
        )
        row_of = {(int(a), int(b)): i for i, (a, b) in enumerate(pairs)}
        for link_name, link_id in zip(robot.link_names, robot.link_ids):
            # The fingers' columns differ in layout (pinocchio keeps the
            # mimic joint's own column; gjkd folds it into its leader's).
            if link_id == 0 or "finger" in link_name or not model.existFrame(link_name):
                continue
            frame = model.getFrameId(link_name)
            jacobian = pin.getFrameJacobian(model, data, frame, pin.LOCAL_WORLD_ALIGNED)
            origin = data.oMf[frame].translation
            for obstacle in obstacles:
                answer = client.distance(int(link_id), obstacle, warm_start=False, gradient=True)
                got = answer.gradient
                assert got is not None and got.shape == (robot.dof,)
                if answer.distance <= 1e-6 or answer.gradient_not_unique:
                    continue
                normal = np.array(answer.normal)
                r = np.array(answer.point_a) - origin
                point = jacobian[:3] + np.cross(jacobian[3:].T, r).T
                want = np.zeros(robot.dof)
                for k, v in columns.items():
                    want[k] = -normal @ point[:, v]
                error = np.linalg.norm(got - want)
                assert error <= 1e-6 * np.linalg.norm(want) + 1e-12, (
                    link_name,
                    got,
                    want,
                )
                batch = rows.gradient[row_of[(int(link_id), obstacle)]]
                error = np.linalg.norm(batch - want)
                assert error <= 1e-6 * np.linalg.norm(want) + 1e-12, (link_name, batch, want)
                judged += 1
    assert judged > 30


def test_scene_rows_carry_the_pair_gradients(
    panda: tuple[gjkd.Client, Any, list[int]],
) -> None:
    client, robot, obstacles = panda
    client.set_joints(robot, np.zeros(robot.dof).clip(robot.lower, robot.upper))
    rows = gjkd.SceneRows(64, gradient_columns=robot.dof + 6, gradient_base=True)
    summary = client.within(robot, 0.5, out=rows)
    n = summary.written
    assert n > 3
    assert rows.gradient.shape == (64, robot.dof + 6)
    for i in range(n):
        answer = client.distance(int(rows.a[i]), int(rows.b[i]), gradient=True, gradient_base=True)
        np.testing.assert_allclose(rows.gradient[i], answer.gradient, rtol=1e-9, atol=1e-12)
        assert rows.gradient_flags[i] & 1 and rows.gradient_flags[i] & 4
        assert rows.gradient_error[i] >= 0.0
    # Without room for gradients, none are asked.
    plain = gjkd.SceneRows(64)
    client.within(robot, 0.5, out=plain)
    assert plain.gradient.shape == (64, 0)
    with pytest.raises(gjkd.InvalidInput):
        gjkd.SceneRows(4, gradient_columns=17)


def test_batch_gradients_equal_the_single_queries_bit_for_bit(
    panda: tuple[gjkd.Client, Any, list[int]],
) -> None:
    client, robot, obstacles = panda
    client.set_joints(robot, random_positions(robot, np.random.default_rng(17)))
    pairs = link_pairs(robot, obstacles)
    # More pairs than one request takes: the batch is split, and each
    # chunk's gradients must land in its own rows.
    tiled = np.tile(pairs, (1100 // len(pairs) + 1, 1))
    limit = client.server_info()["max_batch"] if isinstance(client, gjkd.Client) else 1024
    assert len(tiled) > limit
    columns = robot.dof + 6
    out = gjkd.Distances(len(tiled), gradient_columns=columns, gradient_base=True)
    assert out.gradient.shape == (len(tiled), columns)
    assert client.distances(tiled, warm_start=False, out=out) is out
    assert (out.error == 0).all()
    # Fewer columns than the gradient has: each row keeps its first ones.
    narrow = client.distances(
        pairs, warm_start=False, out=gjkd.Distances(len(pairs), gradient_columns=3)
    )
    for i, (a, b) in enumerate(pairs):
        answer = client.distance(
            int(a), int(b), warm_start=False, gradient=True, gradient_base=True
        )
        want = padded(answer, columns)
        for row in range(i, len(tiled), len(pairs)):
            assert out.distance[row] == answer.distance
            np.testing.assert_array_equal(out.gradient[row], want)
            assert out.gradient_error[row] == answer.gradient_error
            flags = int(out.gradient_flags[row])
            assert bool(flags & 1) == (answer.gradient is not None)
            assert bool(flags & 2) == answer.gradient_not_unique
            assert flags & 4, "the base twist was asked"
        np.testing.assert_array_equal(narrow.gradient[i], want[:3])
    # Without gradient columns, none are asked.
    plain = client.distances(pairs, warm_start=False)
    assert plain.gradient.shape == (len(pairs), 0)
    assert not plain.gradient_flags.any() and not plain.gradient_error.any()
    np.testing.assert_array_equal(plain.distance, out.distance[: len(pairs)])
    assert {"gradient", "gradient_flags", "gradient_error"} <= set(out.as_dict())


def test_batch_gradients_match_central_differences(
    panda: tuple[gjkd.Client, Any, list[int]],
) -> None:
    client, robot, obstacles = panda
    rng = np.random.default_rng(23)
    lower, upper = np.asarray(robot.lower), np.asarray(robot.upper)
    # Inside the limits by more than the step, so that q ± h is too.
    q = rng.uniform(lower + 0.01 * (upper - lower), upper - 0.01 * (upper - lower))
    pairs = link_pairs(robot, obstacles)
    client.set_joints(robot, q)
    rows = client.distances(
        pairs, warm_start=False, out=gjkd.Distances(len(pairs), gradient_columns=robot.dof)
    )
    h = 1e-6
    differences = np.zeros((len(pairs), robot.dof))
    for k in range(robot.dof):
        step = h * np.eye(robot.dof)[k]
        client.set_joints(robot, q + step)
        plus = client.distances(pairs, warm_start=False).distance
        client.set_joints(robot, q - step)
        minus = client.distances(pairs, warm_start=False).distance
        differences[:, k] = (plus - minus) / (2 * h)
    client.set_joints(robot, q)
    assert judge_differences(rows, differences, pairs) > 20


def test_a_free_object_gets_its_twist(panda: tuple[gjkd.Client, Any, list[int]]) -> None:
    client, robot, obstacles = panda
    client.set_joints(robot, random_positions(robot, np.random.default_rng(29)))
    links = [int(k) for k in robot.link_ids if k]
    pairs = np.array(
        [[o, k] for o in obstacles for k in links[::3]]
        + [[o, p] for o in obstacles for p in obstacles if o != p],
        dtype=np.uint64,
    )
    rows = client.distances(
        pairs, warm_start=False, out=gjkd.Distances(len(pairs), gradient_columns=6)
    )
    assert (rows.error == 0).all()
    # Room for a robot's base too: a free object's rows use 6 columns, the
    # rest zero, without the base flag.
    wide = client.distances(
        pairs,
        warm_start=False,
        out=gjkd.Distances(len(pairs), gradient_columns=robot.dof + 6, gradient_base=True),
    )
    np.testing.assert_array_equal(wide.gradient[:, :6], rows.gradient)
    assert not wide.gradient[:, 6:].any() and not (wide.gradient_flags & 4).any()
    for i, (a, b) in enumerate(pairs):
        answer = client.distance(int(a), int(b), warm_start=False, gradient=True)
        np.testing.assert_array_equal(rows.gradient[i], padded(answer, 6))
    # Central differences over the twist, each pose given for the query.
    stored = np.array([matrix(p) for p in client.poses(pairs[:, 0])])
    h = 1e-6
    differences = np.zeros((len(pairs), 6))
    for k in range(6):
        plus = np.array([turned(m, k, h) for m in stored])
        minus = np.array([turned(m, k, -h) for m in stored])
        d_plus = client.distances(pairs, poses_a=plus, warm_start=False).distance
        d_minus = client.distances(pairs, poses_a=minus, warm_start=False).distance
        differences[:, k] = (d_plus - d_minus) / (2 * h)
    assert judge_differences(rows, differences, pairs) > 10
    # Two balls: moving the first along the line of centres, -1 per unit
    # of distance; turning a ball about its centre changes nothing.
    balls = obstacles[1::2]
    centres = client.poses(balls)[:, :3]
    ball_pairs = np.array([[balls[0], balls[1]], [balls[1], balls[2]]], dtype=np.uint64)
    got = client.distances(ball_pairs, out=gjkd.Distances(2, gradient_columns=6))
    for i, (a, b) in enumerate([(0, 1), (1, 2)]):
        line = centres[b] - centres[a]
        want = np.concatenate([-line / np.linalg.norm(line), np.zeros(3)])
        np.testing.assert_allclose(got.gradient[i], want, atol=1e-12)


def test_gradient_rooms_refuse_bad_columns_and_a_base_alone(
    panda: tuple[gjkd.Client, Any, list[int]],
) -> None:
    client, robot, obstacles = panda
    link = int(robot.link("panda_link4"))  # moved by joints 1 to 3
    for make in (gjkd.Distances, gjkd.SceneRows):
        with pytest.raises(gjkd.InvalidInput) as e:
            make(4, gradient_columns=17)
        assert e.value.field == "gradient_columns"
        with pytest.raises(gjkd.InvalidInput) as e:
            make(4, gradient_base=True)
        assert e.value.field == "gradient_base"
        assert make(4, gradient_columns=16).gradient.shape == (4, 16)
    with pytest.raises(gjkd.InvalidInput) as e:
        client.distance(link, obstacles[0], gradient_base=True)
    assert e.value.field == "gradient_base"
    # A room of another size is refused, and nothing is written.
    out = gjkd.Distances(3, gradient_columns=robot.dof)
    good = np.array([[link, obstacles[0]], [link, obstacles[1]]], dtype=np.uint64)
    with pytest.raises(gjkd.InvalidInput) as e:
        client.distances(good, out=out)
    assert e.value.field == "out"
    assert not out.gradient.any() and not out.gradient_flags.any()
    # A pair that fails has its error and no gradient (not the one an
    # earlier call left in its row); the others are answered.
    out = client.distances(good, out=gjkd.Distances(2, gradient_columns=robot.dof))
    assert (out.gradient_flags & 1).all() and out.gradient.any(axis=1).all()
    bad = np.array([[link, obstacles[0]], [link, 10**9]], dtype=np.uint64)
    client.distances(bad, out=out)
    assert out.error[0] == 0 and out.error[1] == gjkd.ErrorCode.UNKNOWN_OBJECT
    assert out.gradient_flags[0] & 1 and out.gradient_flags[1] == 0
    assert not out.gradient[1].any() and out.gradient_error[1] == 0.0


def load_example() -> ModuleType:
    spec = importlib.util.spec_from_file_location("trajopt_panda", EXAMPLE)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["trajopt_panda"] = module
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("backend", ["gjkd", "coal"])
def test_the_trajectory_optimisation_example_clears_the_path(backend: str) -> None:
    pytest.importorskip("scipy", reason="scipy is not installed: the example needs it")
    if backend == "coal":
        pytest.importorskip("pinocchio", reason="pinocchio is not installed (pip install pin)")
        pytest.importorskip("coal", reason="coal is not installed (pip install coal)")
    example = load_example()
    out = example.run(backend, obstacles=15, waypoints=6)
    assert out.converged, out
    # The straight path went through obstacles; the optimised one clears
    # every obstacle by the margin.
    assert out.least >= 0.03 - 1e-6
    assert out.iterations >= 2

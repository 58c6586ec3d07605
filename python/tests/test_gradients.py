"""Distance gradients through the Python client: the Panda's link-obstacle
gradients against pinocchio's frame Jacobians at gjkd's witness points
(an independent kinematics library), scene rows against the pair query,
and the trajectory optimisation example (gjkd, and pinocchio + coal as
the baseline) run small."""

from __future__ import annotations

import importlib.util
import itertools
import pathlib
import sys
from types import ModuleType
from typing import Any, Iterator

import numpy as np
import pytest

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
        for link_name, link_id in zip(robot.link_names, robot.link_ids):
            # The fingers' columns differ in layout (pinocchio keeps the
            # mimic joint's own column; gjkd folds it into its leader's).
            if link_id == 0 or "finger" in link_name or not model.existFrame(link_name):
                continue
            frame = model.getFrameId(link_name)
            jacobian = pin.getFrameJacobian(model, data, frame, pin.LOCAL_WORLD_ALIGNED)
            origin = data.oMf[frame].translation
            for obstacle in obstacles:
                answer = client.distance(int(link_id), obstacle, gradient=True)
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

"""Robots from a URDF the test writes (box, sphere and mesh links, a
revolute, a second revolute, a prismatic and a fixed joint): forward
kinematics against transforms computed here by hand, link distances
through the server against analytic answers, and every bad input. Every
test that takes ``client`` runs on a ``gjkd.Client`` and on a
``gjkd.Local``: the in-process store offers the same robot calls."""

from __future__ import annotations

import itertools
import math
import pathlib
from typing import Any, Iterator

import numpy as np
import pytest
from test_meshes import write_binary_stl

import gjkd
from conftest import unique_service

_robots = itertools.count()

FORE_LENGTH = 0.4
ARM_URDF = """<?xml version="1.0"?>
<robot name="testarm">
  <link name="base">
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="upper">
    <collision><geometry><sphere radius="0.05"/></geometry></collision>
  </link>
  <link name="fore">
    <collision><geometry><mesh filename="meshes/fore.stl"/></geometry></collision>
  </link>
  <link name="tip">
    <collision>
      <origin xyz="0.05 0 0" rpy="0 0 0"/>
      <geometry><box size="0.1 0.1 0.1"/></geometry>
    </collision>
  </link>
  <link name="tool"/>
  <link name="pin">
    <collision><geometry><cylinder radius="0.03" length="0.2"/></geometry></collision>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/>
    <axis xyz="0 0 1"/>
    <limit lower="-3.14159" upper="3.14159" effort="1" velocity="1"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="fore"/>
    <origin xyz="0.5 0 0" rpy="0 0 0"/>
    <axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/>
  </joint>
  <joint name="slide" type="prismatic">
    <parent link="fore"/><child link="tip"/>
    <origin xyz="0.4 0 0" rpy="0 0 0"/>
    <axis xyz="1 0 0"/>
    <limit lower="0" upper="0.2" effort="1" velocity="1"/>
  </joint>
  <joint name="flange" type="fixed">
    <parent link="tip"/><child link="tool"/>
    <origin xyz="0.1 0 0" rpy="0 0 1.5707963267948966"/>
  </joint>
  <joint name="pin_mount" type="fixed">
    <parent link="upper"/><child link="pin"/>
    <origin xyz="0 0 0.2" rpy="0 0 0"/>
  </joint>
</robot>
"""


def box_mesh(lo: list[float], hi: list[float]) -> tuple[np.ndarray, np.ndarray]:
    v = np.array(
        [
            [(lo, hi)[i & 1][0], (lo, hi)[(i >> 1) & 1][1], (lo, hi)[(i >> 2) & 1][2]]
            for i in range(8)
        ]
    )
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    t = np.array([tri for a, b, c, d in quads for tri in ((a, b, c), (a, c, d))])
    return v, t


@pytest.fixture(scope="module")
def arm_dir(tmp_path_factory: pytest.TempPathFactory) -> pathlib.Path:
    d = tmp_path_factory.mktemp("arm")
    (d / "meshes").mkdir()
    v, t = box_mesh([0.0, -0.05, -0.05], [FORE_LENGTH, 0.05, 0.05])
    write_binary_stl(d / "meshes" / "fore.stl", v, t)
    (d / "arm.urdf").write_text(ARM_URDF)
    (d / "arm.srdf").write_text(
        '<robot name="testarm"><disable_collisions link1="base" link2="fore" reason="x"/></robot>'
    )
    return d


def robot_name() -> str:
    return f"arm{next(_robots)}"


@pytest.fixture()
def client(objects: Any) -> Any:
    """A Client of the module's server, then a Local (conftest's
    ``objects``)."""
    return objects


@pytest.fixture()
def arm(client: gjkd.Client, arm_dir: pathlib.Path) -> Iterator[gjkd.Robot]:
    yield client.register_robot(robot_name(), arm_dir / "arm.urdf", srdf=arm_dir / "arm.srdf")


# Hand-written kinematics: 4x4 matrices, independent of the library's.
def trans(x: float, y: float, z: float) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = [x, y, z]
    return m


def rot_z(a: float) -> np.ndarray:
    m = np.eye(4)
    m[:2, :2] = [[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]]
    return m


def rot_y(a: float) -> np.ndarray:
    m = np.eye(4)
    m[0, 0], m[0, 2], m[2, 0], m[2, 2] = math.cos(a), math.sin(a), -math.sin(a), math.cos(a)
    return m


def hand_fk(q: np.ndarray, base: np.ndarray) -> dict[str, np.ndarray]:
    upper = base @ trans(0, 0, 0.1) @ rot_z(q[0])
    fore = upper @ trans(0.5, 0, 0) @ rot_y(q[1])
    tip = fore @ trans(0.4, 0, 0) @ trans(q[2], 0, 0)
    tool = tip @ trans(0.1, 0, 0) @ rot_z(math.pi / 2)
    pin = upper @ trans(0, 0, 0.2)
    return {"base": base, "upper": upper, "fore": fore, "tip": tip, "tool": tool, "pin": pin}


def matrix(row: np.ndarray) -> np.ndarray:
    x, y, z, w = row[3:]
    m = np.eye(4)
    m[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]
    m[:3, 3] = row[:3]
    return m


def test_links_and_joints(arm: gjkd.Robot) -> None:
    assert arm.link_names == ["base", "upper", "fore", "tip", "tool", "pin"]
    assert arm.joint_names == ["shoulder", "elbow", "slide"]
    assert arm.dof == 3 and len(arm) == 6
    assert list(arm.positions) == [0.0, 0.0, 0.0]
    assert list(arm.lower) == [-3.14159, -2.0, 0.0]
    assert list(arm.upper) == [3.14159, 2.0, 0.2]
    assert arm.limits()["slide"] == (0.0, 0.2)
    ids = arm.link_ids
    assert ids.dtype == np.uint64 and ids[4] == 0 and all(ids[:4] > 0) and ids[5] > 0
    assert arm.link("tool") is None
    assert arm.link("tip") == ids[3]
    with pytest.raises(gjkd.NotFound) as e:
        arm.link("elbow")
    assert e.value.field == "name"


def test_forward_kinematics_matches_hand_transforms(arm: gjkd.Robot) -> None:
    rng = np.random.default_rng(3)
    base = [0.3, -0.2, 0.1, 0.0, 0.0, math.sin(0.35), math.cos(0.35)]
    for _ in range(8):
        q = rng.uniform(arm.lower, arm.upper)
        poses = arm.link_poses(q, base)
        expected = hand_fk(q, trans(0.3, -0.2, 0.1) @ rot_z(0.7))
        for i, link in enumerate(arm.link_names):
            assert np.max(np.abs(matrix(poses[i]) - expected[link])) < 1e-12, link


def test_set_joints_moves_links_on_the_server(client: gjkd.Client, arm: gjkd.Robot) -> None:
    """A small ball placed 0.3 along a link's local z axis (by the hand
    kinematics) is 0.3 - 0.05 - 0.05 from it, wherever the joints are."""
    ball = client.register_sphere(0.05)
    rng = np.random.default_rng(11)
    base_m = trans(1.0, 2.0, 0.0) @ rot_z(-0.4)
    base = [1.0, 2.0, 0.0, 0.0, 0.0, math.sin(-0.2), math.cos(-0.2)]
    for step in range(6):
        q = rng.uniform(arm.lower, arm.upper)
        client.set_joints(arm, q, base=base if step == 0 else None)
        assert np.array_equal(arm.positions, q)
        frames = hand_fk(q, base_m)
        tip_centre = frames["tip"] @ [0.05, 0, 0, 1]
        fore_centre = frames["fore"] @ [0.2, 0, 0, 1]
        for link, centre, frame in (
            ("tip", tip_centre, frames["tip"]),
            ("fore", fore_centre, frames["fore"]),
            ("upper", frames["upper"][:, 3], frames["upper"]),
        ):
            p = centre[:3] + 0.3 * frame[:3, 2]
            client.set_pose(ball, [*p, 0.0, 0.0, 0.0, 1.0])
            d = client.distance(arm.link(link), ball).distance
            assert abs(d - 0.2) < 1e-9, (link, step, d)
        # The pin, an exact cylinder of radius 0.03: a ball 0.3 out along
        # its x axis, level with its middle, is 0.3 - 0.03 - 0.05 away.
        p = frames["pin"][:3, 3] + 0.3 * frames["pin"][:3, 0]
        client.set_pose(ball, [*p, 0.0, 0.0, 0.0, 1.0])
        d = client.distance(arm.link("pin"), ball).distance
        assert abs(d - 0.22) < 1e-9, (step, d)


def test_set_joints_by_name_and_clamp(client: gjkd.Client, arm: gjkd.Robot) -> None:
    client.set_joints(arm, np.array([0.5, 0.0, 0.1]))
    client.set_joints(arm, {"elbow": -1.0})
    assert list(arm.positions) == [0.5, -1.0, 0.1]
    client.set_joints(arm, np.array([0.0, 5.0, -1.0]), clamp=True)
    assert list(arm.positions) == [0.0, 2.0, 0.0]
    # The server clamped too: the tip sits where the clamped positions put it.
    ball = client.register_sphere(0.05)
    frames = hand_fk(np.array([0.0, 2.0, 0.0]), np.eye(4))
    p = (frames["tip"] @ [0.05, 0, 0, 1])[:3] + 0.5 * frames["tip"][:3, 1]
    client.set_pose(ball, [*p, 0, 0, 0, 1])
    assert abs(client.distance(arm.link("tip"), ball).distance - 0.4) < 1e-9
    poses = arm.link_poses([0.0, 5.0, 0.0], clamp=True)
    assert np.allclose(matrix(poses[3]), frames["tip"], atol=1e-12)


def test_joint_errors_change_nothing(client: gjkd.Client, arm: gjkd.Robot) -> None:
    client.set_joints(arm, np.array([0.1, 0.2, 0.05]))

    def raises(kind: type, call: Any, code: Any, field: str, index: "int | None") -> None:
        with pytest.raises(kind) as e:
            call()
        assert e.value.code == code, e.value
        assert e.value.field == field, e.value
        assert e.value.index == index, e.value

    E = gjkd.ErrorCode
    raises(
        gjkd.InvalidInput,
        lambda: client.set_joints(arm, np.array([0.0, 2.5, 0.0])),
        E.OUT_OF_LIMITS,
        "positions",
        1,
    )
    raises(
        gjkd.InvalidInput,
        lambda: client.set_joints(arm, np.array([0.0, 0.0, math.nan])),
        E.NON_FINITE_POSE,
        "positions",
        2,
    )
    raises(gjkd.InvalidInput, lambda: client.set_joints(arm, np.zeros(2)), None, "positions", None)
    raises(
        gjkd.NotFound,
        lambda: client.set_joints(arm, {"wrist": 0.0}),
        E.UNKNOWN_NAME,
        "positions",
        None,
    )
    raises(
        gjkd.InvalidInput,
        lambda: client.set_joints(arm, np.zeros(3), base=[math.nan, 0, 0, 0, 0, 0, 1]),
        E.NON_FINITE_POSE,
        "base",
        None,
    )
    raises(
        gjkd.InvalidInput,
        lambda: client.set_joints(arm, np.zeros(3), base=[0, 0, 0, 0, 0, 0, 2]),
        E.BAD_QUATERNION,
        "base",
        None,
    )
    assert list(arm.positions) == [0.1, 0.2, 0.05]
    # The server kept the last good positions.
    ball = client.register_sphere(0.05)
    frames = hand_fk(np.array([0.1, 0.2, 0.05]), np.eye(4))
    p = (frames["tip"] @ [0.05, 0, 0, 1])[:3] + 0.3 * frames["tip"][:3, 2]
    client.set_pose(ball, [*p, 0, 0, 0, 1])
    assert abs(client.distance(arm.link("tip"), ball).distance - 0.2) < 1e-9


def test_robot_registration_errors(client: gjkd.Client, arm_dir: pathlib.Path) -> None:
    def invalid(call: Any, field: str, words: str) -> None:
        with pytest.raises(gjkd.InvalidInput) as e:
            call()
        assert e.value.field == field, e.value
        assert words in str(e.value), e.value

    name = robot_name()
    invalid(lambda: client.register_robot(name, arm_dir / "none.urdf"), "urdf", "none.urdf")
    invalid(lambda: client.register_robot(name, urdf_text="<robot"), "urdf", "")
    # URDF text: the relative mesh path is relative to the working folder.
    invalid(lambda: client.register_robot(name, urdf_text=ARM_URDF), "urdf", "fore.stl")
    invalid(lambda: client.register_robot(name), "urdf", "urdf")
    invalid(
        lambda: client.register_robot(name, arm_dir / "arm.urdf", srdf=arm_dir / "none.srdf"),
        "srdf",
        "none.srdf",
    )
    bad_srdf = '<robot name="testarm"><disable_collisions link1="base" link2="nolink"/></robot>'
    invalid(
        lambda: client.register_robot(name, arm_dir / "arm.urdf", srdf_text=bad_srdf),
        "urdf",
        "nolink",
    )
    # None of these left a link behind: the name is still free.
    with pytest.raises(gjkd.NotFound):
        client.lookup(f"{name}/base")
    robot = client.register_robot(name, arm_dir / "arm.urdf")
    with pytest.raises(gjkd.Refused) as e:
        client.register_robot(name, arm_dir / "arm.urdf")
    assert e.value.code == gjkd.ErrorCode.NAME_TAKEN
    # Another client finds it by name (a Local, itself).
    if isinstance(client, gjkd.Client):
        other = gjkd.Client(client.service)
    else:
        other = client
    with other:
        found = other.open_robot(name, ARM_URDF)
        assert found.id == robot.id and list(found.link_ids) == list(robot.link_ids)
        with pytest.raises(gjkd.NotFound) as e:
            other.open_robot("no-such-robot", ARM_URDF)
        assert e.value.code == gjkd.ErrorCode.UNKNOWN_NAME


def test_a_robot_is_removed_whole(client: gjkd.Client, arm_dir: pathlib.Path) -> None:
    """remove_robot takes the kinematics and every link, by robot or name."""
    name = robot_name()
    robot = client.register_robot(name, arm_dir / "arm.urdf")
    links = [i for i in robot.link_ids if i]
    with pytest.raises(gjkd.NotFound):
        client.remove(robot.id)  # the robot's id is no object id
    client.remove_robot(robot)
    for link in links:
        with pytest.raises(gjkd.NotFound):
            client.distance(link, link)
    with pytest.raises(gjkd.NotFound) as e:
        client.remove_robot(name)
    assert e.value.code == gjkd.ErrorCode.UNKNOWN_NAME
    # The name is free again, and a robot is removed by name too.
    client.register_robot(name, arm_dir / "arm.urdf")
    client.remove_robot(name)
    with pytest.raises(gjkd.NotFound):
        client.lookup(f"{name}/base")


def test_urdf_text_with_package_path(client: gjkd.Client, arm_dir: pathlib.Path) -> None:
    text = ARM_URDF.replace("meshes/fore.stl", f"package://{arm_dir.name}/meshes/fore.stl")
    robot = client.register_robot(robot_name(), urdf_text=text, package_path=[arm_dir.parent])
    assert robot.link("fore") is not None
    with pytest.raises(gjkd.InvalidInput):
        client.register_robot(robot_name(), urdf_text=text, package_path=[])


def test_link_pairs_in_a_batch(client: gjkd.Client, arm: gjkd.Robot) -> None:
    """Link objects are ordinary ids: a batch of link-obstacle pairs."""
    client.set_joints(arm, np.array([math.pi / 2, 0.0, 0.1]))
    wall = client.register_box([1.0, 0.05, 1.0], pose=[0.0, 1.6, 0.1, 0, 0, 0, 1])
    ids = arm.link_ids[:4]
    result = client.distances(np.array([[i, wall] for i in ids], dtype=np.uint64))
    assert list(result.error) == [0, 0, 0, 0]
    # Along world y: base box to 0.1, upper sphere to 0.05, fore to 0.9,
    # tip box (slid 0.1) to 1.1; the wall's face is at 1.55.
    assert np.allclose(result.distance, [1.45, 1.5, 0.65, 0.45], atol=1e-9)


def test_robot_unknown_service_name_is_independent() -> None:
    # A robot call on a closed client raises like any other call.
    with gjkd.Server(service=unique_service("robot")) as server:
        c = gjkd.Client(server.service)
        c.close()
        with pytest.raises(gjkd.Error):
            c.register_robot("x", urdf_text=ARM_URDF)


def test_poses_read_links_back_where_the_joints_put_them(
    client: gjkd.Client, arm: gjkd.Robot
) -> None:
    """`poses` of the links after `set_joints` against the hand kinematics."""
    q = np.array([0.4, -0.7, 0.05])
    base = [0.3, -0.2, 0.1, 0.0, 0.0, math.sin(0.35), math.cos(0.35)]
    client.set_joints(arm, q, base=base)
    names = [n for n, i in zip(arm.link_names, arm.link_ids) if i != 0]
    got = client.poses([arm.link(n) for n in names])
    assert got.shape == (len(names), 7) and got.dtype == np.float64
    expected = hand_fk(q, trans(0.3, -0.2, 0.1) @ rot_z(0.7))
    for row, name in zip(got, names):
        assert np.max(np.abs(matrix(row) - expected[name])) < 1e-12, name
    # The same rows as the client computes from the same joints.
    local_rows = arm.link_poses(q, base)
    for row, name in zip(got, names):
        assert np.max(np.abs(row - local_rows[arm.link_names.index(name)])) < 1e-12, name

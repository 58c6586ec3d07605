"""A robot without moving joints moves by its base alone: ``set_joints``
with no positions places its link where the base puts it, against the
closed-form distance to a ball. Each test runs on a ``gjkd.Client`` and on
a ``gjkd.Local``."""

from __future__ import annotations

import math
from typing import Any

import pytest

import gjkd
from conftest import unique_service

TABLE = """<robot name="table">
  <link name="top"><collision><geometry><box size="1.0 0.5 0.2"/></geometry></collision></link>
</robot>"""


@pytest.fixture()
def client(objects: Any) -> Any:
    """A Client of the module's server, then a Local (conftest's
    ``objects``)."""
    return objects


def test_a_robot_without_moving_joints_moves_by_its_base(client: gjkd.Client) -> None:
    table = client.register_robot(unique_service("table"), urdf_text=TABLE)
    assert len(table.joint_names) == 0
    top = table.link("top")
    assert top is not None
    ball = client.register_sphere(0.1, pose=[0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0])
    assert math.isclose(client.distance(top, ball).distance, 0.8, abs_tol=1e-9)
    # Raised by 0.5 and turned a quarter about x: half extent 0.25 along z.
    s = math.sqrt(0.5)
    client.set_joints(table, [], base=[0.0, 0.0, 0.5, s, 0.0, 0.0, s])
    assert math.isclose(client.distance(top, ball).distance, 0.15, abs_tol=1e-9)
    # Neither positions nor base: nothing moves.
    client.set_joints(table, [])
    assert math.isclose(client.distance(top, ball).distance, 0.15, abs_tol=1e-9)
    client.remove(ball)


def test_robot_faults_carry_the_codes_of_the_server(client: gjkd.Client) -> None:
    table = client.register_robot(unique_service("coded"), urdf_text=TABLE)
    with pytest.raises(gjkd.NotFound) as e:
        client.set_joints(table, {"no_such_joint": 0.0})
    assert e.value.code == gjkd.ErrorCode.UNKNOWN_NAME
    with pytest.raises(gjkd.InvalidInput) as bad:
        client.register_robot(unique_service("bad"), urdf_text="<robot name='x'><link")
    assert bad.value.code == gjkd.ErrorCode.INVALID_ROBOT
    assert bad.value.field == "urdf"
    # Opening a robot by name reads its URDF here too: the same fault, the
    # same code (Rust's ClientError::InvalidRobot, C's GJKD_CODE_INVALID_ROBOT).
    with pytest.raises(gjkd.InvalidInput) as unread:
        client.open_robot(unique_service("coded"), "<robot name='x'><link")
    assert unread.value.code == gjkd.ErrorCode.INVALID_ROBOT
    assert unread.value.field == "urdf"

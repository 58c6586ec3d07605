"""Objects that end with their client (``Client(..., remove_on_close=True)``):
what such a client registered, robots whole, is gone once it closes, while
the objects of a client without the option stay."""

import math

import pytest

import gjkd
from conftest import unique_service

URDF = """<robot name="arm">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="tip"><collision><origin xyz="1 0 0"/>
    <geometry><sphere radius="0.1"/></geometry></collision></link>
  <joint name="turn" type="revolute"><parent link="base"/><child link="tip"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"""


def test_objects_end_with_their_client_when_asked(server: gjkd.Server, client: gjkd.Client) -> None:
    kept = client.register_sphere(0.5, name=unique_service("kept"))
    ball_name = unique_service("ball")
    arm_name = unique_service("arm")
    with gjkd.Client(server.service, remove_on_close=True) as passing:
        ball = passing.register_sphere(
            0.25, pose=[3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0], name=ball_name
        )
        arm = passing.register_robot(arm_name, urdf_text=URDF)
        tip = arm.link("tip")
        # 3 - 0.5 - 0.25 from the other client.
        assert math.isclose(client.distance(kept, ball).distance, 2.25, abs_tol=1e-12)
    for gone in (ball, tip):
        with pytest.raises(gjkd.NotFound) as e:
            client.distance(kept, gone)
        assert e.value.code == gjkd.ErrorCode.UNKNOWN_OBJECT
    with pytest.raises(gjkd.NotFound) as e:
        client.lookup(ball_name)
    assert e.value.code == gjkd.ErrorCode.UNKNOWN_NAME
    with pytest.raises(gjkd.NotFound):
        client.lookup(f"{arm_name}/tip")

    # The default: objects outlive their client.
    stays_name = unique_service("stays")
    with gjkd.Client(server.service) as lasting:
        stays = lasting.register_sphere(0.1, name=stays_name)
    assert client.lookup(stays_name) == stays

"""Continuous paths from Python: every pose of the motion between steps,
certified clear or its first contact bracketed, against the closed form;
on a ``gjkd.Client`` and on a ``gjkd.Local``."""

from __future__ import annotations

from typing import Iterator

import numpy as np
import pytest

import gjkd
from conftest import unique_service


def at(x: float, y: float = 0.0, z: float = 0.0) -> list[float]:
    return [x, y, z, 0.0, 0.0, 0.0, 1.0]


@pytest.fixture(params=["client", "local"])
def client(request: pytest.FixtureRequest) -> Iterator[gjkd.Client]:
    if request.param == "local":
        with gjkd.Local() as local:
            yield local  # type: ignore[misc]
        return
    with gjkd.Server(service=unique_service("continuous"), wait="spin") as server:
        with gjkd.Client(server.service) as c:
            yield c


def test_a_thin_plate_between_samples_is_found(client: gjkd.Client) -> None:
    ball = client.register_sphere(0.01)
    plate = client.register_box([0.5e-4, 1.0, 1.0])
    rows = gjkd.SceneRows(4)
    ends = np.array([at(-3.0), at(3.3)])
    s = client.path([ball], [ball], ends, out=rows, question="continuous", bracket=1e-9)
    assert s.written == 1 and s.first_hit == 0
    assert (rows.a[0], rows.b[0]) == (ball, plate)
    # x = -3 + 6.3 s touches the plate 0.01005 before x = 0.
    exact = (3.0 - 0.01005) / 6.3
    assert rows.s_lo[0] <= exact <= rows.s_hi[0]
    assert rows.s_hi[0] - rows.s_lo[0] <= 1e-9
    assert rows.lower[0] <= 0.0
    # Ten samples miss it.
    steps = np.array([at(-3.0 + 0.63 * k) for k in range(11)])
    assert client.path([ball], [ball], steps, out=rows, question="first_hit").first_hit is None
    # Beside the plate, the whole motion is certified clear.
    beside = np.array([at(-3.0, 2.0), at(3.3, 2.0)])
    assert client.path([ball], [ball], beside, out=rows, question="continuous").written == 0


def test_bad_continuous_paths_raise(client: gjkd.Client) -> None:
    ball = client.register_sphere(0.1)
    rows = gjkd.SceneRows(4)
    ends = np.array([at(-1.0), at(1.0)])
    # A bracket of 0, and a segment along which nothing moves.
    with pytest.raises(gjkd.Error):
        client.path([ball], [ball], ends, out=rows, question="continuous", bracket=0.0)
    with pytest.raises(gjkd.Error):
        client.path([ball], [ball], np.array([at(1.0), at(1.0)]), out=rows, question="continuous")
    with pytest.raises(gjkd.InvalidInput):
        client.path([ball], [ball], ends, out=rows, question="sideways")

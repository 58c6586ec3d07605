"""A path longer than one request takes comes back whole with the server's
default limits: 1 000 steps of three moving objects (3 000 items, over
``max_batch``; 3 000 rows), split by the client, against the same question
asked at single steps."""

from __future__ import annotations

import numpy as np

import gjkd


def test_a_1000_step_path_comes_back_whole(client: gjkd.Client) -> None:
    info = client.server_info()
    assert info is not None
    group = [client.register_sphere(0.1) for _ in range(3)]
    wall = client.register_box([0.1, 3.0, 3.0], pose=[2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
    steps = 1000
    poses = np.zeros((steps * 3, 7))
    for s in range(steps):
        for i in range(3):
            poses[s * 3 + i] = [1.5 * s / steps, 0.5 * i, 0.0, 0.0, 0.0, 0.0, 1.0]
    assert steps * 3 > info["max_batch"]
    rows = gjkd.SceneRows(steps * 3 + 8)
    summary = client.path(group, group, poses, out=rows)
    assert not summary.truncated
    assert (summary.steps, summary.written, summary.total) == (steps, steps * 3, steps * 3)
    assert np.array_equal(rows.step[: steps * 3], np.repeat(np.arange(steps), 3))
    # Each member's clearance is the wall's face (x = 1.9) minus its x and
    # radius: exact for every converged row, inside the interval for all.
    want = 1.9 - poses[:, 0] - 0.1
    assert np.all(rows.b[: steps * 3] == wall)
    assert np.all(rows.lower[: steps * 3] <= want + 1e-9)
    assert np.all(want - 1e-9 <= rows.upper[: steps * 3])
    exact = client.path(group, group, poses, out=rows, exact=True)
    assert exact.written == steps * 3
    assert np.allclose(rows.distance[: steps * 3], want, atol=1e-9)
    for g in group:
        client.remove(g)
    client.remove(wall)

"""``exact=True``: every reported scene row carries its converged distance,
where without it rows proved inside a margin early (``CLOSER``) or answered
from motion bounds (``BOUNDED``) carry estimates; against the closed-form
distance between a ball and boxes; on a ``gjkd.Client`` and on a
``gjkd.Local``."""

from __future__ import annotations

import numpy as np

import gjkd


def test_exact_rows_carry_converged_distances(objects: gjkd.Client) -> None:
    client = objects
    radius, half = 0.1, np.array([0.2, 0.3, 0.25])
    ball = client.register_sphere(radius)
    centres = [
        np.array([1.5 * np.cos(0.52 * i) + 0.3, 1.5 * np.sin(0.52 * i), 0.2 * (i % 3)])
        for i in range(12)
    ]
    boxes = [client.register_box(half, pose=[*c, 0.0, 0.0, 0.0, 1.0]) for c in centres]
    rows = gjkd.SceneRows(64)
    estimates = {int(gjkd.Status.CLOSER), int(gjkd.Status.BOUNDED)}
    seen = 0
    for step in range(6):
        at = np.array([0.02 * step, 0.01 * step, 0.0])
        client.set_pose(ball, [*at, 0.0, 0.0, 0.0, 1.0])
        want = {
            b: np.linalg.norm(np.maximum(np.abs(at - c) - half, 0.0)) - radius
            for b, c in zip(boxes, centres)
        }
        loose = client.within(ball, 3.0, out=rows)
        seen += sum(int(s) in estimates for s in rows.status[: loose.written])
        exact = client.within(ball, 3.0, out=rows, exact=True)
        assert exact.written == len(boxes)
        for b, d, s in zip(
            rows.b[: exact.written], rows.distance[: exact.written], rows.status[: exact.written]
        ):
            assert int(s) not in estimates
            assert abs(d - want[int(b)]) <= 1e-9 * (1.0 + want[int(b)])
    assert seen > 0, "estimates without exact"
    for b in boxes:
        client.remove(b)
    client.remove(ball)

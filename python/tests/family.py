"""The twelve polytopes and twenty pairs of Section 7 of Gilbert, Johnson and
Keerthi (1986), rebuilt in Python from the recipe of ``gjk``'s test kit (the
same shapes and sizes; the random two-plane polytopes and the poses come from
numpy's generator, not the Rust one, so the vertices are not the Rust
family's bit for bit). Used to compare a server's answers with
``gjkd.Local``'s on the same inputs."""

from __future__ import annotations

import math
from typing import List, Tuple

import numpy as np

VERTEX_COUNTS = [2, 3, 8, 12, 16, 20, 20, 40, 50, 60, 100, 100]

# The paper's (i, 2), (i, 4), (i, 5), (i, 10) for i = 1, 3, 6, 8, then
# (7, 9), (7, 12), (11, 9), (11, 12), 0-based.
PAIRS: List[Tuple[int, int]] = [
    (0, 1), (0, 3), (0, 4), (0, 9),
    (2, 1), (2, 3), (2, 4), (2, 9),
    (5, 1), (5, 3), (5, 4), (5, 9),
    (7, 1), (7, 3), (7, 4), (7, 9),
    (6, 8), (6, 11), (10, 8), (10, 11),
]  # fmt: skip

MAX_GAP = 20.0 / 3.0


def _prism(n: int, r_bottom: float, r_top: float, half_h: float) -> np.ndarray:
    rows = []
    for r, z in ((r_bottom, -half_h), (r_top, half_h)):
        for k in range(n):
            a = 2.0 * math.pi * k / n
            rows.append((r * math.cos(a), r * math.sin(a), z))
    return np.array(rows)


def _two_plane(rng: np.random.Generator, m: int, radius: float) -> np.ndarray:
    half = m // 2
    h = rng.uniform(0.3, 1.0)
    rows = []
    for z in (-h, h):
        a, b = rng.uniform(0.5, 1.0), rng.uniform(0.5, 1.0)
        tilt = rng.uniform(0.0, math.pi)
        cx, cy = rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2)
        phase = rng.uniform(0.0, 2.0 * math.pi)
        for k in range(half):
            t = phase + 2.0 * math.pi * (k + 0.8 * rng.uniform()) / half
            x, y = a * math.cos(t), b * math.sin(t)
            s, c = math.sin(tilt), math.cos(tilt)
            rows.append((cx + c * x - s * y, cy + s * x + c * y, z))
    v = np.array(rows)
    v -= v.mean(axis=0)
    return v * (radius / np.linalg.norm(v, axis=1).max())


def family(seed: int = 1986) -> List[np.ndarray]:
    """The twelve vertex sets, ``(M, 3)`` float64 each, in the paper's order."""
    out = [np.array([(0.0, 0.0, -1.5), (0.0, 0.0, 1.5)])]
    out.append(
        np.array(
            [
                (
                    2.0 * math.cos(2 * math.pi * k / 3 + math.pi / 2),
                    2.0 * math.sin(2 * math.pi * k / 3 + math.pi / 2),
                    0.0,
                )
                for k in range(3)
            ]
        )
    )
    h = (1.0, 1.5, 2.0)
    out.append(
        np.array(
            [
                (
                    h[0] if i & 1 else -h[0],
                    h[1] if i & 2 else -h[1],
                    h[2] if i & 4 else -h[2],
                )
                for i in range(8)
            ]
        )
    )
    out.append(_prism(6, 2.0, 1.0, 1.0))
    out.append(_prism(8, 1.5, 1.5, 1.5))
    out.append(_prism(10, 2.0, 2.0, 2.5))
    rng = np.random.default_rng(seed)
    for m, radius in zip(VERTEX_COUNTS[6:], [2.0, 3.0, 2.5, 3.5, 4.0, 3.0]):
        out.append(_two_plane(rng, m, radius))
    for v, m in zip(out, VERTEX_COUNTS):
        assert v.shape == (m, 3)
    return out


def random_rotations(rng: np.random.Generator, n: int) -> np.ndarray:
    """``(n, 4)`` uniform unit quaternions ``[qx, qy, qz, qw]`` (Shoemake)."""
    u1, u2, u3 = rng.uniform(size=(3, n))
    a, b = np.sqrt(1.0 - u1), np.sqrt(u1)
    t2, t3 = 2 * math.pi * u2, 2 * math.pi * u3
    q = np.stack([a * np.sin(t2), a * np.cos(t2), b * np.sin(t3), b * np.cos(t3)], axis=1)
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def separated_poses(
    rng: np.random.Generator, n: int, spread: float = 5.0
) -> Tuple[np.ndarray, np.ndarray]:
    """``n`` random pose pairs ``(N, 7)``: A in the cube ``[-5, 5]^3``, B at a
    random offset of 6 to 14 from it (a first placement: the cases are then
    slid along their near-point line, see ``cases``)."""
    poses_a = np.empty((n, 7))
    poses_b = np.empty((n, 7))
    poses_a[:, :3] = rng.uniform(-spread, spread, size=(n, 3))
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    poses_b[:, :3] = poses_a[:, :3] + direction * rng.uniform(6.0, 14.0, size=(n, 1))
    poses_a[:, 3:] = random_rotations(rng, n)
    poses_b[:, 3:] = random_rotations(rng, n)
    return poses_a, poses_b

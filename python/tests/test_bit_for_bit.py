"""A server and gjkd.Local give the same arrays, bit for bit, on the paper's
Section 7 family (separated, touching and intersecting examples), along a
warm-started motion, and on compounds of its members."""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np
import pytest

import gjkd
from family import PAIRS, family, random_rotations, separated_poses

FIELDS = (
    "distance", "lower", "upper", "penetration", "point_a", "point_b", "normal",
    "status", "iterations", "pieces", "error", "warm_started",
)  # fmt: skip


def assert_same_bits(x: gjkd.Distances, y: gjkd.Distances) -> None:
    for field in FIELDS:
        a, b = getattr(x, field), getattr(y, field)
        assert a.dtype == b.dtype and a.shape == b.shape, field
        # Compare the bytes: -0.0 against 0.0 or two NaNs would slip
        # through an equality test.
        assert a.tobytes() == b.tobytes(), field


def register_family(objects: Any, sets: Sequence[np.ndarray]) -> np.ndarray:
    return np.array([objects.register_polytope(v) for v in sets], dtype=np.uint64)


PER_PAIR = 25


def family_cases(local: gjkd.Local, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pairs and poses of the separated, touching and intersecting examples:
    separated ones drawn at random, then slid along their near-point line
    (found with ``local``) into contact and past it."""
    rng = np.random.default_rng(7)
    index = np.repeat(np.array(PAIRS), PER_PAIR, axis=0)
    pairs = ids[index]
    n = len(pairs)
    poses_a, poses_b = separated_poses(rng, n)
    first = local.distances(pairs, poses_a, poses_b, warm_start=False)
    assert np.all(first.error == 0)
    touching = poses_b.copy()
    touching[:, :3] -= first.normal * first.distance[:, None]
    inside = touching.copy()
    inside[:, :3] -= first.normal * rng.uniform(0.1, 0.5, size=(n, 1))
    all_pairs = np.concatenate([pairs, pairs, pairs])
    return (
        all_pairs,
        np.concatenate([poses_a, poses_a, poses_a]),
        np.concatenate([poses_b, touching, inside]),
    )


@pytest.mark.parametrize("tolerance", [gjkd.DEFAULT_TOLERANCE, 1e-6, 0.0])
def test_family_cold(client: gjkd.Client, tolerance: float) -> None:
    sets = family()
    local = gjkd.Local()
    server_ids = register_family(client, sets)
    local_ids = register_family(local, sets)
    pairs, poses_a, poses_b = family_cases(local, local_ids)
    from_local = local.distances(pairs, poses_a, poses_b, tolerance=tolerance, warm_start=False)
    server_pairs = server_ids[np.searchsorted(local_ids, pairs)]
    from_server = client.distances(
        server_pairs, poses_a, poses_b, tolerance=tolerance, warm_start=False
    )
    assert np.all(from_server.error == 0)
    assert_same_bits(from_server, from_local)
    # The examples are what they say: touching ones at distance ~0...
    n = len(pairs) // 3
    assert np.all(from_server.distance[n : 2 * n] < 1e-9)
    # Pushed past contact along the near-point line: most overlap (where
    # the line leaves A - B at a sharp edge at once, they part again).
    assert np.mean(from_server.distance[2 * n :] == 0.0) > 0.5


def test_family_warm_motion_and_stored_poses(client: gjkd.Client) -> None:
    sets = family()
    local = gjkd.Local()
    server_ids = register_family(client, sets)
    local_ids = register_family(local, sets)
    rng = np.random.default_rng(11)
    poses = np.zeros((12, 7))
    poses[:, :3] = rng.uniform(-8, 8, size=(12, 3))
    poses[:, 3:] = random_rotations(rng, 12)
    spin = random_rotations(rng, 12) * 0.02
    spin[:, 3] = 1.0
    index = np.array(PAIRS)
    for step in range(30):
        # Each object drifts and turns a little: every query starts from the
        # pair's last simplex, on the server as in Local.
        poses[:, :3] += 0.05 * np.sin(step + np.arange(12))[:, None]
        poses[:, 3:] = quat_mul(poses[:, 3:], spin)
        poses[:, 3:] /= np.linalg.norm(poses[:, 3:], axis=1, keepdims=True)
        client.set_poses(server_ids, poses)
        local.set_poses(local_ids, poses)
        from_server = client.distances(server_ids[index])
        from_local = local.distances(local_ids[index])
        assert_same_bits(from_server, from_local)
        if step > 0:
            assert np.all(from_server.warm_started)


def test_compounds_bit_for_bit(client: gjkd.Client) -> None:
    sets = family()
    rng = np.random.default_rng(5)
    local = gjkd.Local()
    pieces = []
    for k in range(4):
        offset = np.concatenate([rng.uniform(-3, 3, 3), random_rotations(rng, 1)[0]])
        pieces.append((offset, gjkd.Shape.polytope(sets[3 * k + 1], radius=0.05 * k)))
    ids = []
    for objects in (client, local):
        ids.append(
            (
                objects.register_compound(pieces),
                objects.register_compound(pieces[:2]),
                objects.register_polytope(sets[9], 0.1),
            )
        )
    n = 200
    poses_a, poses_b = separated_poses(rng, n, spread=2.0)
    combos = np.array([[0, 1], [0, 2], [1, 2], [2, 0]])[rng.integers(0, 4, n)]
    results = []
    for objects, own in zip((client, local), ids):
        pairs = np.array(own, dtype=np.uint64)[combos]
        results.append(objects.distances(pairs, poses_a, poses_b))
        results.append(objects.distances(pairs, poses_a, poses_b))
    assert np.all(results[0].error == 0)
    assert np.any(results[0].pieces != 0)
    assert_same_bits(results[0], results[2])
    assert_same_bits(results[1], results[3])


def test_large_batches_are_split(client: gjkd.Client) -> None:
    limit = client.server_info()["max_batch"]  # type: ignore[index]
    local = gjkd.Local()
    n = 2 * limit + 17
    rng = np.random.default_rng(3)
    sets = family()
    ids = [register_family(o, sets) for o in (client, local)]
    index = rng.integers(0, 12, size=(n, 2))
    poses_a, poses_b = separated_poses(rng, n)
    from_server = client.distances(ids[0][index], poses_a, poses_b, warm_start=False)
    from_local = local.distances(ids[1][index], poses_a, poses_b, warm_start=False)
    assert len(from_server) == n and np.all(from_server.error == 0)
    assert_same_bits(from_server, from_local)


def quat_mul(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Row-wise Hamilton products of ``[x, y, z, w]`` quaternions."""
    px, py, pz, pw = p.T
    qx, qy, qz, qw = q.T
    return np.stack(
        [
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
            pw * qw - px * qx - py * qy - pz * qz,
        ],
        axis=1,
    )


def test_poses_come_back_bit_for_bit_from_client_and_local(client: gjkd.Client) -> None:
    """`poses` reads back exactly what `set_poses` stored, the same bits
    from a server and from `Local`; an unknown id raises with its row."""
    rng = np.random.default_rng(5)
    rows = np.zeros((6, 7))
    rows[:, :3] = rng.uniform(-3, 3, (6, 3))
    q = rng.normal(size=(6, 4))
    rows[:, 3:] = q / np.linalg.norm(q, axis=1)[:, None]
    answers = []
    with gjkd.Local() as local:
        for objects in (client, local):
            ids = np.array([objects.register_sphere(0.1) for _ in range(6)], dtype=np.uint64)
            objects.set_poses(ids, rows)
            got = objects.poses(ids)
            assert got.shape == (6, 7) and got.dtype == np.float64
            assert np.array_equal(got.view(np.uint64), rows.view(np.uint64))
            assert objects.poses(np.array([], dtype=np.uint64)).shape == (0, 7)
            gone = int(ids[2])
            objects.remove(gone)
            with pytest.raises(gjkd.NotFound) as e:
                objects.poses([int(ids[0]), gone])
            assert e.value.code == gjkd.ErrorCode.UNKNOWN_OBJECT and e.value.index == 1
            answers.append(got)
    assert np.array_equal(answers[0].view(np.uint64), answers[1].view(np.uint64))

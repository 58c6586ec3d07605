"""No reference or memory leaks over 100 000 calls."""

from __future__ import annotations

import gc
import sys
import tracemalloc
from typing import Any, Callable

import numpy as np

import gjkd

CALLS = 100_000


def growth(call: Callable[[], Any], watched: list[Any]) -> tuple[list[int], int, int]:
    """Reference counts of ``watched`` objects, Python objects alive and
    traced memory, after against before ``CALLS`` calls (after a warm-up, so
    that caches filled once do not count)."""
    for _ in range(1000):
        call()
    gc.collect()
    refs = [sys.getrefcount(w) for w in watched]
    objects = len(gc.get_objects())
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    for _ in range(CALLS):
        call()
    gc.collect()
    after = tracemalloc.get_traced_memory()[0]
    tracemalloc.stop()
    refs_after = [sys.getrefcount(w) for w in watched]
    return (
        [b - a for a, b in zip(refs, refs_after)],
        len(gc.get_objects()) - objects,
        after - before,
    )


def check(objects: Any) -> None:
    a = objects.register_box([1.0, 1.0, 1.0])
    b = objects.register_sphere(0.5, pose=[3.0, 0, 0, 0, 0, 0, 1])
    pairs = np.array([[a, b]] * 4, dtype=np.uint64)
    poses = np.tile([0.0, 0, 0, 0, 0, 0, 1], (4, 1))
    pose = np.array([0.0, 0.5, 0, 0, 0, 0, 1])
    out = gjkd.Distances(4)
    ids = np.array([a])

    def batch() -> None:
        objects.distances(pairs, poses_a=poses, out=out)

    def fresh_batch() -> None:
        objects.distances(pairs, poses_b=poses)

    def single() -> None:
        objects.distance(a, b, pose)

    def store() -> None:
        objects.set_poses(ids, poses[:1])

    def failing() -> None:
        try:
            objects.distance(a, 12345)
        except gjkd.NotFound:
            pass

    for call, watched in (
        (batch, [pairs, poses, out, out.distance]),
        (fresh_batch, [pairs, poses]),
        (single, [pose]),
        (store, [ids, poses]),
        (failing, []),
    ):
        refs, alive, memory = growth(call, watched)
        assert refs == [0] * len(watched), (call.__name__, refs)
        assert alive < 100, (call.__name__, alive)
        # A leak of even one small object per call would be megabytes.
        assert memory < 100_000, (call.__name__, memory)


def test_client_does_not_leak(client: gjkd.Client) -> None:
    check(client)


def test_local_does_not_leak() -> None:
    check(gjkd.Local())

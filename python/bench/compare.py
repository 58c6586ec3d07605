"""gjkd from Python against coal and python-fcl, on the same box pairs, in one run.

    python python/bench/compare.py [--pairs 1000] [--repeats 30]

Prints, per pair: ``Client.distances`` in batches of 1, 64 and 1000, the Rust
client's ``query_batch`` on the same 1000 pairs (built and run from
``bench/examples/batch_cost.rs``), ``gjkd.Local`` warm and cold, ``coal`` and
``python-fcl`` called one pair at a time as their users call them (shapes and
transforms built before timing, so only the distance call and its result are
timed); the single-query round trip from Python (p50, p90); and each
library's error against gjkd's certified interval ``[lower, upper]``.

Needs the package installed (``pip install ./python``) and, for the peers,
``pip install coal python-fcl`` (left out with a note if missing). Starts its
own server (``wait="spin"``).

The Rust figure needs the ``batch_cost`` example, found in this order: the
program ``$GJKD_BATCH_COST`` names; built with cargo in the gjkd checkout
``--workspace`` names (default: the checkout this script sits in, if any)
into the target directory cargo uses there (``$CARGO_TARGET_DIR`` when set);
``batch_cost`` on ``$PATH``. Without any, its figure is left out with a
note, so the script runs from an install or a read-only checkout as well.
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import pathlib
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from typing import Any, Callable, Optional

import numpy as np

import gjkd

HERE = pathlib.Path(__file__).resolve().parent

# Turns taken by the Python and the Rust batches of 1000.
ROUNDS = 3


def random_rotations(rng: np.random.Generator, n: int) -> np.ndarray:
    u1, u2, u3 = rng.uniform(size=(3, n))
    a, b = np.sqrt(1.0 - u1), np.sqrt(u1)
    t2, t3 = 2 * np.pi * u2, 2 * np.pi * u3
    q = np.stack([a * np.sin(t2), a * np.cos(t2), b * np.sin(t3), b * np.cos(t3)], axis=1)
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def box_pairs(n: int, seed: int = 2026) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Half extents of A and B ``(n, 3)`` each, poses of A and B ``(n, 7)``:
    random sizes and rotations, B placed 0.05 to 3 beyond the bounding
    spheres, so every pair is separated."""
    rng = np.random.default_rng(seed)
    ha = rng.uniform(0.2, 1.0, size=(n, 3))
    hb = rng.uniform(0.2, 1.0, size=(n, 3))
    pa = np.empty((n, 7))
    pb = np.empty((n, 7))
    pa[:, :3] = rng.uniform(-5, 5, size=(n, 3))
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    reach = np.linalg.norm(ha, axis=1) + np.linalg.norm(hb, axis=1) + rng.uniform(0.05, 3.0, n)
    pb[:, :3] = pa[:, :3] + d * reach[:, None]
    pa[:, 3:] = random_rotations(rng, n)
    pb[:, 3:] = random_rotations(rng, n)
    return ha, hb, pa, pb


def rotation_matrices(q: np.ndarray) -> np.ndarray:
    x, y, z, w = q.T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=1,
    )


def per_pair(run: Callable[[], Any], pairs: int, repeats: int) -> float:
    """Median over ``repeats`` of the time of ``run()`` divided by
    ``pairs``, in µs, after a warm-up run."""
    run()
    times = []
    for _ in range(repeats):
        start = time.perf_counter_ns()
        run()
        times.append((time.perf_counter_ns() - start) / pairs / 1000)
    return statistics.median(times)


def interval_error(d: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """How far each distance lies outside ``[lower, upper]`` (0 inside)."""
    return np.maximum(0.0, np.maximum(lower - d, d - upper))


@functools.cache
def batch_cost_program(workspace: Optional[pathlib.Path]) -> Optional[pathlib.Path]:
    """The ``batch_cost`` example's program (see the module documentation),
    or None with a note saying why there is none."""
    named = os.environ.get("GJKD_BATCH_COST")
    if named:
        return pathlib.Path(named)
    if workspace is None:
        checkout = HERE.parent.parent
        workspace = checkout if (checkout / "bench" / "examples").is_dir() else None
    if workspace is not None and shutil.which("cargo"):
        # Where cargo puts it, whatever sets that ($CARGO_TARGET_DIR, a
        # .cargo/config.toml): cargo says.
        meta = subprocess.run(
            ["cargo", "metadata", "--format-version", "1", "--no-deps"],
            cwd=workspace,
            capture_output=True,
            text=True,
        )
        build = subprocess.run(
            [
                "cargo",
                "build",
                "--release",
                "--quiet",
                "-p",
                "gjkd-bench",
                "--example",
                "batch_cost",
            ],
            cwd=workspace,
        )
        if meta.returncode == 0 and build.returncode == 0:
            target = pathlib.Path(json.loads(meta.stdout)["target_directory"])
            return target / "release" / "examples" / "batch_cost"
        print(f"(the Rust query_batch example did not build in {workspace})")
    found = shutil.which("batch_cost")
    if found:
        return pathlib.Path(found)
    print(
        "(no batch_cost program: set GJKD_BATCH_COST, or --workspace to a gjkd checkout; "
        "the Rust query_batch figure is left out)"
    )
    return None


def rust_query_batch(service: str, ha: np.ndarray, hb: np.ndarray, pa: np.ndarray,
                     pb: np.ndarray, repeats: int,
                     workspace: Optional[pathlib.Path]) -> Optional[float]:  # fmt: skip
    """The Rust client's per-pair cost on the same pairs, in µs, or None
    without the Rust example."""
    program = batch_cost_program(workspace)
    if program is None:
        return None
    data = np.concatenate([[len(ha)], np.hstack([ha, hb, pa, pb]).ravel()]).astype("<f8")
    with tempfile.NamedTemporaryFile(suffix=".f64", delete=False) as f:
        f.write(data.tobytes())
    try:
        out = subprocess.run(
            [str(program), service, f.name, str(repeats)],
            capture_output=True,
            text=True,
            check=True,
        ).stdout
    finally:
        os.unlink(f.name)
    return float(out.split()[1]) / 1000


def coal_distances(ha: np.ndarray, hb: np.ndarray, pa: np.ndarray,
                   pb: np.ndarray) -> Optional[tuple[Callable[[], None], np.ndarray]]:  # fmt: skip
    try:
        import coal
    except ImportError as e:
        print(f"(coal not installed: {e}; `pip install coal`)")
        return None
    n = len(ha)
    boxes_a = [coal.Box(*(2 * h)) for h in ha]
    boxes_b = [coal.Box(*(2 * h)) for h in hb]
    ra, rb = rotation_matrices(pa[:, 3:]), rotation_matrices(pb[:, 3:])
    ta = [coal.Transform3s(ra[i], pa[i, :3]) for i in range(n)]
    tb = [coal.Transform3s(rb[i], pb[i, :3]) for i in range(n)]
    request = coal.DistanceRequest()
    out = np.empty(n)

    def run() -> None:
        for i in range(n):
            result = coal.DistanceResult()
            out[i] = coal.distance(boxes_a[i], ta[i], boxes_b[i], tb[i], request, result)

    return run, out


def fcl_distances(ha: np.ndarray, hb: np.ndarray, pa: np.ndarray,
                  pb: np.ndarray) -> Optional[tuple[Callable[[], None], np.ndarray]]:  # fmt: skip
    try:
        import fcl
    except ImportError as e:
        print(f"(python-fcl not installed: {e}; `pip install python-fcl`)")
        return None
    n = len(ha)

    def obj(h: np.ndarray, p: np.ndarray) -> Any:
        q_wxyz = np.array([p[6], p[3], p[4], p[5]])
        return fcl.CollisionObject(fcl.Box(*(2 * h)), fcl.Transform(q_wxyz, p[:3]))

    objs_a = [obj(ha[i], pa[i]) for i in range(n)]
    objs_b = [obj(hb[i], pb[i]) for i in range(n)]
    request = fcl.DistanceRequest(enable_nearest_points=True)
    out = np.empty(n)

    def run() -> None:
        for i in range(n):
            # A fresh result each call: fcl keeps the smallest distance seen.
            result = fcl.DistanceResult()
            out[i] = fcl.distance(objs_a[i], objs_b[i], request, result)

    return run, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pairs", type=int, default=1000)
    parser.add_argument("--repeats", type=int, default=30)
    parser.add_argument("--single", type=int, default=20000, help="single-query round trips")
    parser.add_argument(
        "--no-pin",
        action="store_true",
        help="leave the server and this process unpinned (default: server on CPU 1, "
        "this process and the Rust client on CPU 0, as `gjkd bench latency` does)",
    )
    parser.add_argument(
        "--workspace",
        type=pathlib.Path,
        default=None,
        help="a gjkd checkout to build the Rust example in (default: the one this script "
        "sits in, if any); see GJKD_BATCH_COST",
    )
    args = parser.parse_args()
    n = args.pairs
    ha, hb, pa, pb = box_pairs(n)
    service = f"gjkd-bench-py-{os.getpid()}"
    rows: list[tuple[str, float, str]] = []

    with gjkd.Server(service=service, wait="spin") as server, gjkd.Client(service) as client:
        pinned = not args.no_pin and len(os.sched_getaffinity(0)) >= 2
        if pinned:
            assert server.pid is not None
            os.sched_setaffinity(server.pid, {1})
            os.sched_setaffinity(0, {0})
        ids_a = np.array([client.register_box(h) for h in ha], dtype=np.uint64)
        ids_b = np.array([client.register_box(h) for h in hb], dtype=np.uint64)
        pairs = np.stack([ids_a, ids_b], axis=1)
        truth = client.distances(pairs, pa, pb, warm_start=False)
        assert np.all(truth.error == 0)

        calls: dict[int, list[int]] = {}

        def batched(batch: int) -> Callable[[], None]:
            chunks = [
                (pairs[s : s + batch], pa[s : s + batch], pb[s : s + batch])
                for s in range(0, n, batch)
            ]
            outs = [gjkd.Distances(len(c[0])) for c in chunks]
            times = calls.setdefault(batch, [])

            def run() -> None:
                for (p, a, b), o in zip(chunks, outs):
                    start = time.perf_counter_ns()
                    client.distances(p, a, b, out=o)
                    times.append(time.perf_counter_ns() - start)

            return run

        def median_call(batch: int) -> str:
            return f"median call {np.median(calls[batch]) / 1000 / batch:.3f} µs/pair"

        for batch in (1, 64):
            t = per_pair(batched(batch), n, args.repeats)
            rows.append((f"Client.distances, batch {batch}", t, median_call(batch)))
        # The Python and Rust batches of 1000 take turns, so that both see
        # the same machine (a 2-core machine shared with other work drifts).
        python_1000, rust_1000 = [], []
        for _ in range(ROUNDS):
            python_1000.append(per_pair(batched(1000), n, args.repeats))
            rust = rust_query_batch(service, ha, hb, pa, pb, args.repeats * 10, args.workspace)
            if rust is not None:
                rust_1000.append(rust)
        rows.append(
            ("Client.distances, batch 1000", statistics.median(python_1000), median_call(1000))
        )
        rust = statistics.median(rust_1000) if rust_1000 else None

        # Single-query round trip: one pair at its stored poses, from Python
        # and from Rust (a batch of one) in turns.
        client.set_poses(pairs[0], np.stack([pa[0], pb[0]]))
        a0, b0 = int(pairs[0, 0]), int(pairs[0, 1])
        single: list[int] = []
        rust_single = []
        for _ in range(ROUNDS):
            for _ in range(1000):
                client.distance(a0, b0)
            for _ in range(args.single // ROUNDS):
                start = time.perf_counter_ns()
                client.distance(a0, b0)
                single.append(time.perf_counter_ns() - start)
            one = rust_query_batch(
                service, ha[:1], hb[:1], pa[:1], pb[:1], args.single // ROUNDS, args.workspace
            )
            if one is not None:
                rust_single.append(one)
        single_p50 = float(np.percentile(single, 50)) / 1000
        single_p90 = float(np.percentile(single, 90)) / 1000

    local = gjkd.Local()
    lids = np.stack(
        [
            np.array([local.register_box(h) for h in ha], dtype=np.uint64),
            np.array([local.register_box(h) for h in hb], dtype=np.uint64),
        ],
        axis=1,
    )
    local_out = gjkd.Distances(n)
    for warm in (True, False):
        rows.append(
            (
                f"gjkd.Local, {'warm' if warm else 'cold'}",
                per_pair(
                    lambda w=warm: local.distances(lids, pa, pb, warm_start=w, out=local_out),
                    n,
                    args.repeats,
                ),
                "",
            )
        )
    local_error = interval_error(local_out.distance, truth.lower, truth.upper)
    for name, make in (("coal", coal_distances), ("python-fcl", fcl_distances)):
        built = make(ha, hb, pa, pb)
        if built is None:
            continue
        run, out = built
        t = per_pair(run, n, max(3, args.repeats // 5))
        err = interval_error(out, truth.lower, truth.upper)
        rows.append(
            (
                name,
                t,
                f"outside gjkd's [lower, upper] by at most {err.max():.2e} "
                f"(median {np.median(err):.2e}, {int(np.sum(err > 0))}/{n} outside)",
            )
        )

    print(f"{n} separated box pairs, each with its own poses; server wait spin")
    print(f"load average at the end: {os.getloadavg()[0]:.2f} (1 min)")
    print(f"{'':34} {'µs/pair':>9}  (all pairs' time / pairs, median of runs)")
    for name, t, note in rows:
        print(f"{name:34} {t:9.3f}  {note}")
    if rust is not None:
        print(f"{'Rust Client::query_batch, 1000':34} {rust:9.3f}")
        batch_1000 = next(t for name, t, _ in rows if name.endswith("batch 1000"))
        print(f"Python batch 1000 / Rust query_batch: {batch_1000 / rust:.2f}x")
    print(f"gjkd.Local against the server: max {local_error.max():.2e} outside the interval")
    print(f"single query round trip from Python: p50 {single_p50:.2f} µs, p90 {single_p90:.2f} µs")
    if rust_single:
        rust_p50 = statistics.median(rust_single)
        print(f"single query round trip from Rust (batch of one), median: {rust_p50:.2f} µs")
    print(f"pinned: {'server on CPU 1, clients on CPU 0' if pinned else 'no'}")
    print(f"interval width: median {np.median(truth.upper - truth.lower):.2e}")


if __name__ == "__main__":
    sys.exit(main())

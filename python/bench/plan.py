"""OMPL plans the vendored Panda through MotionBenchMaker's scenes with two
collision checkers: gjkd (``gjkd.ompl``, a server) and pinocchio + coal in
process (``baseline.py``), the same planner and settings for both.

    python python/bench/plan.py            # 100 problems a scene
    python python/bench/plan.py --quick    # 4 problems a scene
    python python/bench/plan.py --planner RRTstar --objective clearance \
        --problems 20 --time 2             # an optimising planner, fixed time
    python python/bench/plan.py --pybullet --plot docs/img/planning.svg
                                           # pybullet as a third checker; a plot

Per checker: RRTConnect's planning time (OMPL's own measure; median and
90th percentile), success rate, state checks and edge checks per second of
planning, and every returned path re-checked densely by an exact check
independent of gjkd (pinocchio + coal on the URDF's own meshes, margin 0,
at a tenth of OMPL's resolution): the paths that touch an obstacle or
collide with themselves. The problems alternate checkers, one problem at a
time, so that both see the same machine load. gjkd's edge check is the
certified continuous check (one request an edge; ``--motion sampled`` for
the sampled path at OMPL's resolution), the baseline's OMPL's discrete
validator at its default resolution. ``--pybullet`` adds pybullet's
``getClosestPoints`` (``bullet.py``) as a reference point, planned the
baseline's way. Needs ``pip install ompl pin coal`` besides the gjkd
package (and ``pybullet``, ``matplotlib`` for those options).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import sys
from typing import Any, Optional

import numpy as np
from baseline import PinCoal
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou
from scenes import PACKAGES, PANDA_SRDF, Problem, load_problems, panda_urdf, read_scene

import gjkd
import gjkd.ompl

try:
    from bullet import Bullet
except ImportError:  # pybullet not installed: --pybullet says so
    Bullet = None  # type: ignore[assignment,misc]

SCENES = ["box", "cage", "table_pick", "table_under_pick", "bookshelf_small"]
# Planners that use their whole time improving the path under an objective.
OPTIMISING = {"RRTstar", "BITstar", "PRMstar", "LBTRRT", "InformedRRTstar", "ABITstar", "AITstar"}


def clearance_cost(si: Any, clearance: Any) -> Any:
    """OMPL's clearance objective (its demos' form: 1 / clearance
    integrated along the path) over ``clearance(q)``, for the baseline;
    ``gjkd.ompl.clearance_objective`` is the same over gjkd's clearance."""

    class Clearance(ob.OptimizationObjective):  # type: ignore[misc]
        def __init__(self) -> None:
            super().__init__(si)

        def stateCost(self, state: Any) -> Any:  # noqa: N802 (OMPL's name)
            return ob.Cost(1.0 / (max(clearance(state[0:7]), 0.0) + 1e-9))

        def motionCost(self, s1: Any, s2: Any) -> Any:  # noqa: N802 (OMPL's name)
            # As gjkd.ompl's: the bindings call no Python override of a
            # StateCostIntegralObjective subclass from C++.
            a, b = self.stateCost(s1).value(), self.stateCost(s2).value()
            return ob.Cost(0.5 * (a + b) * si.distance(s1, s2))

    return Clearance()


def path_length(path: Optional[np.ndarray]) -> float:
    """The path's length in joint space (radians), ``nan`` for none."""
    if path is None:
        return math.nan
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())


def least_clearance(truth: PinCoal, path: Optional[np.ndarray], step: float) -> float:
    """The least distance along ``path`` checked densely by ``truth``."""
    if path is None:
        return math.nan
    return min(truth.clearance(q) for q in dense(path, step))


def register(client: gjkd.Client, problem: Problem) -> list[int]:
    """The problem's obstacles on the server; their ids."""
    ids = []
    for o in read_scene(problem.scene_file):
        if o.kind == "box":
            ids.append(client.register_box(o.size["half_extents"], pose=o.pose))
        elif o.kind == "cylinder":
            half = o.size["length"] / 2
            ids.append(client.register_cylinder(o.size["radius"], half, pose=o.pose))
        else:
            ids.append(client.register_sphere(o.size["radius"], pose=o.pose))
    return ids


def dense(path: np.ndarray, step: float) -> np.ndarray:
    """The path's states at most ``step`` apart (joint-space norm)."""
    out = [path[:1]]
    for a, b in zip(path[:-1], path[1:]):
        n = max(1, math.ceil(float(np.linalg.norm(b - a)) / step))
        t = np.arange(1, n + 1)[:, None] / n
        out.append(a + t * (b - a))
    return np.concatenate(out)


def touches(truth: PinCoal, path: Optional[np.ndarray], step: float) -> Optional[str]:
    """The first colliding pair along ``path`` checked densely, or None."""
    if path is None:
        return None
    for q in dense(path, step):
        if not truth.is_valid(q):
            return truth.first_collision(q) or "collision"
    return None


def run_gjkd(
    ss: Any, checker: gjkd.ompl.RobotChecker, p: Problem, limit: float
) -> tuple[Optional[np.ndarray], dict[str, Any]]:
    checker.state_checks = checker.edge_checks = checker.edge_steps = 0
    checker.clearance_checks = 0
    path = gjkd.ompl.plan(ss, checker, p.start, p.goal, time=limit)
    return path, {
        "time": ss.getLastPlanComputationTime(),
        "states": checker.state_checks + checker.edge_steps + checker.clearance_checks,
        "edges": checker.edge_checks,
    }


def run_in_process(
    checker: Any,
    lower: np.ndarray,
    upper: np.ndarray,
    p: Problem,
    limit: float,
    planner: str,
    objective: str,
) -> tuple[Optional[np.ndarray], dict[str, Any]]:
    """OMPL with an in-process ``checker`` (``is_valid(q)``; ``clearance(q)``
    for the clearance objective) and its discrete motion validator at the
    default resolution, as its users set it up."""
    space = ob.RealVectorStateSpace(7)
    bounds = ob.RealVectorBounds(7)
    for i in range(7):
        bounds.setLow(i, float(lower[i]))
        bounds.setHigh(i, float(upper[i]))
    space.setBounds(bounds)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(lambda s: checker.is_valid(s[0:7]))
    si = ss.getSpaceInformation()
    ss.setPlanner(getattr(og, planner)(si))
    if planner in OPTIMISING and objective == "clearance":
        ss.setOptimizationObjective(clearance_cost(si, checker.clearance))
    start, goal = ss.getStateSpace().allocState(), ss.getStateSpace().allocState()
    for i in range(7):
        start[i], goal[i] = float(p.start[i]), float(p.goal[i])
    ss.setStartAndGoalStates(start, goal)
    ss.solve(limit)
    path = None
    if ss.haveExactSolutionPath():
        path = np.array([list(s[0:7]) for s in ss.getSolutionPath().getStates()])
    stats = {
        "time": ss.getLastPlanComputationTime(),
        "states": checker.checks,
        "edges": si.getMotionValidator().getCheckedMotionCount(),
    }
    return path, stats


def plot(results: dict[str, list[dict[str, Any]]], limit: float, title: str, out: str) -> None:
    """Each checker's share of problems solved within a planning time (a
    cumulative curve, log time): the curve to the left plans faster."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 3.6))
    for name, rows in results.items():
        times = sorted(1e3 * r["time"] for r in rows if r["solved"])
        share = np.arange(1, len(times) + 1) / max(len(rows), 1)
        ax.step(times, share, where="post", label=name)
    ax.set_xscale("log")
    ax.set_xlabel("planning time, ms (log)")
    ax.set_ylabel("share of problems solved")
    ax.set_ylim(0, 1)
    ax.set_xlim(right=1e3 * limit)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="lower right")
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(out)


def summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    # Over every problem, an unsolved one taking the whole limit: both
    # checkers' medians are then over the same problems.
    times = sorted(r["time"] for r in rows)
    total = sum(times) or math.nan
    return {
        "problems": len(rows),
        "solved": sum(r["solved"] for r in rows),
        "median_ms": 1e3 * statistics.median(times) if times else math.nan,
        "p90_ms": 1e3 * times[min(len(times) - 1, int(0.9 * len(times)))] if times else math.nan,
        "states_per_s": sum(r["states"] for r in rows) / total,
        "edges_per_s": sum(r["edges"] for r in rows) / total,
        "touching": sum(r["touch"] is not None for r in rows),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="4 problems a scene, 2 s each")
    parser.add_argument("--problems", type=int, default=100, help="problems a scene")
    parser.add_argument("--time", type=float, default=5.0, help="planning time limit, s")
    parser.add_argument("--margin", type=float, default=0.0, help="collision margin, m")
    parser.add_argument("--scenes", nargs="*", default=SCENES)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument(
        "--wait",
        default="block",
        help="the gjkd server's wait mode (block: on a loaded 2-core machine, "
        "a spinning server takes the planner's core)",
    )
    parser.add_argument("--planner", default="RRTConnect", help="OMPL's og.<planner>")
    parser.add_argument(
        "--motion",
        choices=["continuous", "sampled"],
        default="continuous",
        help="gjkd's edge check: certified continuous, or sampled at OMPL's resolution",
    )
    parser.add_argument(
        "--objective",
        choices=["length", "clearance"],
        default="length",
        help="an optimising planner's objective (OMPL's default: path length)",
    )
    parser.add_argument(
        "--pybullet",
        action="store_true",
        help="also plan with pybullet's getClosestPoints (a reference point; pip install pybullet)",
    )
    parser.add_argument(
        "--plot", help="write the planning-time curves here (SVG; needs matplotlib)"
    )
    parser.add_argument("--json", help="write every problem's figures here")
    args = parser.parse_args()
    if args.quick:
        args.problems, args.time = 4, 2.0
    if args.pybullet and Bullet is None:
        parser.error("--pybullet needs pybullet: pip install pybullet")
    ou.setLogLevel(ou.LOG_WARN)
    ou.RNG.setSeed(args.seed)
    problems, robot = load_problems(args.scenes, args.problems)
    fingers = float(robot["fixed"]["panda_finger_joint1"])
    names = ["gjkd", "pinocchio+coal"] + (["pybullet"] if args.pybullet else [])
    results: dict[str, list[dict[str, Any]]] = {name: [] for name in names}
    invalid: dict[str, list[str]] = {name: [] for name in names}
    skipped: list[str] = []
    service = f"gjkd-plan-{os.getpid()}"
    with (
        gjkd.Server(service=service, wait=args.wait) as server,
        gjkd.Client(server.service, timeout=10.0) as client,
    ):
        checker = gjkd.ompl.RobotChecker(
            client,
            "panda",
            urdf_text=panda_urdf(fingers),
            srdf=PANDA_SRDF,
            package_path=[PACKAGES],
            margin=args.margin,
            joints=robot["joints"],
            fixed=robot["fixed"],
            motion=args.motion,
        )
        ss = gjkd.ompl.simple_setup(checker, planner=args.planner)
        if args.planner in OPTIMISING and args.objective == "clearance":
            ss.setOptimizationObjective(gjkd.ompl.clearance_objective(ss, checker))
        for k, p in enumerate(problems):
            ends = np.array([p.start, p.goal])
            if np.any(ends < checker.lower) or np.any(ends > checker.upper):
                # An older description of the Panda (MoveIt's) had wider
                # limits; neither checker can plan outside the URDF's.
                skipped.append(f"{p.scene}/{p.index}")
                continue
            ids = register(client, p)
            for q, what in ((p.start, "start"), (p.goal, "goal")):
                if not checker.is_valid(q):
                    invalid["gjkd"].append(f"{p.scene}/{p.index} {what}")
            path, stats = run_gjkd(ss, checker, p, args.time)
            for i in ids:
                client.remove(i)
            obstacles = read_scene(p.scene_file)
            truth = PinCoal(obstacles, args.margin, fingers)
            runs = [("gjkd", path, stats)]
            for name in names[1:]:
                other = (
                    truth if name == "pinocchio+coal" else Bullet(obstacles, args.margin, fingers)
                )
                for q, what in ((p.start, "start"), (p.goal, "goal")):
                    if not other.is_valid(q):
                        invalid[name].append(f"{p.scene}/{p.index} {what}")
                other.checks = 0
                opath, ostats = run_in_process(
                    other,
                    checker.lower,
                    checker.upper,
                    p,
                    args.time,
                    args.planner,
                    args.objective,
                )
                runs.append((name, opath, ostats))
                if other is not truth:
                    other.close()
            if args.margin != 0.0:
                truth = PinCoal(obstacles, 0.0, fingers)
            step = 0.001 * checker.extent
            for name, pth, st in runs:
                results[name].append(
                    {
                        "scene": p.scene,
                        "index": p.index,
                        "solved": pth is not None,
                        "touch": touches(truth, pth, step),
                        "length": path_length(pth),
                        "clearance": least_clearance(truth, pth, step)
                        if args.planner in OPTIMISING
                        else math.nan,
                        **st,
                    }
                )
            done = ", ".join(
                f"{n} {results[n][-1]['solved']} {1e3 * results[n][-1]['time']:.1f} ms"
                for n in names
            )
            print(f"[{k + 1}/{len(problems)}] {p.scene}/{p.index}: {done}", file=sys.stderr)
        checker.close()
    objective = f", objective {args.objective}" if args.planner in OPTIMISING else ""
    print(
        f"{args.planner}{objective}, {args.time:g} s limit, margin {args.margin:g}, "
        f"seed {args.seed}; times over every problem, an unsolved one counting as the limit"
    )
    head = "| scene | checker | solved | median ms | p90 ms | states/s | edges/s | paths touching |"
    print(head)
    print("|---|---|---|---|---|---|---|---|")
    for scene in [*args.scenes, "all"]:
        for name, rows in results.items():
            sel = [r for r in rows if scene in ("all", r["scene"])]
            s = summary(sel)
            print(
                f"| {scene} | {name} | {s['solved']}/{s['problems']} | {s['median_ms']:.1f} "
                f"| {s['p90_ms']:.1f} | {s['states_per_s']:.0f} | {s['edges_per_s']:.0f} "
                f"| {s['touching']} |"
            )
    g = summary(results["gjkd"])
    for name in names[1:]:
        b = summary(results[name])
        print(f"median planning time, gjkd / {name}: {g['median_ms'] / b['median_ms']:.2f}")
    if args.planner in OPTIMISING:
        # A fixed time: what the time bought, the path's length and its least
        # clearance (checked densely by pinocchio + coal), median over the
        # problems both solved.
        print("| checker | median length, rad | median least clearance, m | states/s |")
        print("|---|---|---|---|")
        pairs = [
            (x, y)
            for x, y in zip(results["gjkd"], results["pinocchio+coal"])
            if x["solved"] and y["solved"]
        ]
        for i, name in enumerate(results):
            sel = [pair[i] for pair in pairs]
            if sel:
                s = summary(sel)
                length = statistics.median(r["length"] for r in sel)
                clear = statistics.median(r["clearance"] for r in sel)
                print(f"| {name} | {length:.3f} | {clear:.4f} | {s['states_per_s']:.0f} |")
    both = [
        (x["time"], y["time"])
        for x, y in zip(results["gjkd"], results["pinocchio+coal"])
        if x["solved"] and y["solved"]
    ]
    if both:
        ratio = statistics.median(x / y for x, y in both)
        print(f"median of per-problem ratios (both solved, {len(both)}): {ratio:.2f}")
    lost = [
        f"{x['scene']}/{x['index']}"
        for x, y in zip(results["gjkd"], results["pinocchio+coal"])
        if y["solved"] and not x["solved"]
    ]
    print(f"solved by pinocchio+coal, not by gjkd: {len(lost)} {lost}")
    for name, rows in results.items():
        for r in rows:
            if r["touch"] is not None:
                print(f"{name}: {r['scene']}/{r['index']} path touches: {r['touch']}")
    print(f"{len(skipped)} problems skipped, start or goal outside the URDF's limits: {skipped}")
    for name, bad in invalid.items():
        print(f"{name}: {len(bad)} invalid starts or goals" + "".join(f"\n  {x}" for x in bad))
    if args.plot:
        plot(
            results,
            args.time,
            f"{args.planner}{objective}, {sum(len(r) for r in results.values()) // len(names)} "
            f"problems, margin {args.margin:g}",
            args.plot,
        )
    if args.json:
        with open(args.json, "w") as f:
            json.dump(
                {"args": vars(args), "results": results, "invalid": invalid, "skipped": skipped},
                f,
                indent=1,
            )


if __name__ == "__main__":
    main()

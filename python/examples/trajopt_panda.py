"""Trajectory optimisation of the vendored Panda among obstacles, with gjkd's
signed distances and joint gradients: ONE scene request per iteration.

A straight joint-space path from ``START`` to ``GOAL`` passes through a few
obstacles (placed on it) among many others. A small sequential convex loop
pushes it out to a collision-free path with ``margin`` clearance: each
iteration asks the server, in one ``path_joints`` request, for every
link-obstacle pair within ``margin + buffer`` at every waypoint, each row
with its signed distance (``distance - penetration``) and its gradient with
respect to the joints (``SceneRows(..., gradient_columns=dof)``); then
scipy's SLSQP solves the linearised subproblem (smoothness cost, one linear
constraint per row ``sd + g·Δq >= margin``, a trust region), which needs no
further request.

The same optimiser runs with pinocchio + coal in process as the baseline
(``--backend coal``): coal's signed distance per pair (convex hulls of the
same meshes; a bounding-sphere test first, as any user would write), and
pinocchio's frame Jacobians for the gradients.

Run from the repository's root::

    python python/examples/trajopt_panda.py                  # gjkd
    python python/examples/trajopt_panda.py --backend coal   # baseline
    python python/examples/trajopt_panda.py --obstacles 100 --waypoints 12

It prints the iterations, the time per iteration (the distance and
gradient part, and the whole) and the final least signed distance.
"""

from __future__ import annotations

import argparse
import dataclasses
import pathlib
import time
from typing import Callable, Optional

import numpy as np
import numpy.typing as npt
from scipy.optimize import minimize

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "model" / "tests" / "data"
PANDA = DATA / "example-robot-data" / "robots" / "panda_description" / "urdf" / "panda.urdf"

#: Arm joints at both ends (fingers shut); the straight path between them
#: sweeps the hand through the space in front of the robot.
START = np.array([-1.2, 0.3, 0.0, -1.8, 0.0, 2.1, 0.8])
GOAL = np.array([1.2, 0.3, 0.0, -1.8, 0.0, 2.1, 0.8])

F64 = npt.NDArray[np.float64]


@dataclasses.dataclass
class Rows:
    """One iteration's constraint rows: waypoint, signed distance, gradient."""

    step: npt.NDArray[np.int64]
    sd: F64
    grad: F64  # (rows, 7): the arm joints' columns


@dataclasses.dataclass
class Obstacle:
    """A ball or a box (half extents) at a position, axis-aligned."""

    position: F64
    radius: float = 0.0
    half: Optional[F64] = None


def make_obstacles(count: int, seed: int, on_path: list[F64]) -> list[Obstacle]:
    """Balls at the given points (on the initial path), then boxes and balls
    scattered on a shell around the robot's reach, to ``count`` in all."""
    rng = np.random.default_rng(seed)
    out = [Obstacle(position=p, radius=0.06) for p in on_path]
    while len(out) < count:
        direction = rng.normal(size=3)
        direction[2] = abs(direction[2])
        direction /= np.linalg.norm(direction)
        position = direction * rng.uniform(1.05, 1.6)
        if rng.random() < 0.5:
            out.append(Obstacle(position=position, radius=float(rng.uniform(0.03, 0.08))))
        else:
            out.append(Obstacle(position=position, half=rng.uniform(0.02, 0.06, size=3)))
    return out[:count]


def pose7(p: F64) -> F64:
    return np.array([p[0], p[1], p[2], 0.0, 0.0, 0.0, 1.0])


class GjkdBackend:
    """Signed distances and gradients from a gjkd server: one request."""

    def __init__(self, service: str) -> None:
        import gjkd

        self.server = gjkd.Server(service=service, wait="spin")
        self.server.__enter__()
        self.client = gjkd.Client(service)
        self.robot = self.client.register_robot("panda", PANDA, package_path=[DATA])
        self.dof = self.robot.dof
        self.rows = gjkd.SceneRows(4096, gradient_columns=self.dof)

    def hand(self, arm: F64) -> F64:
        """The hand link's origin at arm joints ``arm``."""
        positions = np.zeros(self.dof)
        positions[:7] = arm
        poses = self.robot.link_poses(positions)
        return np.asarray(poses[self.robot.link_names.index("panda_hand"), :3])

    def add(self, obstacles: list[Obstacle]) -> None:
        for o in obstacles:
            if o.half is None:
                self.client.register_sphere(o.radius, pose=pose7(o.position))
            else:
                self.client.register_box(o.half, pose=pose7(o.position))

    def full(self, path: F64) -> F64:
        """``(T, dof)`` positions: the fingers shut."""
        out = np.zeros((path.shape[0], self.dof))
        out[:, :7] = path
        return out

    def rows_within(self, path: F64, distance: float) -> Rows:
        summary = self.client.path_joints(
            self.robot,
            self.robot,
            self.full(path),
            out=self.rows,
            question="within",
            margin=distance,
        )
        n = summary.written
        assert not summary.truncated, "more rows than room"
        r = self.rows
        sd = r.distance[:n] - r.answers.penetration[:n]
        return Rows(
            step=r.step[:n].astype(np.int64),
            sd=sd.copy(),
            grad=r.gradient[:n, :7].copy(),
        )

    def close(self) -> None:
        self.client.close()
        self.server.__exit__(None, None, None)


class CoalBackend:
    """The same rows from pinocchio (kinematics, frame Jacobians) and coal
    (signed distance per pair, convex hulls of the meshes), in process."""

    def __init__(self) -> None:
        import coal
        import pinocchio as pin

        self.pin, self.coal = pin, coal
        self.model, self.geom = pin.buildModelsFromUrdf(
            str(PANDA), package_dirs=[str(DATA)], geometry_types=pin.GeometryType.COLLISION
        )[:2]
        self.data = self.model.createData()
        self.geom_data = self.geom.createData()
        self.arm = [
            self.model.joints[self.model.getJointId(f"panda_joint{i}")].idx_q for i in range(1, 8)
        ]
        self.arm_v = [
            self.model.joints[self.model.getJointId(f"panda_joint{i}")].idx_v for i in range(1, 8)
        ]
        # Links as convex hulls (as gjkd holds them), with a bounding ball.
        self.links = []
        for g in self.geom.geometryObjects:
            shape = g.geometry
            if isinstance(shape, coal.BVHModelBase):
                shape.buildConvexRepresentation(False)
                shape = shape.convex
            shape.computeLocalAABB()
            radius = float(shape.aabb_radius)
            centre = np.array(shape.aabb_center)
            self.links.append((g, shape, radius, centre))
        self.obstacles: list = []
        self.request = coal.DistanceRequest()
        self.request.enable_signed_distance = True
        self.result = coal.DistanceResult()

    def hand(self, arm: F64) -> F64:
        """The hand link's origin at arm joints ``arm``."""
        pin = self.pin
        q = pin.neutral(self.model)
        q[self.arm] = arm
        pin.framesForwardKinematics(self.model, self.data, q)
        return np.array(self.data.oMf[self.model.getFrameId("panda_hand")].translation)

    def add(self, obstacles: list[Obstacle]) -> None:
        for o in obstacles:
            shape = self.coal.Sphere(o.radius) if o.half is None else self.coal.Box(*(2 * o.half))
            shape.computeLocalAABB()
            tf = self.coal.Transform3s(np.eye(3), o.position)
            self.obstacles.append((shape, tf, float(shape.aabb_radius), o.position))

    def rows_within(self, path: F64, distance: float) -> Rows:
        pin, coal = self.pin, self.coal
        steps, sds, grads = [], [], []
        q = pin.neutral(self.model)
        for t, arm in enumerate(path):
            q[self.arm] = arm
            pin.computeJointJacobians(self.model, self.data, q)
            pin.updateGeometryPlacements(self.model, self.data, self.geom, self.geom_data)
            for k, (g, shape, radius, centre) in enumerate(self.links):
                placement = self.geom_data.oMg[k]
                world_centre = placement.act(centre)
                jacobian = None
                for o_shape, o_tf, o_radius, o_position in self.obstacles:
                    if np.linalg.norm(world_centre - o_position) - radius - o_radius > distance:
                        continue
                    self.result.clear()
                    tf = coal.Transform3s(placement.rotation, placement.translation)
                    sd = coal.distance(shape, tf, o_shape, o_tf, self.request, self.result)
                    if sd > distance:
                        continue
                    p_a = self.result.getNearestPoint1()
                    normal = np.array(self.result.normal)
                    if jacobian is None:
                        jacobian = pin.getJointJacobian(
                            self.model, self.data, g.parentJoint, pin.LOCAL_WORLD_ALIGNED
                        )
                        origin = self.data.oMi[g.parentJoint].translation
                    # The link's point moves at v + ω × (p − o): n · (−J_p).
                    r = p_a - origin
                    linear = jacobian[:3, self.arm_v]
                    angular = jacobian[3:, self.arm_v]
                    point = linear + np.cross(angular.T, r).T
                    steps.append(t)
                    sds.append(sd)
                    grads.append(-(normal @ point))
        grad = np.array(grads).reshape(-1, 7)
        return Rows(step=np.array(steps, dtype=np.int64), sd=np.array(sds), grad=grad)

    def close(self) -> None:
        pass


@dataclasses.dataclass
class Outcome:
    """What an optimisation run did."""

    path: F64
    iterations: int
    converged: bool
    least: float
    query_seconds: list[float]
    iteration_seconds: list[float]


def subproblem(
    path: F64,
    rows: Rows,
    lower: F64,
    upper: F64,
    margin: float,
    trust: float,
    penalty: float,
) -> F64:
    """The path that minimises the smoothness cost subject to every row's
    linearised signed distance ``sd + g·Δq >= margin`` within a trust
    region, by SLSQP. TrajOpt's l1 penalty makes each row's violation a
    slack variable priced at ``penalty``, so the subproblem is always
    feasible. No distance is asked here."""
    waypoints = path.shape[0]
    keep = (rows.step > 0) & (rows.step < waypoints - 1)
    steps, sd, grad = rows.step[keep], rows.sd[keep], rows.grad[keep]
    n, m = (waypoints - 2) * 7, len(sd)
    x0 = path[1:-1].ravel()

    def cost(z: F64) -> float:
        full = np.vstack([path[:1], z[:n].reshape(-1, 7), path[-1:]])
        return float(np.sum(np.diff(full, axis=0) ** 2) + penalty * np.sum(z[n:]))

    def cost_grad(z: F64) -> F64:
        full = np.vstack([path[:1], z[:n].reshape(-1, 7), path[-1:]])
        d = np.diff(full, axis=0)
        return np.concatenate([(2 * (d[:-1] - d[1:])).ravel(), np.full(m, penalty)])

    a = np.zeros((m, n + m))
    for i, (t, g) in enumerate(zip(steps, grad)):
        a[i, (t - 1) * 7 : t * 7] = g
    a[:, n:] = np.eye(m)
    b = margin - sd + a[:, :n] @ x0
    constraints = [{"type": "ineq", "fun": lambda z: a @ z - b, "jac": lambda z: a}] if m else []
    bounds = (
        list(
            zip(
                np.maximum(np.tile(lower, waypoints - 2), x0 - trust),
                np.minimum(np.tile(upper, waypoints - 2), x0 + trust),
            )
        )
        + [(0.0, None)] * m
    )
    start = np.concatenate([x0, np.maximum(b - a[:, :n] @ x0, 0.0)])
    solved = minimize(
        cost,
        start,
        jac=cost_grad,
        method="SLSQP",
        bounds=bounds,
        constraints=constraints,
        options={"maxiter": 200, "ftol": 1e-10},
    )
    out = path.copy()
    out[1:-1] = solved.x[:n].reshape(-1, 7)
    return out


def optimise(
    rows_within: Callable[[F64, float], Rows],
    path: F64,
    lower: F64,
    upper: F64,
    *,
    margin: float = 0.03,
    buffer: float = 0.05,
    trust: float = 0.2,
    penalty: float = 10.0,
    max_iterations: int = 40,
) -> Outcome:
    """The sequential convex loop: every iteration one ``rows_within`` call
    (the signed distances within ``margin + buffer`` and their gradients at
    every waypoint), then the linearised subproblem."""
    query_seconds: list[float] = []
    iteration_seconds: list[float] = []
    converged = False
    least = -np.inf
    for _ in range(max_iterations):
        started = time.perf_counter()
        rows = rows_within(path, margin + buffer)
        query_seconds.append(time.perf_counter() - started)
        least = float(rows.sd.min()) if len(rows.sd) else np.inf
        if least >= margin - 1e-6:
            iteration_seconds.append(time.perf_counter() - started)
            converged = True
            break
        path = subproblem(path, rows, lower, upper, margin, trust, penalty)
        iteration_seconds.append(time.perf_counter() - started)
    return Outcome(path, len(query_seconds), converged, least, query_seconds, iteration_seconds)


def straight(waypoints: int) -> F64:
    return np.linspace(START, GOAL, waypoints)


def obstacles_on_path(hand: Callable[[F64], F64], waypoints: int) -> list[F64]:
    """Hand positions at a few waypoints of the straight path, nudged so the
    balls are not centred on the hand's axis."""
    path = straight(waypoints)
    ts = (waypoints // 3, waypoints // 2, (2 * waypoints) // 3)
    return [hand(path[t]) + np.array([0.0, 0.02, 0.03]) for t in ts]


def run(backend: str, obstacles: int, waypoints: int, seed: int = 1, **kw: float) -> Outcome:
    """One optimisation with ``backend`` (``"gjkd"`` or ``"coal"``)."""
    import os

    chosen: "GjkdBackend | CoalBackend"
    if backend == "gjkd":
        chosen = GjkdBackend(service=f"trajopt-{os.getpid()}")
    else:
        chosen = CoalBackend()
    try:
        chosen.add(make_obstacles(obstacles, seed, obstacles_on_path(chosen.hand, waypoints)))
        lower = np.array([-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973])
        upper = np.array([2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973])
        return optimise(chosen.rows_within, straight(waypoints), lower, upper, **kw)  # type: ignore[arg-type]
    finally:
        chosen.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--backend", choices=["gjkd", "coal"], default="gjkd")
    parser.add_argument("--obstacles", type=int, default=100)
    parser.add_argument("--waypoints", type=int, default=12)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    out = run(args.backend, args.obstacles, args.waypoints, args.seed)
    query = np.array(out.query_seconds) * 1e3
    whole = np.array(out.iteration_seconds) * 1e3
    print(
        f"{args.backend}: {out.iterations} iterations, converged={out.converged}, "
        f"least signed distance {out.least:.4f} m; per iteration: distances + gradients "
        f"median {np.median(query):.3f} ms (mean {query.mean():.3f}), whole iteration "
        f"median {np.median(whole):.3f} ms"
    )


if __name__ == "__main__":
    main()

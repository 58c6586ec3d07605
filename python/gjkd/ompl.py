"""gjkd for OMPL: a robot's collision checks for OMPL's planners, answered by a
gjkd server.

OMPL (pip ``ompl`` 2.x) asks a planner's two questions through a state
validity checker ("is this configuration free?") and a motion validator
("is the straight motion between two configurations free?"). Here both are
answered by one scene request each to a gjkd server (:class:`RobotChecker`),
and :func:`simple_setup` wires them into an ``og.SimpleSetup`` with the
joint bounds of the robot's URDF::

    import gjkd
    import gjkd.ompl

    with gjkd.Server(service="plan", scene="scene.toml") as server, \\
            gjkd.Client(server.service) as client:
        checker = gjkd.ompl.RobotChecker(
            client, "panda", "panda.urdf", srdf="panda.srdf",
            package_path=["packages"], margin=0.01,
            joints=[f"panda_joint{i}" for i in range(1, 8)],
            fixed={"panda_finger_joint1": 0.04},
        )
        setup = gjkd.ompl.simple_setup(checker)
        path = gjkd.ompl.plan(setup, start, goal, time=1.0)  # (n, 7) or None

What a state is valid against: every link of the robot at more than
``margin`` from every other object the server holds, and from every other
link of the robot, except the allowed pairs (the SRDF's
``disable_collisions`` pairs and the links joined by a joint, as gjkd reads
them). A pair is reported when its certified lower bound is at most the
margin, so a state is never accepted on an uncertain answer.

The motion validator checks the straight joint-space segment at OMPL's
resolution (``si.getStateValidityCheckingResolution()`` of the space's
extent, OMPL's discrete motion validator's steps), all of them in one path
request. It is sampled: an obstacle thinner than a step can be missed.
:meth:`RobotChecker.motion_valid` is the one place the certified continuous
check will replace.

Errors: every method of :class:`RobotChecker` raises the package's
exceptions (:class:`gjkd.Error` and its subclasses). Inside OMPL's callbacks
an exception must not unwind through the planner, so the OMPL adapters
catch it, report the state or motion invalid (never accept what was not
checked), keep the first exception in :attr:`RobotChecker.error`, and stop
the planner at its next termination check; :func:`plan` then raises it.

``ompl`` is imported only by the functions that need it (:func:`simple_setup`,
:func:`plan`, :func:`clearance_objective`); :class:`RobotChecker` works
without it.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ElementTree
from typing import Any, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

from ._errors import Error, InvalidInput
from ._native import Client, Robot, SceneRows

__all__ = [
    "RobotChecker",
    "allowed_link_pairs",
    "clearance_objective",
    "plan",
    "simple_setup",
]

_PathLike = Union[str, "os.PathLike[str]"]
_F64 = npt.NDArray[np.float64]

# Joint positions one item of a request carries (the protocol's
# JOINTS_PER_ITEM): a step of a robot with more moving joints takes more.
_JOINTS_PER_ITEM = 9


def _read(path: Optional[_PathLike], text: Optional[str]) -> Optional[str]:
    if text is not None:
        return text
    if path is None:
        return None
    with open(path, encoding="utf-8") as f:
        return f.read()


def allowed_link_pairs(urdf_text: str, srdf_text: Optional[str]) -> set[frozenset[str]]:
    """The link pairs a robot's collision checks skip, by link name: the
    SRDF's ``disable_collisions`` pairs and every pair of links joined by a
    joint (the rule gjkd's server applies to a robot's own links).

    Raises:
        gjkd.InvalidInput: the URDF or SRDF is not XML.
    """
    pairs: set[frozenset[str]] = set()
    try:
        for joint in ElementTree.fromstring(urdf_text).iter("joint"):
            parent, child = joint.find("parent"), joint.find("child")
            if parent is not None and child is not None:
                pairs.add(frozenset((parent.get("link", ""), child.get("link", ""))))
    except ElementTree.ParseError as e:
        raise InvalidInput(f"URDF: {e}", field="urdf") from e
    if srdf_text is not None:
        try:
            for d in ElementTree.fromstring(srdf_text).iter("disable_collisions"):
                pairs.add(frozenset((d.get("link1", ""), d.get("link2", ""))))
        except ElementTree.ParseError as e:
            raise InvalidInput(f"SRDF: {e}", field="srdf") from e
    return pairs


class RobotChecker:
    """A robot's state, motion and clearance checks against everything a
    gjkd server holds, one scene request per call.

    Registers the robot (``name``) from its URDF. Each question is one
    path request of joint positions (``Client.path_joints``): the server
    places the links by forward kinematics and checks them against every
    other object it holds and against each other (``self_pairs=True``: the
    self-collisions, but the SRDF's disabled pairs and adjacent links).
    :meth:`close` removes the robot's links. The checker moves nothing on
    the server: other clients' questions see the robot where its joints
    were last set.

    Args:
        client: a connected :class:`gjkd.Client`.
        name: the robot's name on the server (its links are
            ``name/link``).
        urdf, urdf_text, srdf, srdf_text, package_path, base: as
            :meth:`gjkd.Client.register_robot`.
        margin: a state is valid when every pair checked is farther apart
            than this (``>= 0``).
        joints: the joints planned, in the order of OMPL's state (default:
            every moving joint, in the URDF's order).
        fixed: positions of the joints not planned, by name (default: 0
            clamped into the joint's limits).
        resolution: the sampled motion validator's step, as a fraction of
            the space's extent (OMPL's default 0.01); :func:`simple_setup`
            sets the same on OMPL's space information.
        motion: ``"continuous"`` (the default): an edge is valid when the
            server certifies every pose of it clear (one continuous path
            request: nothing between samples is missed); ``"sampled"``: the
            states of :meth:`segment` only, as OMPL's discrete motion
            validator.

    Raises:
        gjkd.Error: the robot cannot be registered (see
            :meth:`gjkd.Client.register_robot`), a joint name is unknown, or
            the margin or resolution is not a finite number in range.

    Counters: :attr:`state_checks`, :attr:`edge_checks`,
    :attr:`edge_steps` and :attr:`clearance_checks` count the questions
    answered (for benchmarks).
    """

    def __init__(
        self,
        client: Client,
        name: str,
        urdf: Optional[_PathLike] = None,
        *,
        urdf_text: Optional[str] = None,
        srdf: Optional[_PathLike] = None,
        srdf_text: Optional[str] = None,
        package_path: Sequence[_PathLike] = (),
        base: Optional[npt.ArrayLike] = None,
        margin: float = 0.0,
        joints: Optional[Sequence[str]] = None,
        fixed: Optional[Mapping[str, float]] = None,
        resolution: float = 0.01,
        motion: str = "continuous",
    ) -> None:
        if not (math.isfinite(margin) and margin >= 0.0):
            raise InvalidInput(f"margin must be a finite number >= 0, not {margin}", field="margin")
        if not (math.isfinite(resolution) and 0.0 < resolution <= 1.0):
            raise InvalidInput(
                f"resolution must be in (0, 1], not {resolution}", field="resolution"
            )
        try:
            text = _read(urdf, urdf_text)
            srdf_str = _read(srdf, srdf_text)
        except OSError as e:
            raise InvalidInput(f"cannot read {e.filename}: {e.strerror}", field="urdf") from e
        if text is None:
            raise InvalidInput("a URDF is needed: urdf or urdf_text", field="urdf")
        if motion not in ("continuous", "sampled"):
            raise InvalidInput(
                f"motion must be 'continuous' or 'sampled', not {motion!r}", field="motion"
            )
        allowed = allowed_link_pairs(text, srdf_str)
        paths = list(package_path)

        # From the file when there is one: relative mesh paths are read
        # next to it.
        if urdf is not None:
            robot = client.register_robot(
                name, urdf, srdf_text=srdf_str, package_path=paths, base=base
            )
        else:
            robot = client.register_robot(
                name, urdf_text=text, srdf_text=srdf_str, package_path=paths, base=base
            )
        self.client = client
        self.robot: Robot = robot
        self.margin = float(margin)
        self.resolution = float(resolution)
        self.motion = motion
        self.error: Optional[BaseException] = None
        self.state_checks = 0
        self.edge_checks = 0
        self.edge_steps = 0
        self.clearance_checks = 0
        try:
            self._choose_joints(joints, fixed)
        except Error:
            self.close()
            raise
        self._plan_pairs(allowed)
        self._rows = SceneRows(256)
        info = client.server_info() or {}
        # A request holds at most max_batch items: per step, the joint
        # positions' items and the step's end.
        per_step = -(-len(self._full) // _JOINTS_PER_ITEM) + 1
        self.steps_per_request = max(1, int(info.get("max_batch", 1024)) // per_step)

    def _choose_joints(
        self, joints: Optional[Sequence[str]], fixed: Optional[Mapping[str, float]]
    ) -> None:
        names = self.robot.joint_names
        lower, upper = self.robot.lower, self.robot.upper
        chosen = list(names) if joints is None else list(joints)
        for j in chosen + list(fixed or {}):
            if j not in names:
                raise InvalidInput(f"the robot has no moving joint {j!r}", field="joints")
        self.joint_names: list[str] = chosen
        self._index = np.array([names.index(j) for j in chosen], dtype=np.intp)
        self._full = np.clip(np.zeros(len(names)), lower, upper)
        for j, v in (fixed or {}).items():
            self._full[names.index(j)] = float(v)
        # A continuous joint has no limits: OMPL's real vector space needs
        # bounds, and one turn either way covers every orientation.
        self.lower: _F64 = np.where(np.isfinite(lower), lower, -math.pi)[self._index]
        self.upper: _F64 = np.where(np.isfinite(upper), upper, math.pi)[self._index]
        self.extent = float(np.linalg.norm(self.upper - self.lower))

    def _plan_pairs(self, allowed: set[frozenset[str]]) -> None:
        # The server skips the same pairs (the robot's allowed pairs): this
        # only counts the self-collision pairs each question checks.
        names, ids = self.robot.link_names, self.robot.link_ids
        links = [i for i in range(len(names)) if ids[i] != 0]
        self.self_pairs = sum(
            1
            for i in links
            for j in links
            if i < j and frozenset((names[i], names[j])) not in allowed
        )

    # -- positions ---------------------------------------------------------

    @property
    def dof(self) -> int:
        """The number of joints planned (the length of OMPL's state)."""
        return len(self.joint_names)

    def positions(self, q: npt.ArrayLike) -> _F64:
        """The robot's whole ``(dof_robot,)`` position array for the planned
        joints' ``q``, the others at their fixed positions."""
        full: _F64 = self._full.copy()
        full[self._index] = np.asarray(q, dtype=np.float64)
        return full

    def _positions(self, qs: _F64) -> _F64:
        """``(S, dof_robot)`` positions of every moving joint at each row of
        ``qs``, the joints not planned at their fixed positions."""
        full = np.repeat(self._full[None, :], len(qs), axis=0)
        full[:, self._index] = qs
        return full

    def _steps(self, qs: npt.ArrayLike) -> _F64:
        a = np.asarray(qs, dtype=np.float64)
        if a.ndim == 1:
            a = a[None, :]
        if a.ndim != 2 or a.shape[1] != self.dof or a.shape[0] == 0:
            raise InvalidInput(
                f"positions must be ({self.dof},) or (S, {self.dof}), not {a.shape}",
                field="positions",
            )
        if not np.all(np.isfinite(a)):
            raise InvalidInput("positions must be finite", field="positions")
        return a

    def _ask(self, qs: _F64, question: str) -> Any:
        """One request: ``question`` at each row of ``qs`` (at most
        :attr:`steps_per_request` rows)."""
        return self.client.path_joints(
            self.robot,
            self.robot,
            self._positions(qs),
            out=self._rows,
            question=question,
            margin=self.margin,
            self_pairs=True,
            # OMPL asks only whether an edge is valid: a bracket as wide as
            # the edge lets the first pose found within the margin settle
            # it, where a narrow one would locate the first contact.
            bracket=1.0,
        )

    # -- the questions ------------------------------------------------------

    def is_valid(self, q: npt.ArrayLike) -> bool:
        """Whether the robot at ``q`` (the planned joints) is farther than the
        margin from everything (one request)."""
        self.state_checks += 1
        return bool(self._ask(self._steps(q), "first_hit").first_hit is None)

    def are_valid(self, qs: npt.ArrayLike) -> npt.NDArray[np.bool_]:
        """Whether each row of ``(S, dof)`` ``qs`` is valid: one request for
        all of them (more only if the rows of one answer do not fit)."""
        steps = self._steps(qs)
        self.state_checks += len(steps)
        valid = np.ones(len(steps), dtype=bool)
        start = 0
        while start < len(steps):
            s = self._ask(steps[start : start + self.steps_per_request], "within")
            hit = self._rows.step[: s.written].astype(np.intp) + start
            valid[hit] = False
            # Rows come step by step: when they did not all fit, the last
            # step written is invalid already and the ones after it are
            # asked again.
            if s.truncated:
                start = int(hit.max()) + 1
            else:
                start += self.steps_per_request
        return valid

    def segment(self, q0: npt.ArrayLike, q1: npt.ArrayLike) -> _F64:
        """The states the motion validator checks between ``q0`` and ``q1``:
        ``n = ceil(|q1 - q0| / (resolution * extent))`` steps (OMPL's
        discrete motion validator's count), ``q1`` and the ``n - 1`` between,
        not ``q0`` (a planner's edge starts at a state already valid)."""
        a, b = self._steps(q0)[0], self._steps(q1)[0]
        n = max(1, math.ceil(float(np.linalg.norm(b - a)) / (self.resolution * self.extent)))
        t = np.arange(1, n + 1, dtype=np.float64)[:, None] / n
        out: _F64 = a + t * (b - a)
        out[-1] = b
        return out

    def motion_valid(self, q0: npt.ArrayLike, q1: npt.ArrayLike) -> bool:
        """Whether the straight motion (joints linear) from ``q0`` to ``q1``
        is valid. ``motion="continuous"``: one request, certified: ``True``
        only when no pose of the motion has a pair within the margin (``q0``
        included; the server bisects and advances conservatively, so a thin
        obstacle between samples is not missed). ``motion="sampled"``: the
        states of :meth:`segment`, stopping at the first within the margin
        (an edge of more than :attr:`steps_per_request` states takes more
        requests)."""
        self.edge_checks += 1
        if self.motion == "continuous":
            ends = self._steps(np.stack([np.asarray(q0, float), np.asarray(q1, float)]))
            if np.array_equal(ends[0], ends[1]):
                # No motion: a continuous path refuses a segment that does
                # not move, and the edge is its one state.
                return bool(self._ask(ends[1:], "first_hit").first_hit is None)
            s = self._ask(ends, "continuous")
            return bool(s.total == 0)
        steps = self.segment(q0, q1)
        for k in range(0, len(steps), self.steps_per_request):
            chunk = steps[k : k + self.steps_per_request]
            s = self._ask(chunk, "first_hit")
            self.edge_steps += s.steps
            if s.first_hit is not None:
                return False
        return True

    def clearance(self, q: npt.ArrayLike) -> float:
        """The distance from the robot at ``q`` to its nearest other object
        or non-allowed link (one request): 0 where shapes overlap, ``inf``
        when nothing qualifies."""
        self.clearance_checks += 1
        s = self._ask(self._steps(q), "clearance")
        d = self._rows.distance[: s.written]
        ok = (self._rows.b[: s.written] != 0) & (self._rows.error[: s.written] == 0)
        return float(d[ok].min()) if ok.any() else math.inf

    # -- lifetime -------------------------------------------------------------

    def close(self) -> None:
        """Removes the robot's link objects from the server (a robot's name
        stays taken there: the server removes objects, not robots)."""
        r = getattr(self, "robot", None)
        if r is None:
            return
        for i in r.link_ids:
            if i != 0:
                try:
                    self.client.remove(int(i))
                except Error:
                    pass

    def __enter__(self) -> RobotChecker:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def raise_error(self) -> None:
        """Raises (and forgets) the first exception an OMPL callback caught."""
        e, self.error = self.error, None
        if e is not None:
            raise e


# -- OMPL ---------------------------------------------------------------------


def _ompl() -> tuple[Any, Any]:
    try:
        from ompl import base as ob
        from ompl import geometric as og
    except ImportError as e:
        raise ImportError("gjkd.ompl needs OMPL's Python bindings 2.x: pip install ompl") from e
    return ob, og


_ADAPTERS: dict[str, Any] = {}


def _adapters() -> dict[str, Any]:
    """OMPL's callback classes, made on first use (they subclass OMPL's)."""
    if _ADAPTERS:
        return _ADAPTERS
    ob, _ = _ompl()

    class StateValidity(ob.StateValidityChecker):  # type: ignore[misc, name-defined]
        """OMPL's state validity checker over a :class:`RobotChecker`."""

        def __init__(self, si: Any, checker: RobotChecker) -> None:
            super().__init__(si)
            self.checker = checker
            self.n = checker.dof

        def isValid(self, state: Any) -> bool:  # noqa: N802 (OMPL's name)
            c = self.checker
            if c.error is not None:
                return False
            try:
                return c.is_valid(state[0 : self.n])
            except Exception as e:  # noqa: BLE001 (kept, raised by plan())
                c.error = e
                return False

        def clearance(self, state: Any) -> float:
            c = self.checker
            if c.error is not None:
                return 0.0
            try:
                return c.clearance(state[0 : self.n])
            except Exception as e:  # noqa: BLE001
                c.error = e
                return 0.0

    class Motion(ob.MotionValidator):  # type: ignore[misc, name-defined]
        """OMPL's motion validator over a :class:`RobotChecker`."""

        def __init__(self, si: Any, checker: RobotChecker) -> None:
            super().__init__(si)
            self.checker = checker
            self.n = checker.dof

        def checkMotion(self, s1: Any, s2: Any) -> bool:  # noqa: N802 (OMPL's name)
            c = self.checker
            if c.error is not None:
                return False
            try:
                return c.motion_valid(s1[0 : self.n], s2[0 : self.n])
            except Exception as e:  # noqa: BLE001
                c.error = e
                return False

    class ClearanceObjective(ob.OptimizationObjective):  # type: ignore[misc, name-defined]
        """Cost 1 / clearance integrated along the path (OMPL's demo's
        clearance objective): lower for paths farther from everything."""

        def __init__(self, si: Any, checker: RobotChecker) -> None:
            super().__init__(si)
            self.checker = checker
            self.n = checker.dof

        def stateCost(self, state: Any) -> Any:  # noqa: N802 (OMPL's name)
            c = self.checker
            try:
                d = c.clearance(state[0 : self.n]) if c.error is None else 0.0
            except Exception as e:  # noqa: BLE001
                c.error = e
                d = 0.0
            return ob.Cost(1.0 / (max(d, 0.0) + 1e-9))

        def motionCost(self, s1: Any, s2: Any) -> Any:  # noqa: N802 (OMPL's name)
            # The integral by the trapezoid rule, as OMPL's
            # StateCostIntegralObjective computes it without interpolation:
            # OMPL's Python bindings call neither a Python `stateCost` nor a
            # Python `motionCost` of a subclass of that class from C++, so
            # planners saw unit state costs (the path's length) until this
            # objective derived from OptimizationObjective itself.
            a = self.stateCost(s1).value()
            b = self.stateCost(s2).value()
            return ob.Cost(0.5 * (a + b) * self.getSpaceInformation().distance(s1, s2))

    _ADAPTERS.update(
        StateValidity=StateValidity, Motion=Motion, ClearanceObjective=ClearanceObjective
    )
    return _ADAPTERS


def simple_setup(checker: RobotChecker, *, planner: Optional[str] = "RRTConnect") -> Any:
    """An ``og.SimpleSetup`` planning ``checker``'s joints: a real vector
    space bounded by the URDF's limits, ``checker`` as the state validity
    checker and the motion validator, the checking resolution set to
    ``checker.resolution``, and the planner ``og.<planner>`` (``None``:
    OMPL's choice).

    Raises:
        ImportError: ``ompl`` cannot be imported.
    """
    ob, og = _ompl()
    a = _adapters()
    space = ob.RealVectorStateSpace(checker.dof)
    bounds = ob.RealVectorBounds(checker.dof)
    for i in range(checker.dof):
        bounds.setLow(i, float(checker.lower[i]))
        bounds.setHigh(i, float(checker.upper[i]))
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    validity = a["StateValidity"](si, checker)
    motion = a["Motion"](si, checker)
    si.setStateValidityChecker(validity)
    si.setMotionValidator(motion)
    si.setStateValidityCheckingResolution(checker.resolution)
    si.setup()
    ss = og.SimpleSetup(si)
    if planner is not None:
        ss.setPlanner(getattr(og, planner)(si))
    # OMPL holds the callbacks by C++ pointers: keep the Python objects.
    checker._ompl_keep = (space, si, validity, motion)  # type: ignore[attr-defined]
    return ss


def clearance_objective(ss: Any, checker: RobotChecker) -> Any:
    """An optimisation objective for ``ss`` rewarding clearance (the
    integral of 1 / clearance along the path, each state one request);
    set it with ``ss.setOptimizationObjective``."""
    _ompl()
    obj = _adapters()["ClearanceObjective"](ss.getSpaceInformation(), checker)
    checker._ompl_objective = obj  # type: ignore[attr-defined]
    return obj


def plan(
    ss: Any,
    checker: RobotChecker,
    start: npt.ArrayLike,
    goal: npt.ArrayLike,
    *,
    time: float = 1.0,
    simplify: bool = False,
) -> Optional[_F64]:
    """Plans from ``start`` to ``goal`` (the planned joints) for at most
    ``time`` seconds; returns the path's ``(n, dof)`` states, or ``None``
    when no exact solution was found.

    Raises:
        gjkd.Error: a check failed during planning (the first such error; the
            planner was stopped, and nothing it returned is used).
    """
    ob, _ = _ompl()
    si = ss.getSpaceInformation()
    states = []
    for q in (start, goal):
        s = si.allocState()
        v = checker._steps(q)[0]
        for i in range(checker.dof):
            s[i] = float(v[i])
        states.append(s)
    ss.clear()
    ss.setStartAndGoalStates(states[0], states[1])
    checker.error = None
    timed = ob.timedPlannerTerminationCondition(float(time))
    failed = ob.PlannerTerminationCondition(lambda: checker.error is not None)
    ss.solve(ob.plannerOrTerminationCondition(timed, failed))
    checker.raise_error()
    if not ss.haveExactSolutionPath():
        return None
    if simplify:
        ss.simplifySolution()
        checker.raise_error()
    path = ss.getSolutionPath()
    return np.array([list(s[0 : checker.dof]) for s in path.getStates()], dtype=np.float64)

"""Type stubs of the native module ``gjkd._native`` (see ``gjkd``)."""

from os import PathLike
from types import TracebackType
from typing import Mapping, Optional, Sequence, Tuple, Type, Union

import numpy as np
import numpy.typing as npt
from typing_extensions import Self, final

__all__ = [
    "Answer",
    "Client",
    "DEFAULT_MAX_ITERATIONS",
    "DEFAULT_TOLERANCE",
    "Distances",
    "Local",
    "MAX_NAME_LEN",
    "MAX_PIECES",
    "MeshInfo",
    "PROTOCOL_VERSION",
    "Robot",
    "SceneRows",
    "SceneSummary",
    "Shape",
    "error_codes",
    "pin_thread",
    "serve",
    "set_realtime_priority",
]

DEFAULT_TOLERANCE: float
DEFAULT_MAX_ITERATIONS: int
MAX_PIECES: int
MAX_NAME_LEN: int
PROTOCOL_VERSION: int

_ArrayLike = npt.ArrayLike
_Pose = npt.ArrayLike
"""A pose: ``(7,)`` ``[x, y, z, qx, qy, qz, qw]`` or a ``(4, 4)`` rigid
transform, float64."""

_Path = Union[str, "PathLike[str]"]

_F64 = npt.NDArray[np.float64]
_U32 = npt.NDArray[np.uint32]
_U64 = npt.NDArray[np.uint64]

@final
class Shape:
    """A convex shape: the hull of its vertices grown by a radius."""

    @staticmethod
    def sphere(radius: float) -> Shape:
        """A ball of ``radius`` about the body origin."""
    @staticmethod
    def capsule(a: _ArrayLike, b: _ArrayLike, radius: float) -> Shape:
        """The segment ``a``-``b`` grown by ``radius``."""
    @staticmethod
    def box(half_extents: _ArrayLike, radius: float = 0.0) -> Shape:
        """A box of these half extents, edges rounded by ``radius``."""
    @staticmethod
    def cylinder(radius: float, half_height: float, rounding: float = 0.0) -> Shape:
        """An exact cylinder about the body z axis, rims rounded by ``rounding``."""
    @staticmethod
    def polytope(vertices: _ArrayLike, radius: float = 0.0) -> Shape:
        """The convex hull of ``(N, 3)`` float64 ``vertices`` grown by ``radius``."""
    @property
    def kind(self) -> str:
        """``"sphere"``, ``"capsule"``, ``"box"``, ``"cylinder"`` or ``"polytope"``."""
    @property
    def radius(self) -> float:
        """The rounding radius."""
    @property
    def vertices(self) -> _F64:
        """``(N, 3)`` vertices in the order the server stores them."""

@final
class Robot:
    """A robot registered from URDF: its links are objects, its joints move them."""

    @property
    def id(self) -> int:
        """The robot's object id on the server."""
    @property
    def name(self) -> str:
        """The name it was registered under."""
    @property
    def link_names(self) -> list[str]:
        """Every link's name, in the URDF's order."""
    @property
    def joint_names(self) -> list[str]:
        """The moving joints' names, in position-array order."""
    @property
    def dof(self) -> int:
        """Number of moving joints."""
    @property
    def link_ids(self) -> npt.NDArray[np.uint64]:
        """``(L,)`` each link's object id, 0 for a link without geometry."""
    @property
    def positions(self) -> _F64:
        """``(dof,)`` the joint positions last set."""
    @property
    def lower(self) -> _F64:
        """``(dof,)`` lower joint limits."""
    @property
    def upper(self) -> _F64:
        """``(dof,)`` upper joint limits."""
    def link(self, name: str) -> Optional[int]:
        """The object id of link ``name``; ``None`` without geometry."""
    def link_poses(
        self,
        positions: Optional[Union[_ArrayLike, Mapping[str, float]]] = None,
        base: Optional[_Pose] = None,
        *,
        clamp: bool = False,
    ) -> _F64:
        """``(L, 7)`` link poses by forward kinematics."""
    def limits(self) -> dict[str, tuple[float, float]]:
        """``{joint: (lower, upper)}`` of the moving joints."""
    def __len__(self) -> int: ...

@final
class Answer:
    """The answer to one pair query."""

    @property
    def distance(self) -> float:
        """Distance between the (rounded) shapes."""
    @property
    def lower(self) -> float:
        """Certified lower bound on the distance."""
    @property
    def upper(self) -> float:
        """Certified upper bound on the distance."""
    @property
    def penetration(self) -> float:
        """Lower bound on the penetration depth; 0 when separated."""
    @property
    def point_a(self) -> Tuple[float, float, float]:
        """Nearest point on A, world frame."""
    @property
    def point_b(self) -> Tuple[float, float, float]:
        """Nearest point on B, world frame."""
    @property
    def normal(self) -> Tuple[float, float, float]:
        """Unit vector from A's nearest point towards B's (zero at contact)."""
    @property
    def status(self) -> int:
        """A ``gjkd.Status`` value."""
    @property
    def iterations(self) -> int:
        """Subalgorithm iterations."""
    @property
    def pieces(self) -> Tuple[int, int]:
        """Pieces of A and B realising the distance (0 for convex objects)."""
    @property
    def warm_started(self) -> bool:
        """The query started from the pair's last simplex."""
    @property
    def backup_used(self) -> bool:
        """The Backup Procedure ran."""
    @property
    def signed_distance(self) -> Optional[float]:
        """The signed distance when asked (``signed_distance=True``), else None.

        The distance apart, minus the penetration depth (the shortest
        translation that separates the shapes) overlapping; ``point_a``,
        ``point_b`` and ``normal`` are then its witnesses and direction,
        ``point_b - point_a = signed_distance * normal``.
        """
    @property
    def signed_interval(self) -> Optional[Tuple[float, float]]:
        """The certified ``(lower, upper)`` bounds of the signed distance, when asked."""
    @property
    def gradient(self) -> Optional[_F64]:
        """``(columns,)`` the distance's gradient (``None`` when not asked).

        With respect to the coordinates that move ``a``; for overlapping
        objects, the signed distance's (``distance - penetration``).
        """
    @property
    def gradient_not_unique(self) -> bool:
        """The nearest points are not unique: a one-sided gradient."""
    @property
    def gradient_error(self) -> float:
        """A bound on each gradient entry's error from the interval."""

@final
class Distances:
    """The answers of N pair queries, one numpy array per field.

    ``Distances(n, gradient_columns=c)`` with ``c > 0`` also asks every call
    given it as ``out=`` for each pair's distance gradient, into
    ``gradient`` ``(N, c)``, ``gradient_flags`` and ``gradient_error``, as
    ``SceneRows(n, gradient_columns=c)`` does for scene rows: the room asks,
    sized once and reused, so a call never asks a gradient it has no room
    for and allocates nothing."""

    def __new__(cls, n: int, gradient_columns: int = 0, gradient_base: bool = False) -> Self:
        """Zeroed arrays for ``n`` pairs, to pass as ``out=``, with room for
        ``gradient_columns`` (at most 16) gradient entries per pair: each
        call filling them then asks every pair's gradient (with
        ``gradient_base=True``, a robot base's twist too; it raises
        ``InvalidInput`` without gradient columns). A gradient of more than
        ``c`` columns keeps its first ``c``: size ``c`` for the widest pair
        (a robot's ``dof``, plus 6 with ``gradient_base``; 6 for a free
        object)."""
    def __len__(self) -> int: ...
    @property
    def gradient(self) -> _F64:
        """``(N, gradient_columns)`` each pair's gradient with respect to the
        coordinates that move its ``a`` (a robot's joints, then the base
        twist with ``gradient_base``; another object's twist), zero beyond
        the columns in use and in failed rows; bit for bit what
        ``distance(a, b, gradient=True)`` answers."""
    @property
    def gradient_flags(self) -> _U32:
        """``(N,)`` 1 computed, 2 not unique, 4 base included, 8 no direction
        (0 in failed rows or without gradient columns)."""
    @property
    def gradient_error(self) -> _F64:
        """``(N,)`` a bound on each pair's gradient entries' error."""
    @property
    def distance(self) -> _F64:
        """``(N,)`` distances."""
    @property
    def lower(self) -> _F64:
        """``(N,)`` certified lower bounds."""
    @property
    def upper(self) -> _F64:
        """``(N,)`` certified upper bounds."""
    @property
    def penetration(self) -> _F64:
        """``(N,)`` lower bounds on penetration depth."""
    @property
    def point_a(self) -> _F64:
        """``(N, 3)`` nearest points on A."""
    @property
    def point_b(self) -> _F64:
        """``(N, 3)`` nearest points on B."""
    @property
    def normal(self) -> _F64:
        """``(N, 3)`` unit normals from A towards B."""
    @property
    def status(self) -> _U32:
        """``(N,)`` ``gjkd.Status`` values (0 for failed rows)."""
    @property
    def iterations(self) -> _U32:
        """``(N,)`` subalgorithm iterations."""
    @property
    def pieces(self) -> _U32:
        """``(N, 2)`` pieces realising the distance."""
    @property
    def error(self) -> _U32:
        """``(N,)`` ``gjkd.ErrorCode`` values, 0 when answered."""
    @property
    def warm_started(self) -> npt.NDArray[np.bool_]:
        """``(N,)`` whether each query started warm."""
    @property
    def signed_distance(self) -> _F64:
        """``(N,)`` signed distances (negative inside: minus the penetration
        depth) of rows that asked for one, NaN in the others; such a row's
        ``point_a``, ``point_b`` and ``normal`` are its witnesses."""
    @property
    def signed_lower(self) -> _F64:
        """``(N,)`` certified lower bounds on the signed distances (NaN when none)."""
    @property
    def signed_upper(self) -> _F64:
        """``(N,)`` certified upper bounds on the signed distances (NaN when none)."""
    @property
    def ok(self) -> npt.NDArray[np.bool_]:
        """``(N,)`` the rows that were answered."""
    def as_dict(self) -> dict[str, npt.NDArray[np.generic]]:
        """The arrays keyed by field name."""

@final
class SceneRows:
    """Room for the rows of scene answers, reused from call to call.

    Which fields are exact depends on a row's ``status``: ``lower`` and
    ``upper`` always bound the true distance. ``CONVERGED`` (and
    ``ITERATION_CAP``, ``TOLERANCE_NOT_MET`` within their bounds):
    ``distance`` and the points are the answer. ``CLOSER`` (a ``within``
    pair proved inside the margin by an early exit) and ``BOUNDED``
    (answered from motion bounds, without GJK): ``distance`` and the points
    are an estimate inside ``[lower, upper]``, which may be wide. Pass
    ``exact=True`` to a scene call for exact distances on every reported
    row."""

    def __new__(
        cls,
        n: int,
        gradient_columns: int = 0,
        gradient_base: bool = False,
        signed_distance: bool = False,
    ) -> Self:
        """Zeroed room for ``n`` rows (and ``gradient_columns`` gradient
        entries per row, at most 16: a call then asks each row's distance
        gradient, kept in ``answers``' arrays; ``gradient_base=True``
        without gradient columns raises ``InvalidInput``). A gradient of
        more columns than the room keeps its first ones.

        ``signed_distance=True`` asks every call for each row's signed
        distance with its certified interval (``signed_distance``,
        ``signed_lower``, ``signed_upper``): the distance apart, minus the
        penetration depth overlapping. Which rows are reported does not
        change (an overlapping pair has distance 0, so ``within`` reports it
        whatever the margin); a continuous path refuses it."""
    @property
    def gradient(self) -> _F64:
        """``(n, gradient_columns)`` each row's gradient with respect to the
        coordinates that move its ``a`` (a robot's joints, then the base twist
        with ``gradient_base``; another object's twist)."""
    @property
    def gradient_flags(self) -> _U32:
        """``(n,)`` 1 computed, 2 not unique, 4 base included, 8 no direction."""
    @property
    def gradient_error(self) -> _F64:
        """``(n,)`` a bound on each row's gradient entries' error."""
    def __len__(self) -> int: ...
    @property
    def a(self) -> _U64:
        """``(n,)`` the group's objects."""
    @property
    def b(self) -> _U64:
        """``(n,)`` the other objects, 0 for none."""
    @property
    def step(self) -> _U32:
        """``(n,)`` the path steps (a continuous path's segments)."""
    @property
    def s_lo(self) -> _F64:
        """``(n,)`` continuous paths: every pose before this ``s`` is certified clear."""
    @property
    def s_hi(self) -> _F64:
        """``(n,)`` continuous paths: the pose at this ``s`` is within the margin."""
    @property
    def answers(self) -> Distances:
        """The pairs' answers."""
    @property
    def distance(self) -> _F64:
        """``(n,)`` distances."""
    @property
    def lower(self) -> _F64:
        """``(n,)`` certified lower bounds."""
    @property
    def upper(self) -> _F64:
        """``(n,)`` certified upper bounds."""
    @property
    def signed_distance(self) -> _F64:
        """``(n,)`` signed distances (``answers.signed_distance``), NaN when none."""
    @property
    def signed_lower(self) -> _F64:
        """``(n,)`` certified lower bounds on the signed distances."""
    @property
    def signed_upper(self) -> _F64:
        """``(n,)`` certified upper bounds on the signed distances."""
    @property
    def status(self) -> _U32:
        """``(n,)`` ``gjkd.Status`` values."""
    @property
    def error(self) -> _U32:
        """``(n,)`` ``gjkd.ErrorCode`` values."""

@final
class SceneSummary:
    """What a scene answer held besides its rows."""

    @property
    def written(self) -> int:
        """Rows written."""
    @property
    def total(self) -> int:
        """Rows that qualified, also those that did not fit."""
    @property
    def truncated(self) -> bool:
        """More rows qualified than the rows hold."""
    @property
    def steps(self) -> int:
        """Steps answered."""
    @property
    def first_hit(self) -> Optional[int]:
        """The first step within the margin of a first-hit path."""
    @property
    def gjk_runs(self) -> int:
        """Pair queries that ran GJK."""
    @property
    def bounded(self) -> int:
        """Pairs answered from motion bounds alone."""
    @property
    def candidates(self) -> int:
        """Pairs the broadphase could not rule out."""

@final
class MeshInfo:
    """What a mesh registration made (``info=`` of ``register_mesh``)."""

    def __new__(cls) -> MeshInfo: ...
    @property
    def pieces(self) -> int:
        """Convex pieces: 1 for a hull."""
    @property
    def deviation(self) -> float:
        """A decomposition's largest deviation found from the mesh; 0 for a hull."""

class _Objects:
    """The methods ``Client`` and ``Local`` share: the same signatures,
    answers and errors, whether a server or this process holds the
    objects."""

    def register(
        self, shape: Shape, *, name: Optional[str] = None, pose: Optional[_Pose] = None
    ) -> int:
        """Registers ``shape``; returns its id."""
    def register_sphere(
        self, radius: float, *, name: Optional[str] = None, pose: Optional[_Pose] = None
    ) -> int:
        """Registers a ball; returns its id."""
    def register_capsule(
        self,
        a: _ArrayLike,
        b: _ArrayLike,
        radius: float,
        *,
        name: Optional[str] = None,
        pose: Optional[_Pose] = None,
    ) -> int:
        """Registers a capsule; returns its id."""
    def register_box(
        self,
        half_extents: _ArrayLike,
        radius: float = 0.0,
        *,
        name: Optional[str] = None,
        pose: Optional[_Pose] = None,
    ) -> int:
        """Registers a box; returns its id."""
    def register_cylinder(
        self,
        radius: float,
        half_height: float,
        rounding: float = 0.0,
        *,
        name: Optional[str] = None,
        pose: Optional[_Pose] = None,
    ) -> int:
        """Registers an exact cylinder about z; returns its id."""
    def register_polytope(
        self,
        vertices: _ArrayLike,
        radius: float = 0.0,
        *,
        name: Optional[str] = None,
        pose: Optional[_Pose] = None,
    ) -> int:
        """Registers the convex hull of ``(N, 3)`` vertices; returns its id."""
    def register_compound(
        self,
        pieces: Sequence[Tuple[_Pose, Shape]],
        *,
        name: Optional[str] = None,
        pose: Optional[_Pose] = None,
    ) -> int:
        """Registers a union of ``(offset, Shape)`` pieces; returns its id."""
    def register_mesh(
        self,
        vertices: _ArrayLike,
        triangles: Optional[_ArrayLike] = None,
        *,
        scale: Optional[Union[float, Sequence[float]]] = None,
        decompose: Optional[int] = None,
        name: Optional[str] = None,
        pose: Optional[_Pose] = None,
        info: Optional[MeshInfo] = None,
    ) -> int:
        """Registers a triangle mesh (its hull, or decomposed); returns its id."""
    def register_mesh_file(
        self,
        path: _Path,
        *,
        scale: Optional[Union[float, Sequence[float]]] = None,
        decompose: Optional[int] = None,
        name: Optional[str] = None,
        pose: Optional[_Pose] = None,
        info: Optional[MeshInfo] = None,
    ) -> int:
        """Registers the mesh of an STL, OBJ or COLLADA file; returns its id."""
    def remove(self, id: int) -> None:
        """Removes object ``id``."""
    def lookup(self, name: str) -> int:
        """The id of the object named ``name``."""
    def set_pose(self, id: int, pose: _Pose) -> None:
        """Stores the pose of object ``id``."""
    def set_poses(self, ids: _ArrayLike, poses: _ArrayLike) -> None:
        """Stores ``(N, 7)`` or ``(N, 4, 4)`` poses of ``(N,)`` ids."""
    def poses(self, ids: _ArrayLike) -> _F64:
        """The stored poses of ``(N,)`` ids as an ``(N, 7)`` array
        ``[x, y, z, qx, qy, qz, qw]``, bit for bit as stored (a robot
        link's where its joints put it); one round trip. An unknown id
        raises ``NotFound`` (``UNKNOWN_OBJECT``, ``index`` its row)."""
    def distance(
        self,
        a: int,
        b: int,
        pose_a: Optional[_Pose] = None,
        pose_b: Optional[_Pose] = None,
        *,
        tolerance: float = ...,
        max_iterations: int = 128,
        margin: Optional[float] = None,
        warm_start: bool = True,
        signed_distance: bool = False,
        gradient: bool = False,
        gradient_base: bool = False,
    ) -> Answer:
        """The distance between objects ``a`` and ``b``.

        ``signed_distance=True`` also answers the signed distance (negative
        inside) with its certified interval; free for a pair proved apart.
        ``gradient=True`` also asks its gradient with respect to the
        coordinates that move ``a`` (``Answer.gradient``): a robot link's
        robot's moving joints (``Robot.joint_names`` order), then with
        ``gradient_base=True`` the base twist ``[v, ω]``; any other object,
        its pose's twist (world frame, turning about its origin).
        ``gradient_base=True`` without ``gradient=True`` raises
        ``InvalidInput``.
        """
    def distances(
        self,
        pairs: _ArrayLike,
        poses_a: Optional[_ArrayLike] = None,
        poses_b: Optional[_ArrayLike] = None,
        *,
        tolerance: float = ...,
        max_iterations: int = 128,
        margin: Optional[float] = None,
        warm_start: bool = True,
        signed_distance: bool = False,
        out: Optional[Distances] = None,
    ) -> Distances:
        """The distances of ``(N, 2)`` pairs in one call.

        ``signed_distance=True`` also answers each pair's signed distance
        with its certified interval (``Distances.signed_distance``,
        ``signed_lower``, ``signed_upper``). Gradients are asked by the
        room, as for scene rows: ``out=Distances(N, gradient_columns=c)``
        gets each pair's gradient in its ``(N, c)`` ``gradient`` array
        (``gradient_flags``, ``gradient_error``)."""
    def register_robot(
        self,
        name: str,
        urdf: Optional[_Path] = None,
        *,
        srdf: Optional[_Path] = None,
        urdf_text: Optional[str] = None,
        srdf_text: Optional[str] = None,
        package_path: Sequence[_Path] = ...,
        base: Optional[_Pose] = None,
    ) -> Robot:
        """Registers a robot from URDF (a file or text).

        ``package://NAME/...`` mesh URLs are searched in ``package_path``,
        then ``$GJKD_PACKAGE_PATH``, ``$ROS_PACKAGE_PATH`` and the ``share``
        folder of each ``$AMENT_PREFIX_PATH`` prefix, as ROS searches them
        (see the README's robot section)."""
    def open_robot(self, name: str, urdf_text: str) -> Robot:
        """The robot ``name`` already held (by the server, or this ``Local``),
        its joints and links read from ``urdf_text``. Raises
        :class:`gjkd.InvalidInput` with ``code`` ``INVALID_ROBOT`` (``field``
        ``"urdf"``) for text that cannot be read, :class:`gjkd.NotFound` with
        ``UNKNOWN_NAME`` for no robot of that name."""
    def remove_robot(self, robot: Union[Robot, str]) -> None:
        """Removes a robot (or the robot named so) with every link."""
    def set_joints(
        self,
        robot: Robot,
        positions: Union[_ArrayLike, Mapping[str, float]],
        *,
        base: Optional[_Pose] = None,
        clamp: bool = False,
    ) -> None:
        """Sets every joint (and the base) in one round trip; a robot without
        moving joints takes ``[]`` and moves by ``base`` alone."""
    def clearance(
        self,
        group: _ArrayLike,
        *,
        out: SceneRows,
        allow: Optional[_ArrayLike] = None,
        cutoff: Optional[float] = None,
        tolerance: float = ...,
        max_iterations: int = ...,
        warm_start: bool = True,
        motion_bounds: bool = True,
        accept_absolute: float = 0.0,
        accept_relative: float = 0.0,
        exact: bool = False,
    ) -> SceneSummary:
        """Each member's nearest object outside ``group``."""
    def within(
        self,
        group: _ArrayLike,
        margin: float,
        *,
        out: SceneRows,
        all_pairs: bool = False,
        self_pairs: bool = False,
        allow: Optional[_ArrayLike] = None,
        tolerance: float = ...,
        max_iterations: int = ...,
        warm_start: bool = True,
        motion_bounds: bool = True,
        accept_absolute: float = 0.0,
        accept_relative: float = 0.0,
        exact: bool = False,
    ) -> SceneSummary:
        """Every pair within ``margin``."""
    def nearest(
        self,
        object: int,
        k: int,
        *,
        out: SceneRows,
        allow: Optional[_ArrayLike] = None,
        cutoff: Optional[float] = None,
        tolerance: float = ...,
        max_iterations: int = ...,
        warm_start: bool = True,
        motion_bounds: bool = True,
        accept_absolute: float = 0.0,
        accept_relative: float = 0.0,
        exact: bool = False,
    ) -> SceneSummary:
        """The ``k`` objects nearest to ``object``."""
    def path(
        self,
        group: _ArrayLike,
        objects: _ArrayLike,
        poses: _ArrayLike,
        *,
        out: SceneRows,
        question: str = "clearance",
        margin: float = 0.0,
        self_pairs: bool = False,
        bracket: float = ...,
        linear_quaternions: bool = False,
        allow: Optional[_ArrayLike] = None,
        cutoff: Optional[float] = None,
        tolerance: float = ...,
        max_iterations: int = ...,
        warm_start: bool = True,
        motion_bounds: bool = True,
        accept_absolute: float = 0.0,
        accept_relative: float = 0.0,
        exact: bool = False,
    ) -> SceneSummary:
        """A question at every step of a candidate motion (``"continuous"``: every pose between)."""
    def path_joints(
        self,
        group: Union[int, Robot, _ArrayLike],
        robot: Robot,
        positions: _ArrayLike,
        *,
        out: SceneRows,
        question: str = "clearance",
        margin: float = 0.0,
        self_pairs: bool = False,
        bracket: float = ...,
        clamp: bool = False,
        allow: Optional[_ArrayLike] = None,
        cutoff: Optional[float] = None,
        tolerance: float = ...,
        max_iterations: int = ...,
        warm_start: bool = True,
        motion_bounds: bool = True,
        accept_absolute: float = 0.0,
        accept_relative: float = 0.0,
        exact: bool = False,
    ) -> SceneSummary:
        """A question at every step of a robot's motion given as ``(S, dof)`` joint positions."""
    def close(self) -> None:
        """Closes (a no-op for ``Local``)."""

@final
class Client(_Objects):
    """A connection to a gjkd server on this host.

    Objects outlive the client that registered them (a server with
    persistence keeps them across restarts); with ``remove_on_close=True``
    the objects and robots this client registers are removed when it closes
    (best effort: a server gone then keeps them).
    """

    def __new__(
        cls,
        service: str = "gjkd",
        timeout: float = 1.0,
        connect_timeout: Optional[float] = None,
        remove_on_close: bool = False,
    ) -> Self: ...
    @property
    def service(self) -> str:
        """The service name."""
    @property
    def timeout(self) -> float:
        """The timeout of every call, in seconds."""
    @property
    def connected(self) -> bool:
        """Whether the client holds a connection."""
    def server_info(self) -> Optional[dict[str, int]]:
        """The server's limits, wait mode and pid."""
    def stats(self) -> dict[str, int]:
        """The server's counters."""
    def __enter__(self) -> Client: ...
    def __exit__(
        self,
        exc_type: Optional[Type[BaseException]],
        exc: Optional[BaseException],
        tb: Optional[TracebackType],
    ) -> bool: ...

@final
class Local(_Objects):
    """Shapes and robots held in this process, answered with no server:
    every method of :class:`Client` but the server's own (``service``,
    ``timeout``, ``connected``, ``server_info``, ``stats``), with the same
    answers, bit for bit, and the same errors."""

    def __new__(cls, max_vertices: int = 100000, cache_capacity: int = 65536) -> Self: ...
    def __len__(self) -> int: ...
    def forget_warm_starts(self) -> None:
        """Forgets every pair's last simplex."""
    def __enter__(self) -> Local: ...
    def __exit__(
        self,
        exc_type: Optional[Type[BaseException]],
        exc: Optional[BaseException],
        tb: Optional[TracebackType],
    ) -> bool: ...

def serve(args: list[str]) -> int:
    """Runs ``gjkd serve`` with ``args``; returns the exit status."""

def error_codes() -> list[tuple[str, int, str]]:
    """Every error code as ``(name, value, description)``."""

def pin_thread(cpu: int) -> None:
    """Pins the calling thread to CPU ``cpu``: from now on it runs there and
    nowhere else. Put the thread that sends queries on a CPU other than the
    server's (``gjkd.Server(cpu=...)``) and away from busy processes.

    Raises :class:`gjkd.InvalidInput` (``field`` ``"cpu"``) for a CPU that
    does not exist or is outside this process's cpuset (the message lists
    the allowed ones), :class:`gjkd.IpcError` for any other refusal. On
    error the thread's affinity is unchanged."""

def set_realtime_priority(priority: int) -> None:
    """Runs the calling thread under ``SCHED_FIFO`` at ``priority`` (1 to
    99): when the server's answer wakes it, it preempts any ordinary process
    on its CPU at once.

    Raises :class:`gjkd.InvalidInput` (``field`` ``"priority"``) outside 1
    to 99, :class:`gjkd.AccessDenied` when the process has neither the
    capability ``CAP_SYS_NICE`` nor an ``RLIMIT_RTPRIO`` of at least
    ``priority`` (the message says how to grant either),
    :class:`gjkd.IpcError` for any other refusal. On error nothing
    changed."""

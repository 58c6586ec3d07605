"""Error codes and statuses, the integers of the ``error`` and ``status``
arrays of :class:`gjkd.Distances`."""

from __future__ import annotations

import enum

__all__ = ["ErrorCode", "Status"]


class ErrorCode(enum.IntEnum):
    """Why an item or a call failed (``docs/errors.md`` has the full table)."""

    OK = 0
    """No error."""
    UNKNOWN_OBJECT = 1
    """No object has this id (never registered, removed, or from a server run
    that has ended)."""
    NON_FINITE_POSE = 2
    """A pose has a NaN or infinite component, or lies beyond about 1e301."""
    BAD_QUATERNION = 3
    """A rotation is not of unit length (within 1e-6), or a 4x4 matrix is not
    a rigid motion."""
    INVALID_OPTIONS = 4
    """A query option is out of its domain."""
    EMPTY_VERTICES = 5
    """A shape has no vertices."""
    TOO_MANY_VERTICES = 6
    """A shape has more vertices than the server accepts."""
    INVALID_RADIUS = 7
    """A radius is negative, NaN or infinite."""
    BATCH_TOO_LARGE = 8
    """A batch has more items than the server accepts (never seen from
    Python: batches are split)."""
    EMPTY_BATCH = 9
    """A batch has no items."""
    MALFORMED = 10
    """A request no client should send."""
    NOT_OWNER = 11
    """The object belongs to another client."""
    READ_ONLY = 12
    """The object comes from the server's scene file."""
    TOO_MANY_PIECES = 13
    """A compound has more than 64 pieces."""
    EMPTY_COMPOUND = 14
    """A compound has no pieces."""
    NON_FINITE_VERTEX = 15
    """A vertex has a NaN or infinite coordinate."""
    UNKNOWN_NAME = 16
    """No object has this name."""
    NAME_TAKEN = 17
    """Another object already has this name."""
    TOO_MANY_OBJECTS = 18
    """The server holds as many objects as it accepts."""
    INTERNAL = 19
    """The server failed in a way that is its own fault; it keeps serving."""
    STORAGE_FULL = 20
    """The server's disk has no room to store a registration or removal: the
    change was not made. Queries and pose updates are still served; the same
    call succeeds once there is room again, without a server restart."""
    OUT_OF_LIMITS = 21
    """A joint position is outside its joint's limits."""
    INVALID_ROBOT = 22
    """A robot's URDF is malformed or its kinematic tree is not supported."""


class Status(enum.IntEnum):
    """How a query ended."""

    NONE = 0
    """No answer: the row failed (see its error code)."""
    CONVERGED = 1
    """The stopping rule held: the distance is exact to the tolerance."""
    FARTHER = 2
    """Early exit: the distance is proved greater than the margin."""
    CLOSER = 3
    """Early exit: the distance is proved at most the margin."""
    ITERATION_CAP = 4
    """The iteration cap was reached first; the bounds still hold."""
    TOLERANCE_NOT_MET = 5
    """Round-off stopped progress before the tolerance was met; the bounds
    still hold."""
    BOUNDED = 6
    """Scene queries only: answered without running GJK, from the pair's last
    certified interval widened by how far the objects moved since; the bounds
    hold, the distance and points are the last answer's carried along."""

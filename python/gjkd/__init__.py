"""gjkd: certified distances between convex shapes, from Python.

Three ways to the same answers, all on numpy arrays:

- :class:`Client` talks to a gjkd server on this host over shared memory
  (start one with :class:`Server` or ``python -m gjkd serve``);
- :class:`Local` (also ``gjkd.local.Local``) holds the shapes and robots
  in this process and answers the same calls (robots and scene questions
  included), bit for bit, with no server;
- :class:`Server` runs a server in a child process.

Latency on a busy host: ``gjkd.Server(wait=..., cpu=..., priority=...)``
chooses the server's wait mode, its CPU and a real-time priority;
:func:`pin_thread` and :func:`set_realtime_priority` do the same for the
thread that sends queries. ``docs/deployment.md`` says which to use for a
control loop, a planner or a batch job, with measured figures.

Register shapes once (``register_sphere``, ``register_capsule``,
``register_box``, ``register_polytope``, ``register_compound``; each returns
an int id), set poses (``set_pose``, ``set_poses``: ``[x, y, z, qx, qy, qz,
qw]`` rows or 4x4 matrices), then ask ``distance(a, b)`` for one pair or
``distances(pairs)`` for many in one call. Every answer carries certified
bounds ``lower <= distance <= upper``, nearest points and a normal.

Scene queries ask about a group of objects against everything the server
(or the :class:`Local`) holds, in one round trip, into a :class:`SceneRows`
you own:
``client.clearance(group, out=rows)`` (each member's nearest other object),
``client.within(group, margin, out=rows)`` (every pair within a margin),
``client.nearest(object, k, out=rows)``, ``client.path(group, objects,
poses, out=rows)`` (a question at every step of a candidate motion) and
``client.path_joints(robot, robot, positions, out=rows)`` (the same along a
robot's joint positions).

:mod:`gjkd.ompl` (imported on its own: ``import gjkd.ompl``) plugs a robot
on a server into OMPL's planners: a state validity checker, a motion
validator and a clearance, one scene request each.

Example::

    import numpy as np
    import gjkd

    with gjkd.Server(service="example") as server, gjkd.Client("example") as client:
        ball = client.register_sphere(0.5)
        crate = client.register_box([1.0, 1.0, 1.0])
        client.set_pose(ball, [3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
        print(client.distance(crate, ball).distance)  # 1.5
        result = client.distances(np.array([[crate, ball]]))
        print(result.distance, result.point_a, result.error)
"""

from __future__ import annotations

from . import local
from ._codes import ErrorCode, Status
from ._errors import (
    AccessDenied,
    Error,
    Incompatible,
    InvalidInput,
    IpcError,
    NotFound,
    ProtocolError,
    Refused,
    ServerGone,
    Timeout,
)
from ._native import (
    DEFAULT_MAX_ITERATIONS,
    DEFAULT_TOLERANCE,
    MAX_NAME_LEN,
    MAX_PIECES,
    PROTOCOL_VERSION,
    Answer,
    Client,
    Distances,
    Local,
    MeshInfo,
    Robot,
    SceneRows,
    SceneSummary,
    Shape,
    pin_thread,
    set_realtime_priority,
)
from .server import Server

__all__ = [
    "AccessDenied",
    "DEFAULT_MAX_ITERATIONS",
    "DEFAULT_TOLERANCE",
    "MAX_NAME_LEN",
    "MAX_PIECES",
    "PROTOCOL_VERSION",
    "Answer",
    "Client",
    "Distances",
    "Error",
    "ErrorCode",
    "Incompatible",
    "InvalidInput",
    "IpcError",
    "Local",
    "MeshInfo",
    "NotFound",
    "ProtocolError",
    "Refused",
    "Robot",
    "SceneRows",
    "SceneSummary",
    "Server",
    "ServerGone",
    "Shape",
    "Status",
    "Timeout",
    "local",
    "pin_thread",
    "set_realtime_priority",
]

__version__ = "0.1.0"

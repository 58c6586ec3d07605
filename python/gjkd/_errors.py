"""The exceptions of gjkd: every failure of a whole call is a :class:`Error`.

Per-pair failures of a batch are not raised: they come back as codes in the
``error`` array of :class:`gjkd.Distances`.
"""

from __future__ import annotations

from typing import Optional

from ._codes import ErrorCode

__all__ = [
    "Error",
    "ServerGone",
    "Timeout",
    "InvalidInput",
    "NotFound",
    "Refused",
    "ProtocolError",
    "IpcError",
    "Incompatible",
    "AccessDenied",
]


class Error(Exception):
    """Base class of every gjkd exception.

    Attributes:
        code: the server's :class:`ErrorCode` for the failure, when it has one.
        field: the name of the argument at fault (``"pose"``, ``"vertices"``,
            ``"pairs"``, ...), when known.
        index: the row of that argument at fault, for array arguments.
    """

    code: Optional[ErrorCode]
    field: Optional[str]
    index: Optional[int]

    def __init__(
        self,
        message: str,
        *,
        code: Optional[int] = None,
        field: Optional[str] = None,
        index: Optional[int] = None,
    ) -> None:
        super().__init__(message)
        self.code = ErrorCode(code) if code is not None else None
        self.field = field
        self.index = index


class ServerGone(Error, ConnectionError):
    """No server serves the service: never started, stopped, or died. The
    client's next call reconnects by itself once a server serves it again."""


class Timeout(Error, TimeoutError):
    """The server is alive but did not answer within the client's timeout."""


class InvalidInput(Error, ValueError):
    """An argument is wrong: its shape, dtype or value (``field`` names it,
    ``index`` its row, ``code`` the server's reason when it has one)."""


class NotFound(Error, LookupError):
    """No object has this id (``code`` ``UNKNOWN_OBJECT``) or name
    (``UNKNOWN_NAME``)."""


class Refused(Error):
    """The server refused a valid request: another client's object
    (``NOT_OWNER``), a read-only scene object, a taken name, a full server
    (of objects, or of clients), or its own failure (``INTERNAL``)."""


class ProtocolError(Error):
    """The server answered something this client does not understand."""


class Incompatible(ProtocolError):
    """A server serves this name but cannot be spoken to: another protocol
    version (another gjkd release), or a service made by another program or
    build. Retrying does not help."""


class AccessDenied(Error, PermissionError):
    """The service belongs to another user, whom this process may not
    reach (run client and server as the same user)."""


class IpcError(Error, OSError):
    """Shared memory could not be set up in this process."""

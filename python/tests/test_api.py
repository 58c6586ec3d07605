"""The package's public surface: every name documented, signatures that
`help()` and editors can read."""

from __future__ import annotations

import inspect

import gjkd


def public_members(obj: object) -> list[str]:
    return [n for n in dir(obj) if not n.startswith("_")]


def test_every_public_name_has_a_docstring() -> None:
    missing = []
    for name in gjkd.__all__:
        obj = getattr(gjkd, name)
        if isinstance(obj, (int, float)):
            continue
        if not (obj.__doc__ or "").strip():
            missing.append(name)
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            for member in public_members(obj):
                attr = getattr(obj, member)
                if isinstance(attr, (int, float)) or member in ("name", "value"):
                    continue
                if not (getattr(attr, "__doc__", None) or "").strip():
                    missing.append(f"{name}.{member}")
    assert missing == []


def test_signatures_are_readable_and_defaults_true() -> None:
    for cls in (gjkd.Client, gjkd.Local):
        for method in ("distance", "distances"):
            params = inspect.signature(getattr(cls, method)).parameters
            assert params["tolerance"].default == gjkd.DEFAULT_TOLERANCE
            assert params["max_iterations"].default == gjkd.DEFAULT_MAX_ITERATIONS
            assert params["warm_start"].default is True
        for method in public_members(cls):
            inspect.signature(getattr(cls, method)) if callable(getattr(cls, method)) else None


def test_error_hierarchy() -> None:
    assert issubclass(gjkd.ServerGone, ConnectionError)
    assert issubclass(gjkd.Timeout, TimeoutError)
    assert issubclass(gjkd.InvalidInput, ValueError)
    assert issubclass(gjkd.NotFound, LookupError)
    for cls in (gjkd.ServerGone, gjkd.Timeout, gjkd.InvalidInput, gjkd.NotFound, gjkd.Refused,
                gjkd.ProtocolError, gjkd.IpcError):  # fmt: skip
        assert issubclass(cls, gjkd.Error)
    e = gjkd.InvalidInput("x", code=3, field="pose", index=2)
    assert e.code is gjkd.ErrorCode.BAD_QUATERNION and e.field == "pose" and e.index == 2


def test_local_module_is_the_same_class() -> None:
    assert gjkd.local.Local is gjkd.Local

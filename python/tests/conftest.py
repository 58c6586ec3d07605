"""Fixtures: a real server per test module, on a service name of its own."""

from __future__ import annotations

import itertools
import os
from typing import Iterator

import pytest

import gjkd

_names = itertools.count()


def unique_service(tag: str) -> str:
    """A service name no other test (or test run) uses."""
    return f"gjkd-pytest-{os.getpid()}-{tag}-{next(_names)}"


@pytest.fixture(scope="module")
def server() -> Iterator[gjkd.Server]:
    with gjkd.Server(service=unique_service("mod"), wait="spin") as s:
        yield s


@pytest.fixture()
def client(server: gjkd.Server) -> Iterator[gjkd.Client]:
    with gjkd.Client(server.service) as c:
        yield c


@pytest.fixture(params=["client", "local"])
def objects(request: pytest.FixtureRequest, server: gjkd.Server) -> Iterator[object]:
    """A Client of the module's server, then a Local: the same tests run on
    both."""
    if request.param == "client":
        with gjkd.Client(server.service) as c:
            yield c
    else:
        with gjkd.Local() as local:
            yield local

"""Where and how urgently threads run: ``gjkd.Server(cpu=..., priority=...)``,
``gjkd.pin_thread`` and ``gjkd.set_realtime_priority``."""

from __future__ import annotations

import os
import threading
from typing import Callable

import pytest

import gjkd
from conftest import unique_service


def allowed_cpus(pid: int = 0) -> set[int]:
    return set(os.sched_getaffinity(pid))


def in_thread(body: Callable[[], None]) -> None:
    """Runs ``body`` on a thread of its own (whose pin dies with it) and
    re-raises what it raised."""
    failure: list[BaseException] = []

    def run() -> None:
        try:
            body()
        except BaseException as e:  # noqa: BLE001 - handed to the caller
            failure.append(e)

    t = threading.Thread(target=run)
    t.start()
    t.join()
    if failure:
        raise failure[0]


def test_a_server_pinned_to_a_cpu_serves_from_it() -> None:
    cpu = max(allowed_cpus())
    with gjkd.Server(service=unique_service("cpu"), cpu=cpu) as server:
        assert server.pid is not None
        # The serving loop runs on the process's main thread, whose id is
        # the process id.
        assert allowed_cpus(server.pid) == {cpu}
        with server.client() as client:
            a = client.register_sphere(1.0)
            b = client.register_sphere(1.0, pose=[5.0, 0, 0, 0, 0, 0, 1])
            assert abs(client.distance(a, b).distance - 3.0) < 1e-9


def test_a_server_given_a_cpu_that_does_not_exist_refuses_to_start() -> None:
    server = gjkd.Server(service=unique_service("nocpu"), cpu=1 << 20)
    with pytest.raises(gjkd.Error, match="--cpu 1048576: CPU 1048576 does not exist"):
        server.start()
    assert not server.running


def test_a_server_given_a_priority_out_of_range_refuses_to_start() -> None:
    server = gjkd.Server(service=unique_service("prio"), priority=100)
    with pytest.raises(gjkd.Error, match="--priority 100: SCHED_FIFO priority 100 is out of range"):
        server.start()
    assert not server.running


def test_pin_thread_pins_the_calling_thread_only() -> None:
    before = allowed_cpus()
    cpu = min(before)

    def body() -> None:
        gjkd.pin_thread(cpu)
        assert allowed_cpus() == {cpu}

    in_thread(body)
    assert allowed_cpus() == before


def test_pin_thread_refuses_a_cpu_that_does_not_exist() -> None:
    before = allowed_cpus()

    def body() -> None:
        with pytest.raises(gjkd.InvalidInput, match="does not exist") as info:
            gjkd.pin_thread(1 << 20)
        assert info.value.field == "cpu"
        assert allowed_cpus() == before

    in_thread(body)


def test_set_realtime_priority_refuses_a_priority_out_of_range() -> None:
    def body() -> None:
        for p in (0, 100):
            with pytest.raises(gjkd.InvalidInput, match="1 to 99") as info:
                gjkd.set_realtime_priority(p)
            assert info.value.field == "priority"
        assert os.sched_getscheduler(0) == os.SCHED_OTHER

    in_thread(body)


def test_set_realtime_priority_works_or_names_what_to_grant() -> None:
    def body() -> None:
        try:
            gjkd.set_realtime_priority(2)
        except gjkd.AccessDenied as e:
            assert "CAP_SYS_NICE" in str(e) and "RLIMIT_RTPRIO" in str(e)
            assert os.sched_getscheduler(0) == os.SCHED_OTHER
        else:
            assert os.sched_getscheduler(0) == os.SCHED_FIFO

    in_thread(body)

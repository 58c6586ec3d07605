"""A server that dies or restarts, seen from Python."""

from __future__ import annotations

import pathlib
import subprocess
import sys
import time

import numpy as np
import pytest

import gjkd
from conftest import unique_service


def test_killed_server_raises_within_the_timeout_and_a_restarted_one_serves() -> None:
    service = unique_service("crash")
    timeout = 0.5
    with gjkd.Server(service=service) as server:
        client = gjkd.Client(service, timeout=timeout)
        a = client.register_sphere(1.0)
        b = client.register_sphere(1.0, pose=[5.0, 0, 0, 0, 0, 0, 1])
        assert abs(client.distance(a, b).distance - 3.0) < 1e-9
        server.kill()
        for call in (
            lambda: client.distance(a, b),
            lambda: client.distances(np.array([[a, b]] * 10)),
            lambda: client.register_sphere(1.0),
        ):
            start = time.monotonic()
            with pytest.raises((gjkd.ServerGone, gjkd.Timeout)):
                call()
            # Within the timeout, plus what a loaded 2-core machine may add
            # to waking up: not a timing assertion, a bound on hanging.
            assert time.monotonic() - start < timeout + 2.0

        server.start()
        # The server kept objects in memory only: the old ids are unknown
        # to the new one, which the same client reaches by itself.
        with pytest.raises(gjkd.NotFound):
            client.distance(a, b)
        c = client.register_sphere(1.0)
        d = client.register_sphere(2.0, pose=[0.0, 6.0, 0, 0, 0, 0, 1])
        assert abs(client.distance(c, d).distance - 3.0) < 1e-9
        client.close()


def test_no_server_raises_server_gone() -> None:
    start = time.monotonic()
    with pytest.raises(gjkd.ServerGone):
        gjkd.Client(unique_service("nobody"), timeout=0.2)
    assert time.monotonic() - start < 5.0


def test_closed_client_raises() -> None:
    with gjkd.Server(service=unique_service("closed")) as server:
        client = server.client()
        client.close()
        with pytest.raises(gjkd.Error):
            client.register_sphere(1.0)
        assert not client.connected


def test_server_stops_on_exit_and_reports_a_failed_start() -> None:
    service = unique_service("twice")
    with gjkd.Server(service=service) as first:
        assert first.running
        pid = first.pid
        # A second server on the same service cannot start; its own error
        # is reported, and the first keeps serving.
        with pytest.raises(gjkd.Error):
            gjkd.Server(service=service, ready_timeout=5.0).start()
        with gjkd.Client(service) as client:
            assert client.server_info()["pid"] == pid  # type: ignore[index]
    assert not first.running


def test_python_m_gjkd_serve_runs_and_stops_on_sigterm(tmp_path: pathlib.Path) -> None:
    service = unique_service("cli")
    # Away from the source tree, which `-m` would find first.
    process = subprocess.Popen(
        [sys.executable, "-m", "gjkd", "serve", "--service", service, "--no-persist"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        cwd=tmp_path,
    )
    try:
        with gjkd.Client(service, timeout=1.0, connect_timeout=10.0) as client:
            assert client.server_info()["pid"] == process.pid  # type: ignore[index]
    finally:
        process.terminate()
        assert process.wait(10) == 0


def test_serve_takes_the_flags_of_gjkd_serve(tmp_path: pathlib.Path) -> None:
    def run(*args: str) -> "subprocess.CompletedProcess[str]":
        return subprocess.run(
            [sys.executable, "-m", "gjkd", *args],
            capture_output=True,
            text=True,
            cwd=tmp_path,
            timeout=60,
        )

    helped = run("serve", "--help")
    assert helped.returncode == 0
    for flag in ("--service", "--wait", "--max-batch", "--state-file", "--no-persist", "--scene"):
        assert flag in helped.stdout
    wrong = run("serve", "--no-such-flag")
    assert wrong.returncode == 2 and "--no-such-flag" in wrong.stderr
    assert run("frobnicate").returncode == 2


def test_a_persisting_server_keeps_ids_across_a_crash(tmp_path: pathlib.Path) -> None:
    service = unique_service("persist")
    server = gjkd.Server(service=service, persist=True, state_file=tmp_path / "objects")
    with server, gjkd.Client(service, timeout=0.5) as client:
        a = client.register_box([1.0, 1.0, 1.0])
        b = client.register_sphere(0.5, pose=[3.0, 0, 0, 0, 0, 0, 1])
        server.kill()
        with pytest.raises(gjkd.ServerGone):
            client.distance(a, b)
        server.start()
        assert abs(client.distance(a, b).distance - 1.5) < 1e-9

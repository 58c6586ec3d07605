"""The GIL is released while a call waits for the server: another Python
thread runs meanwhile. Shown without timing: the server is stopped
(SIGSTOP) and only another Python thread resumes it, so the call is
answered only if that thread could run during it."""

from __future__ import annotations

import os
import signal
import threading
import time
from typing import Any, Callable

import numpy as np
import pytest

import gjkd
from conftest import unique_service


@pytest.mark.parametrize("batched", [False, True])
def test_calls_release_the_gil_while_waiting(batched: bool) -> None:
    with gjkd.Server(service=unique_service("gil")) as server:
        pid = server.pid
        assert pid is not None
        with gjkd.Client(server.service, timeout=10.0) as client:
            a = client.register_sphere(1.0)
            b = client.register_sphere(1.0, pose=[5.0, 0, 0, 0, 0, 0, 1])
            call: Callable[[], Any]
            if batched:
                call = lambda: client.distances(np.array([[a, b]] * 100)).distance[0]  # noqa: E731
            else:
                call = lambda: client.distance(a, b).distance  # noqa: E731

            def resume() -> None:
                # Needs the GIL after its sleep: it runs only if the call
                # below has released it.
                time.sleep(0.2)
                os.kill(pid, signal.SIGCONT)

            os.kill(pid, signal.SIGSTOP)
            helper = threading.Thread(target=resume)
            helper.start()
            try:
                # Held GIL: the helper never resumes the server and this
                # raises Timeout after 10 s.
                assert abs(call() - 3.0) < 1e-9
            finally:
                os.kill(pid, signal.SIGCONT)
                helper.join()

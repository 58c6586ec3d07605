"""``gjkd.Server``: a gjkd server in a child process, for scripts, tests and
notebooks."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
import time
from types import TracebackType
from typing import IO, Optional, Sequence, Type, Union

from . import _native
from ._errors import Error, Incompatible, ServerGone, Timeout

__all__ = ["Server"]

PathLike = Union[str, "os.PathLike[str]"]


class Server:
    """A gjkd server run in a child process (``python -m gjkd serve``).

    Use it as a context manager: entering starts the server and returns once
    it answers, leaving stops it::

        with gjkd.Server(service="demo") as server, gjkd.Client("demo") as client:
            ...

    Args:
        service: the deployment name clients connect to (``gjkd.Client(service)``).
        wait: the server's wait strategy: ``"adaptive"`` (the default:
            spins briefly after each request, then sleeps until a client
            wakes it; near ``"spin"`` for back-to-back requests and as fast
            as ``"block"`` for paced ones, however busy the machine),
            ``"spin"`` (lowest latency, keeps a core busy: only on a CPU of
            its own) or ``"block"`` (no busy core at all).
        cpu: pin the serving thread to this CPU (``gjkd serve --cpu``);
            best one that no busy process and not the client uses.
        priority: run the serving thread at this ``SCHED_FIFO`` priority (1
            to 99, ``gjkd serve --priority``), so that a woken server
            preempts ordinary processes at once. Needs ``CAP_SYS_NICE`` or
            an ``RLIMIT_RTPRIO`` of at least ``priority``; without, the
            server refuses to start and :meth:`start` raises
            :class:`gjkd.Error` quoting its message, which names both.
        persist: keep registered objects in a state file across restarts
            (``state_file``, or the server's default path). Off by default:
            the server holds its objects in memory only.
        state_file: the state file, when ``persist`` is on.
        scene: a TOML scene file of read-only named objects.
        args: further ``gjkd serve`` flags, e.g. ``["--max-batch", "256"]``.
        ready_timeout: seconds to wait for the server to answer.
        log: where the server's log goes: ``None`` (default) keeps it in a
            temporary file, quoted if the server fails to start; or an open
            file.
    """

    def __init__(
        self,
        service: str = "gjkd",
        *,
        wait: str = "adaptive",
        cpu: Optional[int] = None,
        priority: Optional[int] = None,
        persist: bool = False,
        state_file: Optional[PathLike] = None,
        scene: Optional[PathLike] = None,
        args: Sequence[str] = (),
        ready_timeout: float = 10.0,
        log: Optional[IO[str]] = None,
    ) -> None:
        self.service = service
        self.ready_timeout = ready_timeout
        flags = ["--service", service, "--wait", wait]
        if cpu is not None:
            flags += ["--cpu", str(cpu)]
        if priority is not None:
            flags += ["--priority", str(priority)]
        if persist:
            if state_file is not None:
                flags += ["--state-file", os.path.abspath(state_file)]
        else:
            flags.append("--no-persist")
        if scene is not None:
            flags += ["--scene", os.path.abspath(scene)]
        flags += list(args)
        self.args = flags
        self._log = log
        self._own_log: Optional[IO[str]] = None
        self._process: Optional[subprocess.Popen[bytes]] = None

    @property
    def command(self) -> list[str]:
        """The command line that starts the server."""
        return [sys.executable, "-m", "gjkd", "serve", *self.args]

    @property
    def pid(self) -> Optional[int]:
        """The server process's id while it runs."""
        return self._process.pid if self._process is not None else None

    @property
    def running(self) -> bool:
        """Whether the server process is alive."""
        return self._process is not None and self._process.poll() is None

    def start(self) -> "Server":
        """Starts the server and waits until it answers (at most
        ``ready_timeout`` seconds). Raises :class:`gjkd.Error` if it exits
        first (another server may already serve this service: the log
        says), :class:`gjkd.Timeout` if it does not answer in time."""
        if self.running:
            return self
        log = self._log
        if log is None:
            self._own_log = tempfile.TemporaryFile(mode="w+")
            log = self._own_log
        # Started from the directory that holds this very package, so that
        # `-m gjkd` (which looks in the working directory first) runs it and
        # not some other copy, such as a source tree without its extension.
        here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
        self._process = subprocess.Popen(
            self.command, stdin=subprocess.DEVNULL, stdout=log, stderr=log, cwd=here
        )
        self._wait_ready()
        return self

    def _wait_ready(self) -> None:
        assert self._process is not None
        deadline = time.monotonic() + self.ready_timeout
        while True:
            code = self._process.poll()
            if code is not None:
                raise Error(f"gjkd serve exited with status {code}: {self._log_tail()}")
            try:
                with _native.Client(self.service, timeout=0.5, connect_timeout=0.1) as probe:
                    info = probe.server_info()
                if info is not None and info["pid"] == self._process.pid:
                    return
            except (ServerGone, Timeout, Incompatible):
                # A service still being set up (or one a killed server left
                # behind, until the new server has cleaned it up) can look
                # incompatible for a moment.
                pass
            if time.monotonic() > deadline:
                self.kill()
                raise Timeout(
                    f"gjkd serve did not answer within {self.ready_timeout} s: {self._log_tail()}"
                )
            time.sleep(0.02)

    def _log_tail(self) -> str:
        if self._own_log is None:
            return "(log not captured)"
        self._own_log.seek(0)
        return self._own_log.read()[-2000:].strip()

    def log(self) -> str:
        """What the server has logged so far (when ``log`` was not given)."""
        return self._log_tail()

    def stop(self, timeout: float = 5.0) -> Optional[int]:
        """Stops the server (SIGTERM, then SIGKILL after ``timeout``
        seconds); returns its exit status, ``None`` if it was not running."""
        process = self._process
        if process is None:
            return None
        if process.poll() is None:
            process.send_signal(signal.SIGTERM)
            try:
                process.wait(timeout)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
        self._process = None
        return process.returncode

    def kill(self) -> None:
        """Kills the server at once (SIGKILL), as a crash would."""
        if self._process is not None and self._process.poll() is None:
            self._process.kill()
            self._process.wait()

    def client(self, timeout: float = 1.0) -> "_native.Client":
        """A new :class:`gjkd.Client` of this server."""
        return _native.Client(self.service, timeout=timeout)

    def __enter__(self) -> "Server":
        return self.start()

    def __exit__(
        self,
        exc_type: Optional[Type[BaseException]],
        exc: Optional[BaseException],
        tb: Optional[TracebackType],
    ) -> None:
        self.stop()
        if self._own_log is not None:
            self._own_log.close()
            self._own_log = None

    def __repr__(self) -> str:
        state = f"pid {self.pid}" if self.running else "stopped"
        return f"gjkd.Server(service={self.service!r}, {state})"

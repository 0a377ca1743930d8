"""A meshcat server subprocess whose shutdown is guaranteed: the one way this package opens meshcat.

meshcat is an optional dependency (extra ``viz``); it is imported here, lazily, with a message
saying how to install it. ``meshcat.Visualizer()`` starts ``meshcat.servers.zmqserver`` as a
subprocess in a session of its own; meshcat 0.3.2 has no ``close()``, so :class:`MeshcatServer`
kills that process group and waits for it on exit from its ``with`` block, whatever happened inside,
an interruption (SIGINT, SIGTERM) included, even one arriving while the server starts: a server
whose start was cut short is found in the process table (a child of ours running
``meshcat.servers.zmqserver``) and killed.
"""

# meshcat and zmq are imported inside functions: import turntable_pin stays light
from __future__ import annotations

import contextlib
import io
import os
import signal

from ..core.exceptions import TurntablePinError
from ..core.interrupts import deferred, register_cleanup
from .browser import process_table

__all__ = [
    "REPLY_TIMEOUT_S",
    "MeshcatMissingError",
    "MeshcatServer",
    "MeshcatServerError",
    "import_meshcat",
]


class MeshcatMissingError(TurntablePinError):
    """The optional dependency meshcat is not installed."""


class MeshcatServerError(TurntablePinError):
    """The meshcat server stopped answering."""


REPLY_TIMEOUT_S = 60.0
"""Longest wait for one reply of the meshcat server (a static page takes well under a second)."""

_SERVER_MODULE = "meshcat.servers.zmqserver"
_owned_pids: set[int] = set()  # servers of this process that a MeshcatServer holds


def _kill_unowned_servers() -> None:
    """Kill and reap the meshcat servers this process started that no MeshcatServer holds (a
    start cut short by an interruption leaves the server's Popen object in meshcat's hands)."""
    with deferred():
        me = os.getpid()
        for p in process_table():
            if p.ppid == me and p.pid not in _owned_pids and _SERVER_MODULE in p.cmdline:
                for kill, target in ((os.killpg, p.pid), (os.kill, p.pid)):
                    try:
                        kill(target, signal.SIGKILL)
                    except (ProcessLookupError, PermissionError):
                        pass
                try:
                    os.waitpid(p.pid, 0)
                except ChildProcessError:
                    pass


def import_meshcat():
    """The ``meshcat`` module, or :class:`MeshcatMissingError` saying how to install it."""
    try:
        import meshcat
    except ImportError:
        raise MeshcatMissingError(
            "the 3-D viewer needs the optional package meshcat: "
            "pip install 'turntable-pin[viz]' (or pip install meshcat)"
        ) from None
    return meshcat


class MeshcatServer:
    """Context manager: a running meshcat server and a ``meshcat.Visualizer`` connected to it
    (``server.visualizer``, ``server.url``); the server process is gone after the block."""

    def __init__(self) -> None:
        self.visualizer = None
        self.pid: int | None = None
        self._unregister = lambda: None

    def __enter__(self) -> MeshcatServer:
        meshcat = import_meshcat()
        # Registered before the start: an interrupted command line stops the server in any case.
        self._unregister = register_cleanup(self._abandon)
        try:
            # meshcat prints the URL on stdout when it connects; the caller decides what to print.
            with contextlib.redirect_stdout(io.StringIO()):
                self.visualizer = meshcat.Visualizer()
            self.pid = self.visualizer.window.server_proc.pid
            _owned_pids.add(self.pid)
            import zmq

            # Without a timeout a dead server would block the client's recv() forever.
            self.visualizer.window.zmq_socket.setsockopt(zmq.RCVTIMEO, int(REPLY_TIMEOUT_S * 1000))
        except BaseException:
            self._abandon()
            self._unregister()
            raise
        return self

    def _abandon(self) -> None:
        """Stop the server, also one whose start was cut short."""
        self.stop()
        _kill_unowned_servers()

    def __exit__(self, exc_type, exc, traceback) -> None:
        self.stop()
        self._unregister()
        import zmq

        if exc_type is not None and issubclass(exc_type, zmq.error.Again):
            raise MeshcatServerError(
                f"the meshcat server did not answer within {REPLY_TIMEOUT_S:g} s"
            ) from None

    @property
    def url(self) -> str:
        """The viewer's web address (``http://127.0.0.1:PORT/static/``)."""
        return self.visualizer.url()

    @property
    def running(self) -> bool:
        """Whether the server process is still running."""
        return self.visualizer is not None and self.visualizer.window.server_proc.poll() is None

    def stop(self) -> None:
        """Kill the server's process group and reap it; close the client socket. Idempotent."""
        with deferred():  # a signal arriving meanwhile is raised once the server is gone
            if self.visualizer is None:
                return
            window = self.visualizer.window
            proc = window.server_proc
            try:
                # The server runs in its own session (start_new_session): its pid is its group.
                os.killpg(proc.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
            if proc.poll() is None:
                proc.kill()
            proc.wait()
            for stream in (proc.stdout, proc.stderr):
                if stream is not None:
                    stream.close()
            # linger=0: a request still queued for the dead server must not block the exit.
            window.zmq_socket.close(linger=0)
            _owned_pids.discard(proc.pid)
            self.visualizer = None

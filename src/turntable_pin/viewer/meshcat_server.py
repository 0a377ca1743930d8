"""A meshcat server subprocess whose shutdown is guaranteed: the one way this package opens meshcat.

meshcat is an optional dependency (extra ``viz``); it is imported here, lazily, with a message
saying how to install it. ``meshcat.Visualizer()`` starts ``meshcat.servers.zmqserver`` as a
subprocess in a session of its own; meshcat 0.3.2 has no ``close()``, so :class:`MeshcatServer`
kills that process group and waits for it on exit from its ``with`` block, whatever happened inside.
"""

from __future__ import annotations

import contextlib
import io
import os
import signal

from ..core.exceptions import TurntablePinError

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
    """Context manager: a running meshcat server and a ``meshcat.Visualizer`` connected to it.

    Example::

        with MeshcatServer() as server:
            server.visualizer["box"].set_object(...)
            print(server.url)
        # the server process is gone here
    """

    def __init__(self) -> None:
        self.visualizer = None
        self.pid: int | None = None

    def __enter__(self) -> MeshcatServer:
        meshcat = import_meshcat()
        # meshcat prints the URL on stdout when it connects; the caller decides what to print.
        with contextlib.redirect_stdout(io.StringIO()):
            self.visualizer = meshcat.Visualizer()
        self.pid = self.visualizer.window.server_proc.pid
        import zmq

        # Without a timeout a dead server would block the client's recv() forever.
        self.visualizer.window.zmq_socket.setsockopt(zmq.RCVTIMEO, int(REPLY_TIMEOUT_S * 1000))
        return self

    def __exit__(self, exc_type, exc, traceback) -> None:
        self.stop()
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
        if self.visualizer is None:
            return
        window = self.visualizer.window
        proc = window.server_proc
        try:
            # The server runs in its own session (start_new_session), so its pid is its group.
            os.killpg(proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        if proc.poll() is None:
            proc.kill()
        proc.wait()
        for stream in (proc.stdout, proc.stderr):
            if stream is not None:
                stream.close()
        # linger=0: a request still queued for the dead server must not block interpreter exit.
        window.zmq_socket.close(linger=0)
        self.visualizer = None

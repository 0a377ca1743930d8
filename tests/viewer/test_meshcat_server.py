"""Tests of the meshcat server wrapper: it always stops its server, and says how to get meshcat."""

from __future__ import annotations

import builtins

import pytest

from process_watch import alive
from turntable_pin.viewer.meshcat_server import (
    MeshcatMissingError,
    MeshcatServer,
    MeshcatServerError,
    import_meshcat,
)


def test_server_runs_inside_and_is_gone_after_an_error():
    pytest.importorskip("meshcat")
    with pytest.raises(ZeroDivisionError):
        with MeshcatServer() as server:
            pid = server.pid
            assert alive(pid) and server.running
            assert server.url.startswith("http://127.0.0.1:")
            raise ZeroDivisionError("inside the with block")
    assert not alive(pid)
    server.stop()  # idempotent


def test_missing_meshcat_says_how_to_install_it(monkeypatch):
    real_import = builtins.__import__

    def no_meshcat(name, *args, **kwargs):
        if name == "meshcat" or name.startswith("meshcat."):
            raise ImportError("No module named 'meshcat'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_meshcat)
    with pytest.raises(MeshcatMissingError, match=r"turntable-pin\[viz\]"):
        import_meshcat()


def test_a_silent_server_is_an_error_not_a_hang(monkeypatch):
    pytest.importorskip("meshcat")
    import os
    import signal

    import zmq

    with pytest.raises(MeshcatServerError, match="did not answer"):
        with MeshcatServer() as server:
            server.visualizer.window.zmq_socket.setsockopt(zmq.RCVTIMEO, 300)
            # Stopped, not killed: a killed server frees its port, and a server started meanwhile by
            # another test worker may take that port and answer the request (a flaky pass of the
            # recv). A stopped server keeps its port and never answers; the exit kills it anyway.
            os.kill(server.pid, signal.SIGSTOP)
            server.visualizer.static_html()
    assert not alive(server.pid)

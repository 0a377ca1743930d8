"""SIGINT and SIGTERM end every command at once, cleanly: nothing lost, runaway or left behind.

Each command runs as a real child process (``python -m turntable_pin``) in a session of its own,
with ``TMPDIR`` pointing at an empty folder of the test. It is interrupted at a moment it reports
itself (handlers installed, meshcat server started, Chromium running, workers computing), with
SIGINT sent to its whole process group as a terminal's Ctrl-C is, or SIGTERM sent to it alone as a
plain ``kill`` is. Then: exit status 130 / 143 within :data:`EXIT_LIMIT_S` of the signal, a
one-line message on stderr and no traceback, no process it started still alive (the process
table, sampled all along by :class:`process_watch.ProcessWatch`) and nothing left in ``TMPDIR``.

The first tests check :mod:`turntable_pin.core.interrupts` in this process, with real signals.
"""

from __future__ import annotations

import importlib.util
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from conftest import cli_env, needs_chromium
from process_watch import ProcessWatch, catches_signal
from turntable_pin.core import interrupts

EXIT_LIMIT_S = 2.0
"""Longest accepted time from the signal to the exit (about 0.1 s measured; room for load)."""
START_TIMEOUT_S = 120.0
"""Longest wait for a command to reach the moment it is interrupted at (start-up is slow)."""

needs_meshcat = pytest.mark.skipif(
    importlib.util.find_spec("meshcat") is None, reason="needs the optional package meshcat"
)
needs_main_thread = pytest.mark.skipif(
    threading.current_thread() is not threading.main_thread(),
    reason="signal handlers can only be installed in the main thread",
)


# --- the mechanism, in this process ------------------------------------------------------------


@pytest.fixture
def handlers():
    """Our SIGINT/SIGTERM handlers for the length of one test, then the previous ones again."""
    restore = interrupts.install_handlers()
    try:
        yield
    finally:
        restore()


def _signal_self(signum: int = signal.SIGTERM) -> None:
    os.kill(os.getpid(), signum)
    time.sleep(0.5)  # the handler runs at the next bytecode; the sleep is interrupted by it


def _interruption(body) -> interrupts.Interrupted | None:
    """Run ``body()``; the :class:`Interrupted` it raised, marked handled at once as ``main()``
    does (until then the signal is sent again), or None."""
    try:
        body()
    except interrupts.Interrupted as exc:
        interrupts.interruption_handled()
        return exc
    return None


@needs_main_thread
def test_a_signal_raises_interrupted_with_its_exit_status(handlers):
    caught = _interruption(lambda: _signal_self(signal.SIGTERM))
    assert isinstance(caught, KeyboardInterrupt)
    assert (caught.signum, caught.exit_status) == (signal.SIGTERM, 143)
    assert str(caught) == "interrupted by SIGTERM"


@needs_main_thread
def test_deferred_block_finishes_then_raises(handlers):
    done = []

    def body():
        with interrupts.deferred():
            _signal_self(signal.SIGINT)
            done.append("rest of the block")

    assert _interruption(body).exit_status == 130
    assert done == ["rest of the block"]


@needs_main_thread
def test_a_second_signal_does_not_cut_the_cleanup_short(handlers):
    cleaned = []

    def body():
        try:
            _signal_self(signal.SIGINT)
        finally:
            _signal_self(signal.SIGTERM)  # Ctrl-C, then kill: the cleanup still runs
            cleaned.append(True)

    assert _interruption(body).exit_status == 130  # the first signal's
    assert cleaned == [True]


@needs_main_thread
def test_a_swallowed_interruption_is_raised_again(handlers):
    def body():
        try:  # what a library may do around an optional import
            _signal_self(signal.SIGINT)
        except BaseException:
            pass
        time.sleep(10 * interrupts.REDELIVERY_S)

    assert _interruption(body) is not None


@needs_main_thread
def test_temporary_folder_and_cleanups_survive_an_interruption(handlers, tmp_path, monkeypatch):
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    monkeypatch.setattr("tempfile.tempdir", None)
    ran, folders = [], []
    unregister = interrupts.register_cleanup(lambda: ran.append("late cleanup"))

    def body():
        with interrupts.temporary_folder("turntable-pin-test-") as folder:
            folders.append(folder)
            (folder / "file").write_text("x")
            _signal_self()

    assert _interruption(body) is not None
    assert folders and list(tmp_path.iterdir()) == []
    interrupts.run_cleanups()  # what main() does for cleanups a signal cut short
    assert ran == ["late cleanup"]
    unregister()


# --- the command line, as a child process ----------------------------------------------------


class Command:
    """A ``turntable-pin`` child process with its output collected line by line as it comes."""

    def __init__(self, args: list[str], tmp_path: Path) -> None:
        self.tmpdir = tmp_path / "tmp"
        self.tmpdir.mkdir()
        env = cli_env({**os.environ, "TMPDIR": str(self.tmpdir)})
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "turntable_pin", *args],
            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
            text=True, env=env, start_new_session=True,
        )  # fmt: skip
        self.stdout: list[str] = []
        self.stderr: list[str] = []
        self._readers = [
            threading.Thread(target=self._read, args=(stream, lines), daemon=True)
            for stream, lines in ((self.proc.stdout, self.stdout), (self.proc.stderr, self.stderr))
        ]
        for reader in self._readers:
            reader.start()
        self.watch = ProcessWatch(parent_pid=self.proc.pid, interval_s=0.01, descendants=True)
        self.watch.__enter__()

    @staticmethod
    def _read(stream, lines: list[str]) -> None:
        for line in stream:
            lines.append(line.rstrip("\n"))

    def wait_until(self, ready, what: str) -> None:
        """Wait until ``ready()`` holds; fail if the command ends or takes too long first."""
        deadline = time.monotonic() + START_TIMEOUT_S
        while not ready():
            if self.proc.poll() is not None:
                raise AssertionError(f"ended before {what}: {self.stderr}")
            if time.monotonic() > deadline:
                raise AssertionError(f"no {what} within {START_TIMEOUT_S:g} s")
            time.sleep(0.005)

    def interrupt(self, signum: int, then: int | None = None) -> float:
        """Send ``signum`` (SIGINT to the process group, as Ctrl-C does; SIGTERM to the process,
        as ``kill`` does), optionally ``then`` a second one; the seconds until it exited."""
        for sig in (signum, then):
            if sig is None:
                continue
            if sig == signal.SIGINT:
                os.killpg(self.proc.pid, sig)
            else:
                os.kill(self.proc.pid, sig)
            if sig == signum:
                start = time.monotonic()
            time.sleep(0.02)
        try:
            self.proc.wait(timeout=START_TIMEOUT_S)
        finally:
            elapsed = time.monotonic() - start
            self.close()
        return elapsed

    def close(self) -> None:
        """Stop watching; kill the command (and what it left) should it still run."""
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()
        self.watch.__exit__(None, None, None)
        for reader in self._readers:
            reader.join(timeout=10)

    def assert_ended_cleanly(self, signum: int, elapsed: float, command: str) -> None:
        """Status 128 + signal in time, one message line and no traceback, nothing left over."""
        name = signal.Signals(signum).name
        assert self.proc.returncode == 128 + signum, self.stderr
        assert elapsed < EXIT_LIMIT_S, f"exit {elapsed:.2f} s after {name}"
        stderr = "\n".join(self.stderr)
        assert "Traceback" not in stderr and "Exception" not in stderr, stderr
        assert re.fullmatch(
            rf"turntable-pin( {command})?: interrupted \({name}\)", self.stderr[-1]
        ), stderr
        time.sleep(0.1)  # a process killed at the very end has surely left the table by now
        assert self.watch.survivors() == [], "processes left running"
        assert sorted(p.name for p in self.tmpdir.iterdir()) == [], "temporary files left"


def _handlers_installed(command: Command):
    return lambda: catches_signal(command.proc.pid, signal.SIGTERM)


SIGNALS = [signal.SIGINT, signal.SIGTERM]
ids = [s.name for s in SIGNALS]


@pytest.mark.parametrize("signum", SIGNALS, ids=ids)
def test_interrupt_during_start_up_is_one_line_not_a_traceback(signum, tmp_path):
    command = Command(["snapshot", "-o", str(tmp_path / "out.png")], tmp_path)
    try:
        command.wait_until(_handlers_installed(command), "signal handlers")
        elapsed = command.interrupt(signum)
    finally:
        command.close()
    command.assert_ended_cleanly(signum, elapsed, "snapshot")
    assert not command.watch.server_pids  # interrupted before it got that far
    assert not (tmp_path / "out.png").exists()


@pytest.mark.slow
@needs_meshcat
@needs_chromium
@pytest.mark.parametrize("moment", ["server", "browser"])
@pytest.mark.parametrize("signum", SIGNALS, ids=ids)
def test_snapshot_interrupted_leaves_no_server_browser_or_folder(signum, moment, tmp_path):
    command = Command(["snapshot", "-o", str(tmp_path / "out.png")], tmp_path)
    watch = command.watch
    try:
        if moment == "server":  # the meshcat server has just been started
            command.wait_until(lambda: watch.server_pids, "meshcat server")
        else:  # Chromium runs with its helpers (zygotes, crash handler)
            command.wait_until(lambda: len(watch.browser_pids) >= 3, "Chromium")
        elapsed = command.interrupt(signum)
    finally:
        command.close()
    command.assert_ended_cleanly(signum, elapsed, "snapshot")
    assert watch.server_pids
    assert not (tmp_path / "out.png").exists()


@pytest.mark.slow
@needs_meshcat
@needs_chromium
def test_snapshot_ctrl_c_then_kill_still_cleans_up(tmp_path):
    command = Command(["snapshot", "-o", str(tmp_path / "out.png")], tmp_path)
    try:
        command.wait_until(lambda: len(command.watch.browser_pids) >= 3, "Chromium")
        elapsed = command.interrupt(signal.SIGINT, then=signal.SIGTERM)
    finally:
        command.close()
    command.assert_ended_cleanly(signal.SIGINT, elapsed, "snapshot")


@pytest.mark.slow
@needs_meshcat
@pytest.mark.parametrize("moment", ["start-up", "serving"])
@pytest.mark.parametrize("signum", SIGNALS, ids=ids)
def test_view_interrupted_stops_its_server(signum, moment, tmp_path):
    command = Command(["view", "--error", "deps_x=4"], tmp_path)
    try:
        if moment == "start-up":
            command.wait_until(_handlers_installed(command), "signal handlers")
        else:
            command.wait_until(lambda: "serving until Ctrl-C" in command.stdout, "serving")
        elapsed = command.interrupt(signum)
    finally:
        command.close()
    command.assert_ended_cleanly(signum, elapsed, "view")
    if moment == "serving":
        assert len(command.watch.server_pids) == 1


@pytest.mark.slow
@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="montecarlo uses one worker per core")
@pytest.mark.parametrize("signum", SIGNALS, ids=ids)
def test_montecarlo_interrupted_stops_its_workers(signum, tmp_path):
    command = Command(["montecarlo", "--workers", "2", "-n", "10000000"], tmp_path)
    watch = command.watch
    try:
        # Two workers exist and the first chunks came back: the workers are computing. (10^7
        # tables, about 25 s on two workers: the signal lands inside the run, not at its end.)
        command.wait_until(
            lambda: (
                len(watch.descendant_pids) >= 2
                and any(line.startswith("Monte Carlo:") for line in command.stderr)
            ),
            "Monte Carlo progress",
        )
        elapsed = command.interrupt(signum)
    finally:
        command.close()
    command.assert_ended_cleanly(signum, elapsed, "montecarlo")
    assert len(watch.descendant_pids) >= 2

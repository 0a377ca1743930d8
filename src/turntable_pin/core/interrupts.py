"""SIGINT and SIGTERM as an exception that unwinds cleanly, and cleanups that always run.

After :func:`install_handlers` both signals raise :class:`Interrupted` (a ``KeyboardInterrupt``
with the signal number), so every ``finally`` on the way out runs; ``main()`` exits with 128 +
signal. Three rules keep the cleanup itself from being cut short:

- a signal arriving while an interruption is already being handled (in an ``except``/``finally``
  or ``__exit__`` run because of a ``KeyboardInterrupt``) is not raised again: the first one is
  already unwinding the program, a second Ctrl-C must not abort its cleanup;
- inside :func:`deferred` a signal is only recorded and raised when the block ends; short
  acquire-and-register steps (make a folder and register its removal) use it;
- cleanups registered with :func:`register_cleanup` (and the folders of
  :func:`temporary_folder`) are undone by their own ``finally``; should a signal cut that
  ``finally`` short, :func:`run_cleanups` (called by ``main()`` on interruption) finishes them.

And the interruption cannot get lost: some libraries swallow ``BaseException`` (trimesh around
its optional imports), so until ``main()`` reports it handled (:func:`interruption_handled`) the
signal is sent again every :data:`REDELIVERY_S` seconds and raised wherever it is not already
being unwound.

Pool workers call :func:`worker_initializer` (ignore SIGINT, die on SIGTERM and with their
parent); a forked child that still has our handler takes the signal's default action.
"""

# ctypes is imported inside worker_initializer: only pool workers need it
from __future__ import annotations

import contextlib
import os
import shutil
import signal
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

__all__ = [
    "REDELIVERY_S",
    "SIGNALS",
    "Interrupted",
    "deferred",
    "exit_on_signal",
    "first_signal",
    "install_handlers",
    "interruption_handled",
    "register_cleanup",
    "run_cleanups",
    "signal_name",
    "signals_blocked",
    "temporary_folder",
    "worker_initializer",
]

SIGNALS: tuple[int, ...] = (signal.SIGINT, signal.SIGTERM)
"""The signals that end a command: Ctrl-C and a plain ``kill``."""


class Interrupted(KeyboardInterrupt):
    """The program got SIGINT or SIGTERM; ``exit_status`` is 128 + the signal number."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = int(signum)

    @property
    def signal_name(self) -> str:
        """``SIGINT``, ``SIGTERM``, ..."""
        return signal_name(self.signum)

    @property
    def exit_status(self) -> int:
        """The shell's convention for a program ended by a signal: 128 + its number."""
        return 128 + self.signum

    def __str__(self) -> str:
        return f"interrupted by {self.signal_name}"


def signal_name(signum: int) -> str:
    """The name of a signal number (``SIGINT``), or ``signal N``."""
    try:
        return signal.Signals(signum).name
    except ValueError:
        return f"signal {signum}"


REDELIVERY_S = 0.1
"""Period at which an interruption not yet handled by ``main()`` is raised again (a library that
swallows ``BaseException``, e.g. around an optional import, must not make a signal go unheard)."""


class _State:
    owner_pid: int | None = None  # the process whose handlers these are
    first: int | None = None  # first signal received since install_handlers()
    handled = True  # the interruption reached main() (or the handlers are gone): no redelivery
    depth = 0  # nesting of deferred() blocks (main thread only)
    pending: int | None = None  # signal received inside deferred(), raised at its end
    cleanups: dict[int, Callable[[], object]] = {}
    next_token = 0


def _handle(signum: int, frame) -> None:
    if os.getpid() != _State.owner_pid:
        # A forked child (a pool worker before its initializer) must not raise the parent's
        # exception: it takes the signal's default action, i.e. it ends.
        signal.signal(signum, signal.SIG_DFL)
        os.kill(os.getpid(), signum)
        return
    if _State.first is None:
        _State.first = signum
        _State.handled = False
        threading.Thread(target=_redeliver, args=(signum,), daemon=True).start()
    if _State.handled:
        return
    if _State.depth > 0:
        _State.pending = _State.pending or signum
        return
    if isinstance(sys.exc_info()[1], KeyboardInterrupt):
        return  # already unwinding from an interruption: let its cleanup finish
    raise Interrupted(_State.first)


def _redeliver(signum: int) -> None:
    """Send ``signum`` to this process again every REDELIVERY_S until ``main()`` handled it: an
    interruption swallowed by some ``except BaseException`` is raised again (one being unwound
    is left alone by :func:`_handle`)."""
    pid = os.getpid()
    while True:
        time.sleep(REDELIVERY_S)
        if _State.handled or _State.owner_pid != pid:
            return
        os.kill(pid, signum)


def interruption_handled() -> None:
    """Say that the interruption reached its handler (``main()``): stop raising it again, and
    ignore further signals while the program ends."""
    _State.handled = True


def install_handlers() -> Callable[[], None]:
    """Make SIGINT and SIGTERM raise :class:`Interrupted`; returns a function restoring the
    previous handlers. Does nothing (and restores nothing) outside the main thread."""
    if threading.current_thread() is not threading.main_thread():
        return lambda: None
    previous = {signum: signal.getsignal(signum) for signum in SIGNALS}
    if _State.owner_pid != os.getpid() or any(h is not _handle for h in previous.values()):
        _State.first = None  # a fresh start; installing them again keeps what was received
        _State.pending = None
        _State.handled = True
    _State.owner_pid = os.getpid()
    for signum in SIGNALS:
        signal.signal(signum, _handle)

    def restore() -> None:
        _State.handled = True
        for signum, handler in previous.items():
            signal.signal(signum, handler if handler is not None else signal.SIG_DFL)

    return restore


def exit_on_signal(name: str) -> None:
    """For the last moments of a process whose cleanup is done: SIGINT/SIGTERM print
    ``NAME: interrupted (SIGINT)`` on stderr and end the process at once, status 128 + signal."""
    _State.handled = True

    def end(signum: int, frame) -> None:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError, RuntimeError):
                pass
        try:
            os.write(2, f"{name}: interrupted ({signal_name(signum)})\n".encode())
        except OSError:
            pass
        os._exit(128 + signum)

    if threading.current_thread() is threading.main_thread():
        for signum in SIGNALS:
            signal.signal(signum, end)


def first_signal() -> int | None:
    """The first SIGINT/SIGTERM received since :func:`install_handlers`, if any."""
    return _State.first


class _Deferred:
    """Context manager of :func:`deferred`."""

    def __enter__(self) -> None:
        self._active = threading.current_thread() is threading.main_thread()
        if self._active:
            _State.depth += 1

    def __exit__(self, exc_type, exc, traceback) -> bool:
        if not self._active:
            return False
        _State.depth -= 1
        if _State.depth or _State.pending is None:
            return False
        signum, _State.pending = _State.pending, None
        if _State.handled or (exc_type is not None and issubclass(exc_type, KeyboardInterrupt)):
            return False  # already handled, or being unwound
        raise Interrupted(_State.first or signum)


def deferred() -> contextlib.AbstractContextManager:
    """A block that SIGINT/SIGTERM do not cut: a signal arriving inside is raised at its end.

    For short steps only (acquire a resource and register its cleanup, kill and reap a process):
    the program does not answer the signal until the block ends.
    """
    return _Deferred()


def register_cleanup(cleanup: Callable[[], object]) -> Callable[[], None]:
    """Register ``cleanup`` to be run by :func:`run_cleanups`; returns the function that
    unregisters it. ``cleanup`` must be idempotent: its owner normally runs it too."""
    with deferred():
        token = _State.next_token
        _State.next_token += 1
        _State.cleanups[token] = cleanup

    def unregister() -> None:
        _State.cleanups.pop(token, None)

    return unregister


def run_cleanups() -> None:
    """Run (latest first) and forget every registered cleanup still pending; errors are ignored.

    ``main()`` calls this on interruption, for what a signal kept a ``finally`` from finishing.
    """
    with deferred():
        while _State.cleanups:
            token = max(_State.cleanups)
            cleanup = _State.cleanups.pop(token)
            try:
                cleanup()
            except Exception:  # a failing cleanup must not keep the others from running
                pass


@contextlib.contextmanager
def temporary_folder(prefix: str) -> Iterator[Path]:
    """A fresh folder in the system's temporary folder, removed on leaving the block, also when
    the block is interrupted (then by :func:`run_cleanups` at the latest)."""
    with deferred():
        path = Path(tempfile.mkdtemp(prefix=prefix))
        unregister = register_cleanup(lambda: shutil.rmtree(path, ignore_errors=True))
    try:
        yield path
    finally:
        with deferred():
            shutil.rmtree(path, ignore_errors=True)
            unregister()


@contextlib.contextmanager
def signals_blocked() -> Iterator[None]:
    """SIGINT and SIGTERM blocked for the calling thread (and inherited by the processes and
    threads it starts) for the length of the block; a signal that arrives meanwhile is
    delivered at its end. Use it around starting pool workers, with :func:`deferred`."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, SIGNALS)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def worker_initializer() -> None:
    """Signal set-up of a pool worker: ignore SIGINT (Ctrl-C reaches the whole process group;
    the parent handles it and stops the pool), end on SIGTERM, end when the parent dies
    (Linux), then unblock what :func:`signals_blocked` blocked while the worker started."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if sys.platform.startswith("linux"):
        with contextlib.suppress(Exception):
            import ctypes

            pr_set_pdeathsig = 1
            ctypes.CDLL(None, use_errno=True).prctl(pr_set_pdeathsig, int(signal.SIGTERM))
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, SIGNALS)

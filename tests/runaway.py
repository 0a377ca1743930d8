"""Test support: a time limit on a block, so that a runaway (a quadratic step, a walk through
nested aliases, a search over 2**63 positions) fails its test instead of hanging the run."""

from __future__ import annotations

import contextlib
import signal


class StillRunning(Exception):
    """A block ran past its time (not an OSError, which a reader might catch and go on)."""


@contextlib.contextmanager
def time_limit(seconds: float):
    """Raise :class:`StillRunning` in the block after ``seconds`` (SIGALRM: main thread only)."""

    def on_alarm(signum, frame):
        raise StillRunning(f"still running after {seconds} s")

    previous = signal.signal(signal.SIGALRM, on_alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)

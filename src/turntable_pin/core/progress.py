"""A minimal progress reporter for long work (Monte Carlo, sweeps), written to stderr.

It draws a one-line bar when stderr is a terminal and otherwise prints a line at every 10 %, so
logs of batch runs show progress too. ``enabled=False`` silences it; ``delay_s`` keeps it silent
until the work has run that long (a run that ends sooner prints nothing).
"""

from __future__ import annotations

import sys
import time

__all__ = ["Progress"]


class Progress:
    """Report progress of ``total`` units of work.

    Use as a context manager and call :meth:`update` with the units done since the last call.
    """

    def __init__(
        self,
        total: int,
        description: str,
        *,
        enabled: bool = True,
        stream=None,
        delay_s: float = 0.0,
    ) -> None:
        self.total = max(int(total), 1)
        self.description = description
        self.enabled = enabled
        self.delay_s = float(delay_s)
        self._drawn = False
        self.stream = stream if stream is not None else sys.stderr
        self.done = 0
        self._last_decile = -1
        self._start = time.perf_counter()
        self._tty = bool(getattr(self.stream, "isatty", lambda: False)())

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        if self.enabled and self._tty and self._drawn:
            self.stream.write("\n")
            self.stream.flush()

    def update(self, units: int = 1) -> None:
        """Count ``units`` more units as done and redraw when worthwhile."""
        self.done = min(self.done + int(units), self.total)
        if not self.enabled:
            return
        fraction = self.done / self.total
        elapsed = time.perf_counter() - self._start
        if elapsed < self.delay_s:
            return
        self._drawn = True
        if self._tty:
            width = 30
            filled = int(round(width * fraction))
            bar = "#" * filled + "-" * (width - filled)
            self.stream.write(
                f"\r{self.description} [{bar}] {100 * fraction:5.1f}% "
                f"{self.done}/{self.total} {elapsed:6.1f} s"
            )
            self.stream.flush()
            return
        decile = int(10 * fraction)
        if decile > self._last_decile:
            self._last_decile = decile
            self.stream.write(
                f"{self.description}: {100 * fraction:3.0f}% ({self.done}/{self.total}, "
                f"{elapsed:.1f} s)\n"
            )
            self.stream.flush()

"""Test support: watch which helper processes a call starts, to check none outlives it (by pid).

A thread samples /proc while the call runs and records (a) meshcat servers and (b) headless
Chromium processes started on behalf of this test process: a Chromium launcher that is a child
of this process names its throw-away folder on its command line, and every Chromium process of
that run (renderers, GPU, crash handler) names the same folder. With ``descendants=True`` it also
records every process the parent started, directly or not (pool workers, say).
"""

from __future__ import annotations

import os
import re
import threading
import time
from pathlib import Path

from turntable_pin.viewer.browser import descendant_processes, process_table

_RUN_DIR = re.compile(r"--user-data-dir=(/\S*turntable-pin-chromium-[^/\s]+)/profile")


def alive(pid: int) -> bool:
    """Whether ``pid`` is a running (not zombie) process."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat[stat.rfind(")") + 2 :].split()[0] not in ("Z", "X")


class ProcessWatch:
    """Context manager collecting ``server_pids`` and ``browser_pids`` seen while it is open."""

    def __init__(
        self, parent_pid: int | None = None, interval_s: float = 0.02, descendants: bool = False
    ) -> None:
        self.parent_pid = parent_pid or os.getpid()
        self.interval_s = interval_s
        self.descendants = descendants
        self.server_pids: set[int] = set()
        self.browser_pids: set[int] = set()
        self.descendant_pids: set[int] = set()
        self._run_dirs: set[str] = set()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, daemon=True)

    def _sample(self) -> None:
        table = process_table()
        for p in table:
            if p.ppid == self.parent_pid and "meshcat.servers.zmqserver" in p.cmdline:
                self.server_pids.add(p.pid)
            match = _RUN_DIR.search(p.cmdline)
            if p.ppid == self.parent_pid and match:
                self._run_dirs.add(match.group(1))
        for p in table:
            if any(run_dir in p.cmdline for run_dir in self._run_dirs):
                self.browser_pids.add(p.pid)
        if self.descendants:
            self.descendant_pids.update(descendant_processes(self.parent_pid))

    def _loop(self) -> None:
        while not self._stop.is_set():
            self._sample()
            time.sleep(self.interval_s)

    def __enter__(self) -> ProcessWatch:
        self._thread.start()
        return self

    def __exit__(self, *exc_info) -> None:
        self._stop.set()
        self._thread.join()

    def survivors(self) -> list[int]:
        """Recorded pids still running."""
        seen = self.server_pids | self.browser_pids | self.descendant_pids
        return sorted(pid for pid in seen if alive(pid))


def catches_signal(pid: int, signum: int) -> bool:
    """Whether process ``pid`` has a handler installed for ``signum`` (``SigCgt`` of its status)."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    for line in status.splitlines():
        if line.startswith("SigCgt:"):
            return bool(int(line.split()[1], 16) >> (signum - 1) & 1)
    return False

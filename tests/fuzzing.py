"""The rules every fuzz test judges a command by, once: run ``turntable-pin ARGS`` in this process
and assert it ended with exit status 0 (or 1 for a Monte Carlo run over a limit), or with status
2 and exactly one line on stderr naming the place (the file or the option); never a traceback,
never a warning, never an input file changed, never a file left behind (nor one written by a
command that failed). Used by ``test_fuzz_inputs.py`` and ``test_fuzz_effects.py``."""

from __future__ import annotations

import shutil
import tempfile
import warnings
from pathlib import Path

from hypothesis import HealthCheck, settings

from conftest import cli


def fuzz(examples: int):
    """Hypothesis settings of these tests: ``examples`` inputs, no deadline, no database."""
    return settings(
        max_examples=examples,
        deadline=None,
        database=None,  # nothing written into the checkout (.hypothesis/)
        suppress_health_check=[HealthCheck.too_slow],
    )


def _snapshot(folder: Path) -> dict[str, tuple[bytes, int]]:
    return {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in folder.iterdir()}


def run_and_check(
    folder: Path,
    args: list[str],
    place: str,
    *,
    outputs: tuple[str, ...] = (),
    statuses: tuple[int, ...] | None = None,
):
    """Run ``turntable-pin ARGS`` in-process and assert the rules of the module docstring.

    ``place`` is what a refusal must name (a file name or an option); ``outputs`` are the names
    of files the command may create in ``folder``; ``statuses`` the exit statuses allowed (default
    0 and 2, and 1 for ``montecarlo``).
    """
    before = _snapshot(folder)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        proc = cli(*args)
    after = _snapshot(folder)
    for name, content in before.items():
        assert after.get(name) == content, f"input {name} changed by {args}"
    left = set(after) - set(before) - set(outputs)
    assert not left, f"{args} left {sorted(left)} behind"
    assert "Traceback" not in proc.stderr, proc.stderr
    assert not caught, f"{args}: warnings {[str(w.message) for w in caught]}"
    if statuses is None:
        statuses = (0, 1, 2) if args[0] == "montecarlo" else (0, 2)
    assert proc.returncode in statuses, (args, proc.returncode, proc.stderr)
    if proc.returncode == 2:
        lines = proc.stderr.splitlines()
        assert len(lines) == 1, f"{args}: expected one stderr line, got {proc.stderr!r}"
        assert place in lines[0], f"{args}: the message does not name {place!r}: {lines[0]!r}"
        for name in outputs:
            assert name not in after or name in before, f"{args} wrote {name} and failed"
    return proc


def scratch_folder():
    """A folder for the examples of a module (each example gets a subfolder of it); removed at
    the end. The body of each fuzz module's ``scratch`` fixture."""
    folder = Path(tempfile.mkdtemp(prefix="fuzz-"))
    yield folder
    shutil.rmtree(folder, ignore_errors=True)


def example_folder(scratch: Path) -> Path:
    """A new folder for one example, inside ``scratch``."""
    return Path(tempfile.mkdtemp(dir=scratch))

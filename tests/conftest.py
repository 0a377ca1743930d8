"""Shared test helpers: seeded random error sets, the CLI runners (child process and in-process)
and the skip of browser tests without Chromium."""

from __future__ import annotations

import contextlib
import io
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from turntable_pin import TurntableErrors
from turntable_pin.core.units import arcsec_to_rad


def random_errors(rng: np.random.Generator, scale_arcsec: float = 10.0) -> TurntableErrors:
    """Eight angular errors uniform in +-scale_arcsec and deta uniform in +-0.5 mm."""
    angles = arcsec_to_rad(rng.uniform(-scale_arcsec, scale_arcsec, 8))
    return TurntableErrors.from_array(np.append(angles, rng.uniform(-5e-4, 5e-4)))


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261122)


# --- command-line runners and the browser skip, shared by every test module -----------------------
SRC_DIR = Path(__file__).resolve().parents[1] / "src"


def cli_env(extra: dict | None = None) -> dict:
    """The environment for a child ``python -m turntable_pin``: this checkout's ``src`` first."""
    env = dict(os.environ if extra is None else extra)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC_DIR), env.get("PYTHONPATH")]))
    return env


def run_cli(
    *args: str, env: dict | None = None, timeout: float = 120
) -> subprocess.CompletedProcess:
    """Run ``turntable-pin ARGS`` in a child process (for what needs the process boundary)."""
    return subprocess.run(
        [sys.executable, "-m", "turntable_pin", *args],
        capture_output=True, text=True, timeout=timeout, env=cli_env(env),
    )  # fmt: skip


def cli(*args: str) -> subprocess.CompletedProcess:
    """Run ``turntable-pin ARGS`` in this process; same result object as :func:`run_cli`.

    For error paths and options, where a child process only adds a second of start-up.
    """
    from turntable_pin.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(list(args))
        except SystemExit as exc:  # argparse usage errors
            code = exc.code if isinstance(exc.code, int) else 2
    return subprocess.CompletedProcess(
        ["turntable-pin", *args], code, out.getvalue(), err.getvalue()
    )


def _chromium_available() -> bool:
    from turntable_pin.viewer.browser import chromium_available

    return chromium_available()


def needs_chromium(test):
    """Mark a test as a browser test that skips, saying why, without headless Chromium."""
    skip = pytest.mark.skipif(
        not _chromium_available(),
        reason="headless Chromium not found: install the Debian package 'chromium'",
    )
    return pytest.mark.browser(skip(test))

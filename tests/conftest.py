"""Shared test helpers: seeded random error sets, the paper's errors on the generic parameters,
the repository's paths, a file writer (and a bundled run with its temperature cells changed), the
CLI runners (child process and in-process), the transforms a meshcat scene sets, and the skip of
browser tests without Chromium.

The test folders mirror the package's subpackages (tests/core, tests/model, ...) and hold no
``__init__.py``: with pytest's default import mode every test module is imported by its basename,
so basenames are unique across folders. ``tests`` is on ``pythonpath`` (pyproject.toml), so the
modules here (``from conftest import ...``, ``spec_reference``, ``process_watch``) import from any
folder.
"""

from __future__ import annotations

import base64
import contextlib
import io
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

from turntable_pin import TurntableErrors
from turntable_pin.core.units import arcsec_to_rad

# Property tests draw the same examples on every run (the README's test command and CI must not
# pass or fail by the luck of the draw); HYPOTHESIS_PROFILE=explore draws new ones each run, to
# look for inputs nobody tried yet.
settings.register_profile("repeatable", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False, database=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))


def random_errors(rng: np.random.Generator, scale_arcsec: float = 10.0) -> TurntableErrors:
    """Eight angular errors uniform in +-scale_arcsec and deta uniform in +-0.5 mm."""
    angles = arcsec_to_rad(rng.uniform(-scale_arcsec, scale_arcsec, 8))
    return TurntableErrors.from_array(np.append(angles, rng.uniform(-5e-4, 5e-4)))


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261122)


PAPER_TO_GENERIC: dict[str, str] = {
    "dphi_y1": "outer_axis.position",
    "dalpha_z1": "inner_axis.position",
    "dalpha_x1": "inner_axis.tilt_a",
    "deps_x": "inner_axis.tilt_a",
    "deps_y": "inner_axis.tilt_b",
    "dalpha_y2": "payload_mount.rot_y",
    "dphi_z2": "payload_mount.rot_z",
    "dalpha_x2": "payload_mount.rot_x",
}
"""The paper's eight angular errors as parameters of the generic model of its URDF."""


# --- the repository's paths and a file writer ---------------------------------------------------
REPO_DIR = Path(__file__).resolve().parents[1]
SRC_DIR = REPO_DIR / "src"
EXAMPLES_DIR = REPO_DIR / "models" / "examples"
VIZ_DIR = REPO_DIR / "viz"


def write_file(folder: Path, text: str, name: str = "data.csv") -> Path:
    """Write ``text`` to ``folder/name`` and return the path."""
    path = folder / name
    path.write_text(text)
    return path


def temperature_run(folder, cell=lambda row, text: text, note=None):
    """``run_temperature.csv`` with each ``temperature_c`` cell replaced by ``cell(row, text)``
    (spreadsheet row of the file) and, when given, a ``note`` column of ``note``."""
    lines = (EXAMPLES_DIR / "runs" / "run_temperature.csv").read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    column = lines[header].split(",").index("temperature_c")
    out = lines[: header + 1]
    if note is not None:
        out[header] += ",note"
    for row, line in enumerate(lines[header + 1 :], start=header + 2):
        cells = line.split(",")
        cells[column] = cell(row, cells[column])
        out.append(",".join(cells) + ("" if note is None else f",{note}"))
    return write_file(folder, "\n".join(out) + "\n", "run.csv")


# --- command-line runners and the browser skip, shared by every test module -----------------------
def cli_env(extra: dict | None = None) -> dict:
    """The environment for a child ``python -m turntable_pin``: this checkout's ``src`` first."""
    env = dict(os.environ if extra is None else extra)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC_DIR), env.get("PYTHONPATH")]))
    return env


def run_cli(
    *args: str, env: dict | None = None, timeout: float = 120
) -> subprocess.CompletedProcess:
    """Run ``python -m turntable_pin ARGS`` in a child process.

    Only for what needs the process boundary: the module entry point itself, signals, start-up
    imports, and checks that no process or temporary folder outlives the command.
    """
    return subprocess.run(
        [sys.executable, "-m", "turntable_pin", *args],
        capture_output=True, text=True, timeout=timeout, env=cli_env(env),
    )  # fmt: skip


def run_python(code: str) -> str:
    """What ``python -c CODE`` prints in a child process on this checkout's ``src`` (it must
    succeed): for what needs a fresh interpreter, such as the modules an import loads."""
    return subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=cli_env(), check=True
    ).stdout


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


# --- figures -------------------------------------------------------------------------------------
REPORT_FIGURE_MODULES = (
    "allocation_figures",
    "design_figures",
    "html_report",
    "measurement_figures",
    "requirement_figures",
    "separation_figures",
)
"""The report modules that save figures (each through its own name of ``figures.save_png``)."""


def refused(proc: subprocess.CompletedProcess, *words: str) -> str:
    """Assert a command ended with exit status 2 and one line on stderr, no traceback, holding
    every one of ``words``; the line."""
    assert proc.returncode == 2, (proc.returncode, proc.stdout[-300:], proc.stderr[-2000:])
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert all(w in lines[0] for w in words), lines[0]
    return lines[0]


@pytest.fixture
def drawn_figures(monkeypatch) -> list:
    """Every matplotlib figure the report modules save while this fixture is active, in order
    (closed by the saver, still readable: axes, texts, legends)."""
    import importlib

    from turntable_pin.report import figures

    drawn, save = [], figures.save_png

    def recording(fig, path=None, **kw):
        drawn.append(fig)
        return save(fig, path, **kw)

    for name in REPORT_FIGURE_MODULES:
        module = importlib.import_module(f"turntable_pin.report.{name}")
        monkeypatch.setattr(module, "save_png", recording)
    return drawn


def figure_texts(fig) -> tuple[str, list[str]]:
    """All the words on ``fig`` joined (titles, labels, notes, legends) and its legend labels."""
    from matplotlib.text import Text

    words = "\n".join(t.get_text() for t in fig.findobj(Text) if t.get_text())
    legends = [t.get_text() for ax in fig.axes if ax.get_legend()
               for t in ax.get_legend().get_texts()]  # fmt: skip
    return words, legends


# --- meshcat --------------------------------------------------------------------------------------
def meshcat_transforms(scene, *angles_rad: float) -> tuple[dict[str, np.ndarray], int]:
    """Draw ``scene`` at ``angles_rad`` into a short-lived meshcat server: the 4x4 transforms its
    static page sets, by path, and the (stopped) server's pid. Skips without meshcat/umsgpack."""
    pytest.importorskip("meshcat")
    from turntable_pin.viewer.meshcat_server import MeshcatServer

    with MeshcatServer() as server:
        scene.draw(server.visualizer)
        scene.set_position(*angles_rad)
        page = server.visualizer.static_html()
        pid = server.pid
    umsgpack = pytest.importorskip("umsgpack")
    blobs = re.findall(r"base64,([A-Za-z0-9+/=]+)\"", page)
    commands = [umsgpack.unpackb(base64.b64decode(blob)) for blob in blobs]
    return {
        c["path"]: np.array(c["matrix"], dtype=float).reshape(4, 4).T
        for c in commands
        if c["type"] == "set_transform"
    }, pid


def assert_triads_at(transforms: dict[str, np.ndarray], poses) -> str:
    """The actual and ideal payload triads stand where ``poses`` puts them; returns the scene's
    meshcat path prefix."""
    from turntable_pin.viewer.scene import ROOT

    prefix = f"/meshcat/{ROOT}"
    np.testing.assert_allclose(
        transforms[f"{prefix}/actual_triad"], poses.actual_payload, atol=1e-7
    )
    np.testing.assert_allclose(transforms[f"{prefix}/ideal_triad"], poses.ideal_payload, atol=1e-7)
    return prefix


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

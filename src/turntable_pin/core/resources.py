"""Where the bundled files are: the models folder and the files in it.

``$TURNTABLE_PIN_MODELS`` if set; else the repository's ``models/`` (a source checkout or an
editable install); else the package data ``turntable_pin/models`` of an installed wheel (read
with ``importlib.resources``; ``setup.py`` maps the repository's ``models/`` there).
"""

from __future__ import annotations

import os
from importlib import resources
from pathlib import Path

__all__ = [
    "BUNDLED_TABLES",
    "bundled_path",
    "default_gyrowheel_path",
    "default_urdf_path",
    "examples_dir",
    "models_dir",
]

BUNDLED_TABLES: tuple[str, ...] = (
    "turntable",
    "altaz_mount",
    "german_equatorial_mount",
    "two_axis_vertical_outer",
    "three_axis_imu_table",
    "single_axis_rate_table",
)
"""The bundled tables by name (``models/<name>.urdf``; ``turntable`` is the paper's)."""


def models_dir() -> Path:
    """The folder of bundled models (see the module docstring for the search order)."""
    env = os.environ.get("TURNTABLE_PIN_MODELS")
    if env:
        return Path(env)
    checkout = Path(__file__).resolve().parents[3] / "models"
    if checkout.is_dir() and (checkout / "turntable.urdf").is_file():
        return checkout
    return Path(str(resources.files("turntable_pin") / "models"))


def examples_dir() -> Path:
    """The bundled example inputs, ``models/examples``."""
    return models_dir() / "examples"


def default_urdf_path() -> Path:
    """The bundled nominal turntable of the paper, ``models/turntable.urdf``."""
    return models_dir() / "turntable.urdf"


def default_gyrowheel_path() -> Path:
    """Paper Table 1 drift coefficients, ``models/gyrowheel_nominal.yaml``."""
    return models_dir() / "gyrowheel_nominal.yaml"


def bundled_path(value: str | Path) -> Path:
    """A file a command or function reads: the path as given when something is there, else the
    bundled file of that name (``altaz_mount``, ``measurements_example.csv``,
    ``mmt_pointing/k_and_e.dat``, ``models/...``), so an installed package runs its examples
    from any folder; else the path as given (the reader then says it is missing)."""
    path = Path(value)
    if path.exists():
        return path
    root = models_dir()
    parts = path.parts
    name = Path(*parts[1:]) if len(parts) > 1 and parts[0] == "models" else path
    candidates = [root / name, root / "examples" / name]
    if not name.suffix:
        candidates.append(root / name.with_suffix(".urdf"))
    return next((c for c in candidates if c.is_file()), path)

"""Orientation measurements: the CSV of ``docs/measurements.md``, read and validated.

Required columns ``phi1_deg, phi2_deg, dpsi_arcsec, dtheta_arcsec, dgamma_arcsec``; optional
``sigma_arcsec``, ``time_s``, ``dir1``, ``dir2``; other columns are ignored. Beyond the shared
reader's checks (missing columns, non-numbers, NaN), a file is refused, naming row and column, when:

- a value is outside its valid range: ``|phi1_deg|``, ``|phi2_deg|`` above
  :data:`MAX_COMMANDED_ANGLE_DEG`; ``|dpsi|, |dtheta|, |dgamma|`` above
  :data:`MAX_MEASURED_ANGLE_ARCSEC` (the small-error limit); a ``sigma_arcsec`` <= 0, below
  :data:`MIN_SIGMA_ARCSEC` or above the small-error limit; a ``time_s`` negative or above
  :data:`MAX_TIME_S`; a ``dir1``/``dir2`` not +1 or -1;
- two rows are the same measurement: equal ``phi1_deg, phi2_deg`` and equal values of every
  present ``dir1, dir2, time_s`` column. Repeats of a position are legitimate when they differ in
  time or approach direction; a file without ``time_s`` that repeats a position with the same
  directions holds a copied row (angles are compared as written, so 0 and 360 differ);
- an angle column looks like radians: every value is within +-2 pi, some are not whole numbers,
  and either (a) all of them, read as radians, are whole degrees (e.g. 0.5235987756 = 30 deg:
  a degree schedule written in radians), or (b) they span more than pi and none is a multiple of
  0.25 deg besides 0 (irregular values spread over a radian-sized range). A small-angle data set
  in degrees (say -3, -1.5, 0, 1.5, 3) passes: its values are quarter-degree multiples.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..calibration.positions import MAX_COMMANDED_ANGLE_DEG, check_commanded_angles
from ..core.csv_table import read_csv_table, refuse_repeated_rows
from ..core.exceptions import InputError
from ..core.units import ARCSEC_PER_RAD, DEG_PER_RAD
from ..model.angles import ANGLE_NAMES
from ..model.errors import MAX_ANGULAR_ERROR_DEG
from .effects.base import PositionVariables

__all__ = [
    "ANGLE_NAMES",
    "MAX_COMMANDED_ANGLE_DEG",
    "MAX_MEASURED_ANGLE_ARCSEC",
    "MAX_TIME_S",
    "MIN_SIGMA_ARCSEC",
    "OPTIONAL_COLUMNS",
    "REQUIRED_COLUMNS",
    "OrientationMeasurements",
    "read_measurements",
]

REQUIRED_COLUMNS = ("phi1_deg", "phi2_deg", "dpsi_arcsec", "dtheta_arcsec", "dgamma_arcsec")
"""Columns every measurement CSV must have (angles in degrees, errors in arcsec)."""
OPTIONAL_COLUMNS = ("sigma_arcsec", "time_s", "dir1", "dir2")
"""Columns read when present: 1-sigma noise (arcsec), time (s), approach directions (+1/-1)."""

MAX_MEASURED_ANGLE_ARCSEC = MAX_ANGULAR_ERROR_DEG * 3600.0
"""Largest ``|dpsi|, |dtheta|, |dgamma|`` and ``sigma_arcsec`` of a row, arc seconds (5 deg):
the model's small-error limit (:data:`~turntable_pin.model.errors.MAX_ANGULAR_ERROR_DEG`)."""
MIN_SIGMA_ARCSEC = 1e-9
"""Smallest ``sigma_arcsec``, arc seconds: five femtoradians, the rounding of a double-precision
angle; a smaller sigma is no noise level, and its weight 1/sigma^2 would overflow the fit."""
MAX_TIME_S = 366 * 86400.0
"""Largest ``time_s``, seconds (a year): a longer run is a unit mix-up (ms written as s)."""


@dataclass(frozen=True)
class OrientationMeasurements:
    """Measured orientation errors at N positions (radians and seconds inside).

    Attributes:
        phi1_rad, phi2_rad: commanded angles (N,).
        angles_rad: measured ``dpsi, dtheta, dgamma`` (N, 3).
        sigma_rad: 1-sigma noise per row (N,), or ``None`` (to be estimated from the fit).
        time_s, dir1, dir2: optional columns (N,) or ``None``.
        rows: spreadsheet row of each position in the file (N,) (2 = first data row).
        source: the file read, or a description.
    """

    phi1_rad: np.ndarray
    phi2_rad: np.ndarray
    angles_rad: np.ndarray
    sigma_rad: np.ndarray | None = None
    time_s: np.ndarray | None = None
    dir1: np.ndarray | None = None
    dir2: np.ndarray | None = None
    rows: np.ndarray | None = None
    source: str = ""

    def __post_init__(self) -> None:
        n = np.asarray(self.phi1_rad).size
        for name in ("phi1_rad", "phi2_rad", "sigma_rad", "time_s", "dir1", "dir2", "rows"):
            value = getattr(self, name)
            if value is not None:
                value = np.array(value, dtype=int if name == "rows" else float).reshape(-1)
                if value.size != n:
                    raise InputError(f"{name} has {value.size} values, expected {n}")
                value.setflags(write=False)
                object.__setattr__(self, name, value)
        angles = np.array(self.angles_rad, dtype=float).reshape(n, 3)
        angles.setflags(write=False)
        object.__setattr__(self, "angles_rad", angles)
        if self.rows is None:
            rows = np.arange(2, n + 2)
            rows.setflags(write=False)
            object.__setattr__(self, "rows", rows)

    @property
    def n_positions(self) -> int:
        """Number of positions N."""
        return int(self.phi1_rad.size)

    @property
    def has_sigma(self) -> bool:
        """Whether the data give a 1-sigma noise per row."""
        return self.sigma_rad is not None

    def variables(self) -> PositionVariables:
        """What effects may depend on at each position."""
        return PositionVariables(self.phi1_rad, self.phi2_rad, self.time_s, self.dir1, self.dir2)

    def columns(self) -> dict[str, np.ndarray]:
        """The CSV columns of ``docs/measurements.md`` in user units (degrees, arcsec, s)."""
        out = {
            # Rounded to 1e-9 deg so that a 30-degree grid is written as 30.0, not 29.999999...
            "phi1_deg": np.round(self.phi1_rad * DEG_PER_RAD, 9),
            "phi2_deg": np.round(self.phi2_rad * DEG_PER_RAD, 9),
        }
        for i, name in enumerate(ANGLE_NAMES):
            out[f"{name}_arcsec"] = self.angles_rad[:, i] * ARCSEC_PER_RAD
        if self.sigma_rad is not None:
            out["sigma_arcsec"] = self.sigma_rad * ARCSEC_PER_RAD
        if self.time_s is not None:
            out["time_s"] = self.time_s
        for name in ("dir1", "dir2"):
            value = getattr(self, name)
            if value is not None:
                out[name] = value.astype(int)
        return out

    def without_sigma(self) -> OrientationMeasurements:
        """The same data with the noise level left to be estimated from the fit."""
        return OrientationMeasurements(
            self.phi1_rad, self.phi2_rad, self.angles_rad, None, self.time_s, self.dir1,
            self.dir2, self.rows, self.source,
        )  # fmt: skip


def _looks_like_radians(values_deg: np.ndarray) -> str | None:
    """Why an angle column in degrees looks like radians, or ``None`` (rule: module docstring)."""
    v = np.asarray(values_deg, dtype=float)
    if v.size < 3 or np.any(np.abs(v) > 2 * np.pi + 1e-9):
        return None
    non_integer = np.abs(v - np.round(v)) > 1e-9
    if not non_integer.any():
        return None
    as_deg = v * DEG_PER_RAD
    nonzero = np.abs(v) > 1e-12
    if nonzero.sum() >= 2 and np.all(np.abs(as_deg - np.round(as_deg)) < 1e-4):
        return "every value is a whole number of degrees when read as radians"
    quarter = np.abs(v * 4 - np.round(v * 4)) < 1e-9
    if np.ptp(v) > np.pi and not np.any(quarter & nonzero):
        return "the values lie within +-2 pi, span more than pi and none is a round degree value"
    return None


def _check_at_most(table, column: str, limit: float, rule: str) -> None:
    """Refuse the first ``|value| > limit`` of ``column``, naming file, row and column."""
    table.refuse(column, np.abs(table[column]) > limit, rule)


def read_measurements(path: str | Path) -> OrientationMeasurements:
    """Read and validate an orientation measurement CSV (see the module docstring).

    Raises:
        InputError: naming file, row and column of the first problem found.
    """
    table = read_csv_table(path, REQUIRED_COLUMNS, OPTIONAL_COLUMNS, min_rows=1)
    rows = table.rows
    check_commanded_angles(table)
    limit = MAX_MEASURED_ANGLE_ARCSEC
    for column in (f"{n}_arcsec" for n in ANGLE_NAMES):
        _check_at_most(
            table, column, limit,
            f"a measured orientation error must be within +-{limit:g} arcsec "
            f"({MAX_ANGULAR_ERROR_DEG:g} deg; more is not a small error)",
        )  # fmt: skip
    for column in ("phi1_deg", "phi2_deg"):
        why = _looks_like_radians(table[column])
        if why:
            raise InputError(
                f"these angles look like radians, not degrees ({why}); convert the column to "
                "degrees",
                path=table.path,
                row=int(rows[0]),
                column=column,
            )
    if table.has("sigma_arcsec"):
        bad = np.flatnonzero(table["sigma_arcsec"] <= 0)
        if bad.size:
            raise InputError(
                f"sigma must be > 0, found {table['sigma_arcsec'][bad[0]]:g}",
                path=table.path,
                row=int(rows[bad[0]]),
                column="sigma_arcsec",
            )
        bad = np.flatnonzero(table["sigma_arcsec"] < MIN_SIGMA_ARCSEC)
        if bad.size:
            raise InputError(
                f"sigma must be at least {MIN_SIGMA_ARCSEC:g} arcsec, found "
                f"{table['sigma_arcsec'][bad[0]]:g}",
                path=table.path, row=int(rows[bad[0]]), column="sigma_arcsec",
            )  # fmt: skip
        _check_at_most(
            table, "sigma_arcsec", limit,
            f"sigma must be at most {limit:g} arcsec ({MAX_ANGULAR_ERROR_DEG:g} deg)",
        )  # fmt: skip
    if table.has("time_s"):
        table.refuse("time_s", table["time_s"] < 0, "time since the start of the run must be >= 0")
        _check_at_most(
            table, "time_s", MAX_TIME_S,
            f"time since the start of the run must be at most {MAX_TIME_S:g} s (a year)",
        )  # fmt: skip
    for column in ("dir1", "dir2"):
        if table.has(column):
            bad = np.flatnonzero(np.abs(table[column]) != 1)
            if bad.size:
                raise InputError(
                    f"an approach direction must be +1 or -1, found {table[column][bad[0]]:g}",
                    path=table.path,
                    row=int(rows[bad[0]]),
                    column=column,
                )
    refuse_repeated_rows(
        table,
        ("phi1_deg", "phi2_deg", "dir1", "dir2", "time_s"),
        "repeats must differ in time_s or approach direction",
    )
    angles = np.stack([table[f"{n}_arcsec"] for n in ANGLE_NAMES], axis=1) / ARCSEC_PER_RAD
    return OrientationMeasurements(
        phi1_rad=table["phi1_deg"] / DEG_PER_RAD,
        phi2_rad=table["phi2_deg"] / DEG_PER_RAD,
        angles_rad=angles,
        sigma_rad=table["sigma_arcsec"] / ARCSEC_PER_RAD if table.has("sigma_arcsec") else None,
        time_s=table["time_s"] if table.has("time_s") else None,
        dir1=table["dir1"] if table.has("dir1") else None,
        dir2=table["dir2"] if table.has("dir2") else None,
        rows=rows,
        source=str(table.path),
    )

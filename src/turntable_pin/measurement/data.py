"""Orientation measurements: the CSV of ``docs/measurements.md``, read and validated.

Required columns ``phi1_deg, phi2_deg, dpsi_arcsec, dtheta_arcsec, dgamma_arcsec``; optional
``sigma_arcsec``, ``time_s``, ``dir1``, ``dir2``. Another column is numeric when at least half its
filled cells are numbers: it is kept (:attr:`OrientationMeasurements.extra`, a suspect for the
diagnosis) and every cell must be a finite number (``warm`` in ``temperature_c`` is refused); a
text column (a ``note``) is left out and named (``ignored_columns``). Beyond the shared reader's
checks (missing columns, non-numbers, NaN), a file is refused, naming row and column, when:

- a value is out of range: ``|phiK_deg|`` above :data:`MAX_COMMANDED_ANGLE_DEG`; ``|dpsi|,
  |dtheta|, |dgamma|`` above :data:`MAX_MEASURED_ANGLE_ARCSEC` (30 deg: no orientation error of
  the table); a sigma <= 0, below :data:`MIN_SIGMA_ARCSEC` or above :data:`MAX_SIGMA_ARCSEC`; a
  ``time_s`` below 0 or above :data:`MAX_TIME_S`; a ``dirK`` not +1 or -1;
- two rows are the same measurement: equal angles and equal ``dir1, dir2, time_s`` where present
  (repeats must differ in time or approach direction; angles compared as written, 0 and 360
  differ);
- an angle column looks like radians: every value within +-2 pi, some not whole, and either (a)
  all of them, read as radians, whole degrees (0.5235987756 = 30 deg), or (b) spanning more than
  pi with none a multiple of 0.25 deg besides 0. Small angles in degrees (-3, -1.5, 0, 1.5, 3)
  pass: they are quarter-degree multiples.
"""

from __future__ import annotations

import dataclasses
import weakref
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..calibration.positions import (
    MAX_COMMANDED_ANGLE_DEG,
    angle_columns,
    check_commanded_angles,
    check_times_and_directions,
)
from ..core.csv_table import read_csv_table, read_header, refuse_repeated_rows
from ..core.exceptions import InputError
from ..core.notebook import NotebookResult
from ..core.sizes import MAX_TIME_S
from ..core.units import ARCSEC_PER_RAD, DEG_PER_RAD
from ..model.angles import ANGLE_NAMES
from ..model.errors import MAX_ANGULAR_ERROR_DEG, MAX_ORIENTATION_ERROR_DEG
from .effects.base import PositionVariables

__all__ = [
    "ANGLE_NAMES",
    "MAX_COMMANDED_ANGLE_DEG",
    "MAX_MEASURED_ANGLE_ARCSEC",
    "MAX_SIGMA_ARCSEC",
    "MAX_TIME_S",
    "MIN_SIGMA_ARCSEC",
    "OrientationMeasurements",
    "read_measurements",
]

_RESERVED = frozenset(("sigma_arcsec", "time_s"))
_SIGMA_COLUMNS = tuple(f"sigma_{n}_arcsec" for n in ANGLE_NAMES)

MAX_MEASURED_ANGLE_ARCSEC = MAX_ORIENTATION_ERROR_DEG * 3600.0
"""Largest ``|dpsi|, |dtheta|, |dgamma|`` of a row, arc seconds (30 deg,
:data:`~turntable_pin.model.errors.MAX_ORIENTATION_ERROR_DEG`): the fit is exact, so a constant
offset of several degrees is an ordinary run; beyond 30 deg a row is no orientation error of the
table. What the table's errors cannot explain is refused after the base fit
(:data:`~turntable_pin.measurement.fit.MAX_UNEXPLAINED_ARCSEC`)."""
MAX_SIGMA_ARCSEC = MAX_ANGULAR_ERROR_DEG * 3600.0
"""Largest ``sigma_arcsec`` (and ``sigma_<angle>_arcsec``), arc seconds (5 deg): noise is a small
error (:data:`~turntable_pin.model.errors.MAX_ANGULAR_ERROR_DEG`)."""
MIN_SIGMA_ARCSEC = 1e-9
"""Smallest ``sigma_arcsec``, arc seconds: five femtoradians, the rounding of a double-precision
angle; a smaller sigma is no noise level, and its weight 1/sigma^2 would overflow the fit."""


def _frozen(value, dtype=float) -> np.ndarray:
    out = np.array(value, dtype=dtype)
    out.setflags(write=False)
    return out


_VARIABLES = "_variables"
"""Where an :class:`OrientationMeasurements` keeps its :class:`PositionVariables` (weakly)."""


@dataclass(frozen=True)
class OrientationMeasurements(NotebookResult):
    """Measured orientation errors at N positions (radians and seconds inside).

    Attributes:
        joint_rad: commanded joint angles (N, J), chain order from the base (phi1 .. phiJ).
        angles_rad: measured ``dpsi, dtheta, dgamma`` (N, 3); NaN where not measured.
        sigma_rad: 1-sigma noise of each angle (N, 3), or ``None`` (estimated from the fit).
        time_s: time of each row (N,) or ``None``.
        dirs: per joint, the approach direction ``dirK`` (N,) or ``None``.
        extra: other numeric columns of the file, ``{name: (N,)}`` (suspects for the diagnosis).
        rows: the file's line number of each position (N,), comment lines counted (the rule of
            :mod:`~turntable_pin.core.csv_table`; 2 = first data row of a file without them).
        source: the file read, or a description.
        joint_names: the table's joint names (for column names and labels), or ``()``.
        sigma_relative: ``sigma_rad`` gives only the angles' relative noise (weights), the level
            is estimated from the fit (the diagnosis' choice when no sigma is given and the
            angles' noise differ).
        ignored_columns: the file's columns left out as not numbers (text or empty throughout).
    """

    joint_rad: np.ndarray
    angles_rad: np.ndarray
    sigma_rad: np.ndarray | None = None
    time_s: np.ndarray | None = None
    dirs: tuple[np.ndarray | None, ...] = ()
    extra: Mapping[str, np.ndarray] = field(default_factory=dict)
    rows: np.ndarray | None = None
    source: str = ""
    joint_names: tuple[str, ...] = ()
    sigma_relative: bool = False
    ignored_columns: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        joints = np.array(self.joint_rad, dtype=float)
        if joints.ndim == 1:
            joints = joints[:, None]
        n, n_joints = joints.shape
        dirs = (tuple(self.dirs) + (None,) * n_joints)[:n_joints]
        for name, value in (("time_s", self.time_s), ("rows", self.rows),
                            *((f"dir{k + 1}", d) for k, d in enumerate(dirs)),
                            *self.extra.items()):  # fmt: skip
            if value is not None and np.asarray(value).size != n:
                raise InputError(f"{name} has {np.asarray(value).size} values, expected {n}")
        sigma = self.sigma_rad
        if sigma is not None:
            sigma = np.asarray(sigma, dtype=float)
            sigma = np.repeat(sigma.reshape(n, 1), 3, axis=1) if sigma.size == n else sigma
            sigma = _frozen(sigma.reshape(n, 3))
        rows = np.arange(2, n + 2) if self.rows is None else np.reshape(self.rows, -1)
        checked = {
            "joint_rad": _frozen(joints),
            "angles_rad": _frozen(np.reshape(self.angles_rad, (n, 3))),
            "sigma_rad": sigma,
            "time_s": None if self.time_s is None else _frozen(np.reshape(self.time_s, -1)),
            "dirs": tuple(None if d is None else _frozen(np.reshape(d, -1)) for d in dirs),
            "extra": {k: _frozen(np.reshape(v, -1)) for k, v in self.extra.items()},
            "rows": _frozen(rows, int),
            "joint_names": tuple(self.joint_names),
            "ignored_columns": tuple(self.ignored_columns),
        }
        for name, value in checked.items():
            object.__setattr__(self, name, value)
        self._check_values()

    def _check_values(self) -> None:
        """Refuse what would reach the fit as a NaN or a nonsense weight (the reader refuses the
        same in files, naming the row): an empty cell means "not measured" for the three angles
        only."""
        for name, value in (("joint_rad", self.joint_rad), ("time_s", self.time_s),
                            *((f"dir{k}", d) for k, d in enumerate(self.dirs, 1)),
                            *self.extra.items()):  # fmt: skip
            if value is None:
                continue
            bad = ~np.isfinite(np.asarray(value, float).reshape(self.rows.size, -1)).all(axis=1)
            self._refuse(bad, f"{name}: expected finite numbers, found NaN or inf")
        self._refuse(
            np.isinf(self.angles_rad).any(axis=1),
            "angles_rad: an angle is infinite (NaN means not measured; inf is an error)",
        )
        if self.sigma_rad is not None:
            good = np.isfinite(self.sigma_rad) & (self.sigma_rad > 0)
            self._refuse(
                (self.measured & ~good).any(axis=1),
                "sigma_rad: must be finite and > 0 for every measured angle",
            )
        for k, d in enumerate(self.dirs, 1):
            if d is not None:
                self._refuse(np.abs(d) != 1, f"dir{k}: must be +1 or -1")

    def _refuse(self, bad: np.ndarray, what: str) -> None:
        """Raise :class:`InputError` naming the first row where ``bad`` holds."""
        if np.any(bad):
            row = int(self.rows[np.flatnonzero(bad)[0]])
            raise InputError(f"{what} (row {row} of {self.source or 'the data'})")

    @property
    def n_positions(self) -> int:
        """Number of positions N."""
        return int(self.joint_rad.shape[0])

    @property
    def n_joints(self) -> int:
        """Number of joints J."""
        return int(self.joint_rad.shape[1])

    @property
    def measured(self) -> np.ndarray:
        """Which angles were measured, (N, 3) bool (an empty cell is ``False``)."""
        return np.isfinite(self.angles_rad)

    def variables(self) -> PositionVariables:
        """What effects may depend on at each position: one object while any model built on
        these data lives (the arrays are read-only, and the models share what they compute from
        it, :meth:`PositionVariables.memo`); the data set holds it weakly, so that what the
        models computed goes with them."""
        ref = self.__dict__.get(_VARIABLES)
        cached = ref() if ref is not None else None
        if cached is None:
            measured = self.measured
            cached = PositionVariables(
                self.joint_rad,
                self.time_s,
                self.dirs,
                dict(self.extra),
                boresight_only=measured[:, 0] & ~measured[:, 2],
                ignored_columns=self.ignored_columns,
            )
            self.__dict__[_VARIABLES] = weakref.ref(cached)
        return cached

    def __getstate__(self) -> dict:
        """The fields (for pickle and copy): the weakly held variables stay behind."""
        return {k: v for k, v in self.__dict__.items() if k != _VARIABLES}

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)

    def columns(self) -> dict[str, np.ndarray]:
        """The CSV columns of ``docs/measurements.md`` in user units (degrees, arcsec, s)."""
        # Rounded to 1e-9 deg so that a 30-degree grid is written as 30.0, not 29.999999...
        out = {
            f"phi{k + 1}_deg": np.round(self.joint_rad[:, k] * DEG_PER_RAD, 9)
            for k in range(self.n_joints)
        }
        for i, name in enumerate(ANGLE_NAMES):
            out[f"{name}_arcsec"] = self.angles_rad[:, i] * ARCSEC_PER_RAD
        if self.sigma_rad is not None:
            sigma = self.sigma_rad * ARCSEC_PER_RAD
            if np.all(sigma == sigma[:, :1]):
                out["sigma_arcsec"] = sigma[:, 0]
            else:
                for i, name in enumerate(ANGLE_NAMES):
                    out[f"sigma_{name}_arcsec"] = sigma[:, i]
        if self.time_s is not None:
            out["time_s"] = self.time_s
        for k, value in enumerate(self.dirs):
            if value is not None:
                out[f"dir{k + 1}"] = value.astype(int)
        out.update(self.extra)
        return out

    def to_dict(self) -> dict:
        """The measurements as a JSON-ready dict: ``source``, ``n_positions``, ``joint_names``
        and the CSV's :meth:`columns` (degrees, arcsec, s; ``None`` where not measured)."""
        return {
            "source": self.source,
            "n_positions": self.n_positions,
            "joint_names": list(self.joint_names) if self.joint_names else None,
            "columns": {name: values.tolist() for name, values in self.columns().items()},
        }

    def replace(self, **changes) -> OrientationMeasurements:
        """A copy with some attributes changed (``sigma_rad=None``, ``angles_rad=...``)."""
        return dataclasses.replace(self, **changes)

    def without_sigma(self) -> OrientationMeasurements:
        """The same data with the noise level left to be estimated from the fit."""
        return self.replace(sigma_rad=None, sigma_relative=False)


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


def read_measurements(
    path: str | Path, joint_names: Sequence[str] | None = None
) -> OrientationMeasurements:
    """Read and validate an orientation measurement CSV (see the module docstring).

    Args:
        path: the file.
        joint_names: the table's revolute joints from the base (default: the paper's two axes,
            columns ``phi1_deg, phi2_deg``); each joint's angle is ``phiK_deg`` or ``<joint>_deg``.

    Raises:
        InputError: naming file, row and column of the first problem found.
    """
    path = Path(path)
    header, header_row = read_header(path)
    joint_columns = (
        angle_columns(header, joint_names, path, header_row) if header else ("phi1_deg",)
    )
    n_joints = len(joint_names) if joint_names else 2
    value_columns = tuple(f"{n}_arcsec" for n in ANGLE_NAMES)
    dir_columns = tuple(f"dir{k}" for k in range(1, n_joints + 1))
    table = read_csv_table(
        path, (*joint_columns, *value_columns),
        ("sigma_arcsec", *_SIGMA_COLUMNS, "time_s", *dir_columns),
        min_rows=1, blank=value_columns, extra=True,
    )  # fmt: skip
    check_commanded_angles(table, joint_columns)
    values = _measured_angles(table, value_columns, joint_columns)
    sigma = _sigma_arcsec(table)
    check_times_and_directions(table, dir_columns)
    refuse_repeated_rows(
        table,
        (*joint_columns, *dir_columns, "time_s"),
        "repeats must differ in time_s or approach direction",
    )
    return OrientationMeasurements(
        joint_rad=np.stack([table[c] for c in joint_columns], axis=1) / DEG_PER_RAD,
        angles_rad=values / ARCSEC_PER_RAD,
        sigma_rad=None if sigma is None else sigma / ARCSEC_PER_RAD,
        time_s=table["time_s"] if table.has("time_s") else None,
        dirs=tuple(table[c] if table.has(c) else None for c in dir_columns),
        extra={k: v for k, v in table.extra.items() if k not in _RESERVED},
        rows=table.rows,
        source=str(table.path),
        joint_names=tuple(joint_names or ()),
        ignored_columns=table.skipped,
    )


def _measured_angles(table, value_columns, joint_columns) -> np.ndarray:
    """The measured angles (N, 3) arcsec, NaN where empty: refused where a row measures none or
    one is beyond :data:`MAX_MEASURED_ANGLE_ARCSEC`, and where a joint column looks like
    radians."""
    values = np.stack([table[c] for c in value_columns], axis=1)
    none = np.flatnonzero(~np.isfinite(values).any(axis=1))
    if none.size:
        raise InputError(
            "none of dpsi_arcsec, dtheta_arcsec, dgamma_arcsec is given: a row needs at least "
            "one measured angle",
            path=table.path, row=int(table.rows[none[0]]), column=value_columns[0],
        )  # fmt: skip
    limit = MAX_MEASURED_ANGLE_ARCSEC
    for column in value_columns:
        _check_at_most(
            table, column, limit,
            f"a measured orientation error must be within +-{limit:g} arcsec "
            f"({MAX_ORIENTATION_ERROR_DEG:g} deg; more is no orientation error of the table)",
        )  # fmt: skip
    for column in joint_columns:
        why = _looks_like_radians(table[column])
        if why:
            raise InputError(
                f"these angles look like radians, not degrees ({why}); convert the column to "
                "degrees",
                path=table.path,
                row=int(table.rows[0]),
                column=column,
            )
    return values


def _sigma_arcsec(table) -> np.ndarray | None:
    """The sigma of each measured angle (N, 3) arcsec from ``sigma_arcsec`` or the three
    ``sigma_<angle>_arcsec``, checked to be in [:data:`MIN_SIGMA_ARCSEC`,
    :data:`MAX_SIGMA_ARCSEC`]; ``None`` without them."""
    per_angle = any(table.has(c) for c in _SIGMA_COLUMNS)
    if table.has("sigma_arcsec") and per_angle:
        raise InputError(
            "give either sigma_arcsec or the per-angle sigma_<angle>_arcsec columns, not both",
            path=table.path, row=table.header_row, column="sigma_arcsec",
        )  # fmt: skip
    for column in ("sigma_arcsec", *_SIGMA_COLUMNS):
        if not table.has(column):
            continue
        table.refuse(column, table[column] <= 0, "sigma must be > 0")
        table.refuse(
            column, table[column] < MIN_SIGMA_ARCSEC,
            f"sigma must be at least {MIN_SIGMA_ARCSEC:g} arcsec",
        )  # fmt: skip
        _check_at_most(
            table, column, MAX_SIGMA_ARCSEC,
            f"sigma must be at most {MAX_SIGMA_ARCSEC:g} arcsec ({MAX_ANGULAR_ERROR_DEG:g} deg)",
        )  # fmt: skip
    if table.has("sigma_arcsec"):
        return np.repeat(table["sigma_arcsec"][:, None], 3, axis=1)
    if not per_angle:
        return None
    missing = [c for c in _SIGMA_COLUMNS if not table.has(c)]
    if missing:
        raise InputError(
            f"per-angle sigma needs all three columns; missing {', '.join(missing)}",
            path=table.path, row=table.header_row,
        )  # fmt: skip
    return np.stack([table[c] for c in _SIGMA_COLUMNS], axis=1)

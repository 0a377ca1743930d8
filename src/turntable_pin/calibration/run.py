"""A GyroWheel calibration run as read from its CSV: positions, outputs, noise, time, extras.

One row per position (``docs/measurements.md``, "GyroWheel calibration runs"): one angle column
per joint of the table (``phi1_deg .. phiN_deg`` in chain order or ``<joint>_deg``),
``out_x_dph, out_y_dph`` (deg/h) and optionally ``sigma_dph`` (1-sigma output noise of the row),
``time_s`` (s since the start of the run) and any other numeric column (``temperature_c``...),
which is kept as a possible cause for the diagnosis of the run. A column is numeric when at least
half of its filled cells are numbers, and then every cell must be a finite number (a ``warm`` in a
``temperature_c`` column is refused naming file, row and column); a column of text (a ``note``)
is left out and named in :attr:`CalibrationRun.ignored_columns`. The latitude is a parameter of
the run. :func:`read_run` is the one reader: ``calibrate`` fits what it returns, and the run
diagnosis (:mod:`turntable_pin.instrument`) diagnoses it.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..core.csv_table import missing_columns_words, read_csv_table, refuse_repeated_rows
from ..core.exceptions import InputError
from ..model.paper_table import resolve_table
from .positions import PositionInputs, PositionSet, check_times_and_directions, position_inputs

__all__ = [
    "MAX_RUN_OUTPUT_DPH",
    "MIN_RUN_SIGMA_DPH",
    "OUTPUT_COLUMNS",
    "RUN_OPTIONAL_COLUMNS",
    "CalibrationRun",
    "read_run",
    "refuse_copied_rows",
]

OUTPUT_COLUMNS: tuple[str, ...] = ("out_x_dph", "out_y_dph")
"""The two output columns, x axis then y axis (deg/h): every run has them besides each joint's
angle."""
RUN_OPTIONAL_COLUMNS: tuple[str, ...] = ("sigma_dph", "time_s")
"""Columns read when present: 1-sigma output noise (deg/h) and time (s)."""
MAX_RUN_OUTPUT_DPH = 1e6
"""Largest ``|out_x_dph|``, ``|out_y_dph|`` and ``sigma_dph`` of a run, deg/h: the earth rate
(15 deg/h) plus seven drift terms each within ``MAX_COEFFICIENT_DPH`` at 1 g stay below it; more
is a unit mix-up (deg/s or rad/s written as deg/h), and the fit's squares would overflow."""
MIN_RUN_SIGMA_DPH = 1e-9
"""Smallest ``sigma_dph``, deg/h: far below any rate sensor's noise; a smaller sigma is a typo,
and its weight 1/sigma would overflow the fit."""


@dataclass(frozen=True)
class CalibrationRun:
    """One calibration run.

    Attributes:
        inputs: the positions and what the GyroWheel senses there at the ideal orientation.
        outputs_dph: (N, 2) measured ``out_x, out_y``, deg/h.
        sigma_dph: (N,) 1-sigma output noise of each row, deg/h, or ``None`` (estimated).
        time_s: (N,) time since the start of the run, s, or ``None``.
        extra: other numeric columns ``{name: (N,)}`` (``temperature_c``...).
        rows: (N,) the file row of each position (header = row 1).
        source: the file it was read from ('' when made in memory).
        ignored_columns: the file's columns left out as not numbers (text or empty throughout).
    """

    inputs: PositionInputs
    outputs_dph: np.ndarray
    sigma_dph: np.ndarray | None = None
    time_s: np.ndarray | None = None
    extra: dict[str, np.ndarray] = field(default_factory=dict)
    rows: np.ndarray | None = None
    source: str = ""
    ignored_columns: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        outputs = np.asarray(self.outputs_dph, dtype=float)
        n = len(self.inputs)
        if outputs.shape != (n, 2):
            raise InputError(f"a run of {n} positions needs outputs of shape ({n}, 2)")
        if not np.all(np.isfinite(outputs)):
            raise InputError("run outputs must be finite numbers (found NaN or inf)")
        object.__setattr__(self, "outputs_dph", outputs)
        if self.rows is None:
            object.__setattr__(self, "rows", np.arange(2, n + 2))

    @property
    def n_positions(self) -> int:
        """Number of positions (rows) N."""
        return len(self.inputs)

    @property
    def table(self):
        """The table the run was made on."""
        return self.inputs.positions.table

    @property
    def joint_rad(self) -> np.ndarray:
        """(N, J) commanded joint angles, rad."""
        return self.inputs.positions.angles_rad

    def column(self, name: str) -> np.ndarray | None:
        """``time_s``, an extra column, or ``None`` when the run has no such column."""
        return self.time_s if name == "time_s" else self.extra.get(name)

    def missing_columns_words(self, missing) -> str:
        """Why the columns ``missing`` cannot be used: absent from the run, or present but not
        numbers (:func:`~turntable_pin.core.csv_table.missing_columns_words`)."""
        return missing_columns_words(missing, self.ignored_columns, "the run")

    def replace(self, **changes) -> CalibrationRun:
        """A copy with some fields changed."""
        return replace(self, **changes)


def read_run(path: str | Path, latitude_rad: float, table=None) -> CalibrationRun:
    """Read a calibration run CSV (module docstring), refusing out-of-range values by file, row
    and column. Copied rows are refused by :func:`refuse_copied_rows`, which the caller runs
    after its identifiability check (too few positions is the first problem to name).

    ``table``: the :class:`~turntable_pin.model.generic_table.GenericTable` the run was made on
    (default the paper's table).
    """
    table = resolve_table(table)
    optional = PositionSet.candidate_columns(table) + RUN_OPTIONAL_COLUMNS
    csv = read_csv_table(path, OUTPUT_COLUMNS, optional, extra=True)
    columns = PositionSet.columns_of(csv, table)
    positions = PositionSet.from_csv_table(csv, columns, table, str(path))
    _check_run_values(csv)
    extra = {k: v for k, v in csv.extra.items() if k not in columns}
    run = CalibrationRun(
        position_inputs(positions, latitude_rad),
        np.stack([csv[c] for c in OUTPUT_COLUMNS], axis=1),
        csv["sigma_dph"] if csv.has("sigma_dph") else None,
        csv["time_s"] if csv.has("time_s") else None,
        extra,
        np.asarray(csv.rows),
        str(path),
        csv.skipped,
    )
    object.__setattr__(run, "_csv", (csv, columns))
    return run


def refuse_copied_rows(run: CalibrationRun) -> None:
    """Refuse two rows of ``run``'s file that are the same measurement (equal angles and, when
    present, ``time_s``), naming file and rows; nothing for a run made in memory."""
    found = getattr(run, "_csv", None)
    if found is None:
        return
    csv, columns = found
    refuse_repeated_rows(
        csv,
        (*columns, "time_s"),
        "a copied row counts one measurement twice (repeats must differ in time_s)",
    )


def _check_run_values(table) -> None:
    """Refuse outputs, sigmas or times out of range (naming file, row and column)."""
    for column in ("out_x_dph", "out_y_dph", "sigma_dph"):
        if not table.has(column):
            continue
        table.refuse(
            column,
            np.abs(table[column]) > MAX_RUN_OUTPUT_DPH,
            f"must be within +-{MAX_RUN_OUTPUT_DPH:g} deg/h",
        )
    if table.has("sigma_dph"):
        table.refuse("sigma_dph", table["sigma_dph"] <= 0, "sigma_dph must be positive")
        table.refuse(
            "sigma_dph",
            table["sigma_dph"] < MIN_RUN_SIGMA_DPH,
            f"sigma_dph must be at least {MIN_RUN_SIGMA_DPH:g} deg/h",
        )
    check_times_and_directions(table, ())

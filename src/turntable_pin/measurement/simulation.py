"""Simulated orientation measurements: turntable errors, hidden effects, a schedule, noise, a seed.

Users rehearse a measurement campaign with it and the tests make data with known, hidden effects.
The truth goes through the exact chain the fit uses (``OrientationModel``) with the chosen effect
parameters; noise is Gaussian with the stated sigma on each angle. The output is the CSV of
``docs/measurements.md``, the seed and the truth in comment lines.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..calibration.positions import (
    PositionSet,
    angle_columns,
    check_commanded_angles,
    check_times_and_directions,
    checked_times_and_directions,
)
from ..core.csv_table import read_csv_table, read_header, refuse_repeated_rows
from ..core.exceptions import InputError, check_seed
from ..core.notebook import NotebookResult
from ..core.sizes import MAX_SIMULATED_ROWS, MIN_GRID_STEP_DEG, check_count, turn_grid_count
from ..core.turn_grid import full_turn_grid_deg, random_turn_positions_deg
from ..core.units import ARCSEC_PER_RAD, DEG_PER_RAD
from ..model.angles import ANGLE_NAMES
from ..model.errors import TurntableErrors
from ..model.paper_table import paper_table
from .data import (
    MAX_COMMANDED_ANGLE_DEG,
    MAX_MEASURED_ANGLE_ARCSEC,
    MAX_SIGMA_ARCSEC,
    MAX_TIME_S,
    MIN_SIGMA_ARCSEC,
    OrientationMeasurements,
)
from .effects.base import Effect, PositionVariables
from .simulated import (
    SimulatedFile,
    check_dwell,
    checked_noise,
    planted_model,
    run_times_s,
)
from .table import measured_table

__all__ = [
    "ROW_BYTES",
    "APPROACHES",
    "MAX_NOISE_ARCSEC",
    "MAX_NOISE_SPREAD",
    "ORDERS",
    "Schedule",
    "SimulatedMeasurements",
    "read_positions",
    "simulate_measurements",
]

ORDERS = ("grid", "random")
"""Measurement orders a :class:`Schedule` knows."""
APPROACHES = ("random", "motion", "positive")
"""Approach-direction rules a :class:`Schedule` knows."""

MAX_NOISE_ARCSEC = MAX_SIGMA_ARCSEC / 10.0
"""Largest simulated noise sigma, arc seconds (1800, half a degree): a tenth of the largest sigma
a measurement file may hold (and of the small-error limit), so that noise alone never makes a file
that cannot be read back."""

MAX_NOISE_SPREAD = 100.0
"""Largest ``noise_spread`` F: each row's sigma is drawn log-uniform in [sigma/F, sigma*F]."""

ROW_BYTES = 1024
"""Memory a simulated row costs while it is built and written (rough upper bound), bytes."""


DEFAULT_GRID_STEP_DEG = 30.0
"""Grid step of a joint a :class:`Schedule` gives no step for, degrees."""


@dataclass(frozen=True, init=False)
class Schedule:
    """Which positions are measured, in which order, when, and from which side.

    The positions: a grid over every joint (the default), a list (``positions``), single-axis
    sweeps (``sweep``) or random positions (``random_positions``); measured ``repeats`` times
    over, and with ``passes`` K > 0 forward then backward, K times. The grid steps are the
    positional arguments, one per joint from the base: ``Schedule(45, 30, order="random")``.

    Attributes:
        steps_deg: grid step of each joint from the base, degrees (beyond the sequence:
            :data:`DEFAULT_GRID_STEP_DEG`; a table with fewer joints ignores the rest); the grid
            covers [start, start + 360). Reported as ``phiK_step_deg``.
        starts_deg: first grid angle of each joint, degrees (beyond the sequence: 0); a sweep
            holds the other joints there. Reported as ``phiK_start_deg``.
        order: ``grid`` (phi1 the outer loop, the last joint the inner) or ``random`` (shuffled;
            grids only).
        repeats: how many times each position is measured.
        dwell_s: time between consecutive measurements.
        approach: ``random`` (each axis from a random side), ``motion`` (the side the move came
            from, unchanged when the axis did not move; with ``passes``, +1 forward and -1
            backward for every joint) or ``positive``; ``None``: ``motion`` with ``passes``,
            else ``random``.
        positions: a list of positions ``((phi1_deg, phi2_deg, ...), ...)``, one angle per
            joint, measured in its order.
        positions_time_s: the time of each listed position (default: ``dwell_s`` apart); not
            with ``repeats`` or ``passes``.
        positions_dirs: per joint, the approach direction (+1/-1) of each listed position, or
            ``None`` (the ``approach`` rule applies); not with ``passes``.
        positions_source: where the list came from (a file name), for the comment header.
        sweep: joints swept one after the other (``("phi1", "phi2")``: phi1 over its grid with
            the others held at their start, then phi2).
        random_positions: N > 0: N positions uniform over [start, start + 360) of every joint
            (seeded; rounded to 1e-6 deg).
        passes: K > 0: the positions forward then backward, K times (2K traversals).
    """

    steps_deg: tuple[float, ...] = ()
    starts_deg: tuple[float, ...] = ()
    order: str = "grid"
    repeats: int = 1
    dwell_s: float = 60.0
    approach: str | None = None
    positions: tuple[tuple[float, ...], ...] | None = None
    positions_time_s: tuple[float, ...] | None = None
    positions_dirs: tuple[tuple[float, ...] | None, ...] = ()
    positions_source: str = ""
    sweep: tuple[str, ...] = ()
    random_positions: int = 0
    passes: int = 0

    def __init__(
        self,
        *steps_deg: float,
        starts_deg: Sequence[float] = (),
        order: str = "grid",
        repeats: int = 1,
        dwell_s: float = 60.0,
        approach: str | None = None,
        positions: tuple[tuple[float, ...], ...] | None = None,
        positions_time_s: tuple[float, ...] | None = None,
        positions_dirs: tuple[tuple[float, ...] | None, ...] = (),
        positions_source: str = "",
        sweep: tuple[str, ...] = (),
        random_positions: int = 0,
        passes: int = 0,
    ) -> None:
        given = dict(locals())  # the arguments are the fields, by name
        given["steps_deg"] = tuple(float(s) for s in steps_deg)
        given["starts_deg"] = tuple(float(s) for s in starts_deg)
        for name in self.__dataclass_fields__:
            object.__setattr__(self, name, given[name])
        self._check_grid()
        self._check_design()

    def _check_grid(self) -> None:
        for k, step in enumerate(self.steps_deg, start=1):
            if not MIN_GRID_STEP_DEG <= step <= 360:
                raise InputError(
                    f"phi{k}_step_deg (steps_deg[{k - 1}]) must be in [{MIN_GRID_STEP_DEG:g}, "
                    f"360], got {step:g}"
                )
        for k, start in enumerate(self.starts_deg, start=1):
            if not abs(start) <= MAX_COMMANDED_ANGLE_DEG - 360.0:
                raise InputError(
                    f"phi{k}_start_deg (starts_deg[{k - 1}]) must be within "
                    f"+-{MAX_COMMANDED_ANGLE_DEG - 360.0:g} deg, got {start}"
                )

    def _check_design(self) -> None:
        if self.order not in ORDERS:
            raise InputError(f"order must be one of {', '.join(ORDERS)}, got '{self.order}'")
        if self.approach is None:
            object.__setattr__(self, "approach", "motion" if self.passes else "random")
        if self.approach not in APPROACHES:
            raise InputError(f"approach must be one of {', '.join(APPROACHES)}")
        if self.repeats < 1:
            raise InputError(f"repeats must be >= 1, got {self.repeats}")
        if self.passes < 0 or self.random_positions < 0:
            raise InputError("passes and random_positions must be >= 0")
        designs = [
            name
            for name, given in (
                ("positions", self.positions is not None),
                ("sweep", bool(self.sweep)),
                ("random_positions", self.random_positions > 0),
            )
            if given
        ]
        if len(designs) > 1:
            raise InputError(f"give one design of positions, not {' and '.join(designs)}")
        if designs and self.order != "grid":
            raise InputError(
                f"order '{self.order}' shuffles a grid; {designs[0]} are measured in their own "
                "order"
            )
        self._check_positions()
        self._check_sweep()
        check_count(
            float(self._base_count(2)) * self.repeats * (2 * self.passes or 1),
            MAX_SIMULATED_ROWS,
            "rows of simulated measurements",
            ROW_BYTES,
        )
        check_dwell(self.dwell_s)

    def _check_positions(self) -> None:
        if self.positions is None:
            if self.positions_time_s is not None or any(d is not None for d in self.positions_dirs):
                raise InputError("positions_time_s and positions_dirs need positions")
            return
        rows = np.asarray(self.positions, dtype=float)
        if rows.ndim != 2 or rows.shape[0] < 1:
            raise InputError("positions must be a non-empty list of (phi1_deg, phi2_deg, ...)")
        if not np.all(np.abs(rows) <= MAX_COMMANDED_ANGLE_DEG):
            raise InputError(
                f"a listed position must be within +-{MAX_COMMANDED_ANGLE_DEG:g} deg (and finite)"
            )
        checked_times_and_directions(
            rows.shape[0], self.positions_time_s, self.positions_dirs,
            ("positions_time_s", "positions_dirs"),
        )  # fmt: skip
        if self.positions_time_s is not None and (self.repeats > 1 or self.passes):
            raise InputError(
                "the positions give their times; repeats and passes would need other times "
                "(leave out time_s, or list every measurement)"
            )
        given = [k for k, d in enumerate(self.positions_dirs, start=1) if d is not None]
        if given and self.passes:
            raise InputError(
                f"passes set the approach directions themselves; the positions give dir{given[0]}"
            )

    def _check_sweep(self) -> None:
        joints = [str(j) for j in self.sweep]
        for j in joints:
            if not re.fullmatch(r"phi[1-9][0-9]*", j):
                raise InputError(f"sweep: unknown axis '{j}', expected phiK (phi1, phi2, ...)")
        if len(set(joints)) != len(joints):
            raise InputError(f"sweep: an axis is swept twice in {','.join(joints)}")

    def _steps(self, n_joints: int) -> list[tuple[float, float]]:
        """``(start_deg, step_deg)`` of each of ``n_joints`` joints from the base."""
        return [
            (
                self.starts_deg[k] if k < len(self.starts_deg) else 0.0,
                self.steps_deg[k] if k < len(self.steps_deg) else DEFAULT_GRID_STEP_DEG,
            )
            for k in range(n_joints)
        ]

    def _base_count(self, n_joints: int) -> int:
        """Positions of the design before ``repeats`` and ``passes``."""
        if self.positions is not None:
            return len(self.positions)
        if self.random_positions:
            return int(self.random_positions)
        steps = self._steps(n_joints)
        if self.sweep:
            return sum(turn_grid_count(steps[int(j[3:]) - 1][1]) for j in self.sweep
                       if int(j[3:]) <= n_joints)  # fmt: skip
        return math.prod(turn_grid_count(step) for _, step in steps)

    def count(self, n_joints: int = 2) -> int:
        """Number of measurements on a table with ``n_joints`` joints."""
        return int(self._base_count(n_joints) * self.repeats * (2 * self.passes or 1))

    def duration_s(self, n_joints: int = 2) -> float:
        """Time from the first to the last measurement, seconds (``time_s`` of the last row)."""
        if self.positions_time_s is not None:
            return float(max(self.positions_time_s))
        return (self.count(n_joints) - 1) * float(self.dwell_s)

    def _design_deg(self, rng: np.random.Generator, n_joints: int) -> list[np.ndarray]:
        """The design's positions (before repeats and passes), one array per joint."""
        steps = self._steps(n_joints)
        if self.positions is not None:
            rows = np.asarray(self.positions, dtype=float)
            if rows.shape[1] != n_joints:
                raise InputError(
                    f"the positions give {rows.shape[1]} angles each; the table has {n_joints} "
                    "joints"
                )
            return [rows[:, k] for k in range(n_joints)]
        starts = [start for start, _ in steps]
        if self.random_positions:
            rows = random_turn_positions_deg(rng, self.random_positions, n_joints, starts)
            return [rows[:, k] for k in range(n_joints)]
        if self.sweep:
            axes = [full_turn_grid_deg(step, starts_deg=(start,))[:, 0] for start, step in steps]
            out: list[list[np.ndarray]] = [[] for _ in range(n_joints)]
            for label in self.sweep:
                swept = int(label[3:]) - 1
                if swept >= n_joints:
                    raise InputError(f"sweep: the table has no axis {label} ({n_joints} joints)")
                for k in range(n_joints):
                    size = axes[swept].size
                    out[k].append(axes[k] if k == swept else np.full(size, steps[k][0]))
            return [np.concatenate(parts) for parts in out]
        rows = full_turn_grid_deg(*(step for _, step in steps), starts_deg=starts)
        return [rows[:, k] for k in range(n_joints)]

    def rows(self, rng: np.random.Generator, table) -> PositionSet:
        """The measurements on ``table`` (a ``GenericTable``) in their order: the commanded
        angles, each row's ``time_s`` and each joint's approach direction."""
        n_joints = len(table.joint_names)
        check_count(self.count(n_joints), MAX_SIMULATED_ROWS, "rows of simulated measurements",
                    ROW_BYTES)  # fmt: skip
        angles = [np.tile(a, self.repeats) for a in self._design_deg(rng, n_joints)]
        if self.order == "random":
            perm = rng.permutation(angles[0].size)
            angles = [a[perm] for a in angles]
        if self.passes:
            angles = [np.tile(np.concatenate([a, a[::-1]]), self.passes) for a in angles]
        n = angles[0].size
        if self.duration_s(n_joints) > MAX_TIME_S:
            raise InputError(
                f"dwell_s {self.dwell_s:g}: the run of {n} measurements would last "
                f"{self.duration_s(n_joints):.7g} s, more than {MAX_TIME_S:.7g} s (a year)"
            )
        time_s = run_times_s(n, self.dwell_s)
        dirs = tuple(self._directions(a, rng, k) for k, a in enumerate(angles, start=1))
        return PositionSet(
            np.stack(angles, axis=1) / DEG_PER_RAD, table=table, dirs=dirs,
            time_s=time_s if self.positions_time_s is None else self.positions_time_s,
        )  # fmt: skip

    def _directions(self, phi_deg: np.ndarray, rng: np.random.Generator, joint: int) -> np.ndarray:
        """Approach direction (+1 / -1) of joint ``joint`` (1-based) at each measurement."""
        given = self.positions_dirs[joint - 1] if joint <= len(self.positions_dirs) else None
        if given is not None:
            return np.tile(np.asarray(given, dtype=float), self.repeats)
        if self.approach == "positive":
            return np.ones(phi_deg.size)
        if self.approach == "random":
            return rng.choice([-1.0, 1.0], size=phi_deg.size)
        if self.passes:  # +1 on forward and -1 on backward traversals
            return np.tile(np.repeat([1.0, -1.0], phi_deg.size // (2 * self.passes)), self.passes)
        out = np.ones(phi_deg.size)
        for i in range(1, phi_deg.size):
            move = phi_deg[i] - phi_deg[i - 1]
            out[i] = out[i - 1] if move == 0 else np.sign(move)
        return out

    def describe(self, n_joints: int) -> str:
        """The schedule in one line (the ``# schedule:`` comment of a simulated file)."""
        grid = self._steps(n_joints)
        steps = " ".join(f"phi{k}_step_deg={step:g}" for k, (_, step) in enumerate(grid, start=1))
        starts = " ".join(
            f"phi{k}_start_deg={start:g}" for k, (start, _) in enumerate(grid, start=1)
        )
        tail = f"repeats={self.repeats} dwell_s={self.dwell_s:g} approach={self.approach}"
        if self.positions is not None:
            given = [f"dir{k}" for k, d in enumerate(self.positions_dirs, start=1) if d is not None]
            if self.positions_time_s is not None:
                given.append("time_s")
            head = (
                f"positions={self.positions_source or 'list'} n_positions={len(self.positions)}"
                + (f" given={','.join(given)}" if given else "")
            )
        elif self.random_positions:
            head = f"random_positions={self.random_positions} uniform from {starts}"
        elif self.sweep:
            head = f"sweep={','.join(self.sweep)} {steps} held at {starts}"
        else:
            head = f"{steps} order={self.order}"
            if any(start for start, _ in grid):
                head += f" {starts}"
        return f"{head} {tail}" + (f" passes={self.passes}" if self.passes else "")


def read_positions(path: str | Path, joint_names: Sequence[str] | None = None) -> dict:
    """The ``positions`` of a :class:`Schedule` from a CSV file (``Schedule(**read_positions(p))``).

    Columns: one commanded angle per joint (``phi1_deg .. phiN_deg`` or ``<joint>_deg``),
    optionally ``dir1 .. dirN`` (+1/-1) and ``time_s``; other columns are ignored. The rows are
    measured in the file's order.

    Raises:
        InputError: naming the file, row and column of the first problem.
    """
    path = Path(path)
    names = tuple(joint_names) if joint_names else ("", "")
    header, header_row = read_header(path)
    columns = angle_columns(header, joint_names, path, header_row) if header else ("phi1_deg",)
    dir_columns = tuple(f"dir{k}" for k in range(1, len(names) + 1))
    table = read_csv_table(path, columns, ("time_s", *dir_columns), min_rows=1)
    check_commanded_angles(table, columns)
    check_times_and_directions(table, dir_columns)
    if table.has("time_s"):
        refuse_repeated_rows(
            table, (*columns, *dir_columns, "time_s"),
            "a measurement listed twice (same position, directions and time_s)",
        )  # fmt: skip
    check_count(len(table[columns[0]]), MAX_SIMULATED_ROWS, "listed positions", ROW_BYTES)
    return {
        "positions": tuple(zip(*(table[c].tolist() for c in columns), strict=True)),
        "positions_time_s": tuple(table["time_s"].tolist()) if table.has("time_s") else None,
        "positions_dirs": tuple(
            tuple(table[c].tolist()) if table.has(c) else None for c in dir_columns
        ),
        "positions_source": path.name,
    }


@dataclass(frozen=True)
class SimulatedMeasurements(SimulatedFile, NotebookResult):
    """Simulated data and the truth behind it.

    Attributes:
        data: the measurements (with sigma, time and directions).
        errors: the turntable errors used, ``{name_unit: value}`` in user units
            (``<error>_arcsec``, ``<length>_mm``: what ``GenericTable.to_user_units`` gives).
        effects: ``{effect: {parameter: value in user units}}`` hidden in the data.
        noise_arcsec: the noise sigma (one number, or ``(dpsi, dtheta, dgamma)``).
        seed: the random seed.
        schedule: the :class:`Schedule` measured.
        truth_rad: noise-free ``dpsi, dtheta, dgamma`` (N, 3).
        noise_spread: F: each row's sigma was drawn log-uniform in [sigma/F, sigma*F] (1: even).
    """

    data: OrientationMeasurements
    errors: dict[str, float]
    effects: dict[str, dict[str, float]]
    noise_arcsec: float | tuple[float, float, float]
    seed: int
    schedule: Schedule
    truth_rad: np.ndarray = field(repr=False)
    noise_spread: float = 1.0

    _hidden = "errors and hidden effects"

    def _made(self) -> list[str]:
        noise = np.atleast_1d(self.noise_arcsec)
        noise_line = "noise_arcsec=" + ",".join(f"{v:g}" for v in noise)
        if noise.size > 1:
            noise_line += " (dpsi,dtheta,dgamma)"
        if self.noise_spread != 1:
            noise_line += (
                f" noise_spread={self.noise_spread:g} (each row's sigma drawn log-uniform in "
                "[sigma/spread, sigma*spread])"
            )
        schedule = "schedule: " + self.schedule.describe(self.data.n_joints)
        return ["simulated by turntable-pin simulate", f"seed={self.seed}", noise_line, schedule]

    def _truth(self) -> list[str]:
        errors = ", ".join(f"{k}={v:.6g}" for k, v in self.errors.items() if not k.endswith("_mm"))
        effects = "; ".join(
            f"{name}: " + ", ".join(f"{p}={v:.6g}" for p, v in params.items())
            for name, params in self.effects.items()
        )
        return [f"errors (arcsec): {errors}", f"hidden effects: {effects or 'none'}"]

    def to_dict(self) -> dict:
        """The simulation as a JSON-ready dict: the seed, noise and schedule, the truth (errors
        and effects in user units) and the data (:meth:`OrientationMeasurements.to_dict`)."""
        return {
            "seed": self.seed,
            "noise_arcsec": self.noise_arcsec,
            "noise_spread": self.noise_spread,
            "schedule": self.schedule.describe(self.data.n_joints),
            "errors": dict(self.errors),
            "effects": {name: dict(params) for name, params in self.effects.items()},
            "data": self.data.to_dict(),
        }

    def columns(self, *, with_sigma: bool = True) -> dict[str, np.ndarray]:
        """The CSV's columns (``docs/measurements.md``); the sigma columns only ``with_sigma``."""
        columns = self.data.columns()
        if not with_sigma:
            for name in ("sigma_arcsec", "sigma_dpsi_arcsec", "sigma_dtheta_arcsec",
                         "sigma_dgamma_arcsec"):  # fmt: skip
                columns.pop(name, None)
        return columns


def _angle_names(names: Sequence[str]) -> tuple[str, ...]:
    """``names`` checked to be measured angles, leaving at least one measured."""
    names = tuple(dict.fromkeys(names))
    unknown = [a for a in names if a not in ANGLE_NAMES]
    if unknown:
        raise InputError(
            f"not_measured: unknown angle '{unknown[0]}'; the angles: {', '.join(ANGLE_NAMES)}"
        )
    if len(names) == len(ANGLE_NAMES):
        raise InputError("not_measured: a row needs at least one measured angle")
    return names


def simulate_measurements(
    errors: TurntableErrors | np.ndarray | None = None,
    effects: Mapping[str, Mapping[str, float]] | None = None,
    *,
    schedule: Schedule | None = None,
    noise_arcsec: float | Sequence[float] = 1.0,
    seed: int = 0,
    turntable=None,
    catalogue: Sequence[Effect] = (),
    noise_spread: float = 1.0,
    not_measured: Sequence[str] = (),
) -> SimulatedMeasurements:
    """Simulate a measurement run.

    Args:
        errors: the table's error vector (rad, m) in its ``parameter_names`` order (the paper's
            ``TurntableErrors`` on the paper's table); default none.
        effects: ``{effect: {parameter: value in the effect's user unit}}`` (arcsec, arcsec/g,
            arcsec/h; parameters not given are zero).
        schedule: positions, order, time and approach directions (default: 30-degree grid).
        noise_arcsec: 1-sigma Gaussian noise of each angle, in ``[MIN_SIGMA_ARCSEC,
            MAX_NOISE_ARCSEC]`` (the file must read back); three numbers: one per angle
            (written as ``sigma_<angle>_arcsec``).
        seed: seed of every random choice (order, directions, noise), 0 <= seed < 2**63.
        turntable: the table (a ``GenericTable``; ``None``: the paper's).
        catalogue: effects besides the table's catalogue that ``effects`` may name (the user's).
        noise_spread: F >= 1: each row's sigma is ``noise_arcsec`` times a factor drawn
            log-uniform in [1/F, F] (seeded, after the noise), within the noise range; 1: even.
        not_measured: angles left empty at every position (``dgamma`` for a pointing run or an
            autocollimator's two tilts); without ``dgamma`` a row's ``dpsi`` is the payload x
            axis' own component (``-dR[2,0]``, docs/measurements.md section 1).

    Raises:
        InputError: an effect without parameters or beyond ``MAX_EFFECT_VALUE`` in its user
            unit; a run longer than ``MAX_TIME_S``; angles beyond what a measurement file may
            hold (``MAX_MEASURED_ANGLE_ARCSEC``).
    """
    noise = _checked_noise(noise_arcsec, noise_spread)
    seed = check_seed(seed)
    source = paper_table() if turntable is None else getattr(turntable, "table", turntable)
    table = measured_table(source)
    if isinstance(errors, TurntableErrors):
        errors = errors.as_array()
    vector = np.zeros(len(source.parameter_names)) if errors is None else np.asarray(errors, float)
    schedule = schedule or Schedule()
    rng = np.random.default_rng(seed)
    rows = schedule.rows(rng, source)
    blank = [ANGLE_NAMES.index(a) for a in _angle_names(not_measured)]
    variables = PositionVariables.of(
        rows, boresight_only=np.full(len(rows), 2 in blank and 0 not in blank)
    )
    model, params, effects = planted_model(source, vector, effects, variables, catalogue, "effect")
    truth = model.predict(params)
    measured, sigma_rad = _noisy(truth, noise, noise_spread, rng)
    measured[:, blank] = np.nan
    _refuse_beyond_a_file(measured)
    data = OrientationMeasurements(
        variables.joint_rad, measured, sigma_rad, rows.time_s, rows.dirs,
        source=f"simulated (seed {seed})", joint_names=table.data_joint_names,
    )  # fmt: skip
    return SimulatedMeasurements(
        data=data,
        errors=source.to_user_units(vector),
        effects=effects,
        noise_arcsec=float(noise[0]) if noise.size == 1 else tuple(float(v) for v in noise),
        seed=int(seed),
        schedule=schedule,
        truth_rad=truth,
        noise_spread=float(noise_spread),
    )


def _refuse_beyond_a_file(measured: np.ndarray) -> None:
    """Refuse simulated angles (rad) beyond what a measurement file may hold."""
    largest = float(np.nanmax(np.abs(measured))) * ARCSEC_PER_RAD
    if not largest <= MAX_MEASURED_ANGLE_ARCSEC:
        raise InputError(
            f"the simulated orientation errors reach {largest:g} arcsec, beyond the "
            f"+-{MAX_MEASURED_ANGLE_ARCSEC:g} arcsec a measurement may have "
            "(docs/measurements.md); give smaller errors, effect parameters or noise"
        )


def _checked_noise(noise_arcsec, noise_spread: float) -> np.ndarray:
    """``noise_arcsec`` as an array of one or three sigmas, arcsec, each in [MIN_SIGMA_ARCSEC,
    MAX_NOISE_ARCSEC] however ``noise_spread`` spreads it."""
    noise = checked_noise(
        noise_arcsec, "noise_arcsec", (3, "three"), MIN_SIGMA_ARCSEC, MAX_NOISE_ARCSEC
    )
    if not 1.0 <= noise_spread <= MAX_NOISE_SPREAD:
        raise InputError(f"noise_spread must be in [1, {MAX_NOISE_SPREAD:g}], got {noise_spread:g}")
    if (
        noise.min() / noise_spread < MIN_SIGMA_ARCSEC
        or noise.max() * noise_spread > MAX_NOISE_ARCSEC
    ):
        raise InputError(
            f"noise_spread {noise_spread:g}: the sigmas would leave [{MIN_SIGMA_ARCSEC:g}, "
            f"{MAX_NOISE_ARCSEC:g}] arcsec (noise_arcsec / spread .. noise_arcsec * spread)"
        )
    return noise


def _noisy(truth: np.ndarray, noise: np.ndarray, noise_spread: float, rng) -> tuple:
    """``truth`` (n, 3) rad plus Gaussian noise of ``noise`` arcsec (one sigma, or one per
    angle; spread log-uniformly over the rows by ``noise_spread``), and the sigma of each row,
    rad: (n,) for one sigma, else (n, 3)."""
    n = truth.shape[0]
    if noise.size == 1 and noise_spread == 1:
        sigma_rad = float(noise[0]) / ARCSEC_PER_RAD
        return truth + rng.normal(0.0, sigma_rad, truth.shape), np.full(n, sigma_rad)
    unit = rng.standard_normal(truth.shape)
    factor = np.ones((n, 1))
    if noise_spread != 1:
        factor = np.exp(rng.uniform(-1.0, 1.0, (n, 1)) * math.log(noise_spread))
    sigma_rad = factor * noise[None, :] / ARCSEC_PER_RAD  # (n, 1) or (n, 3)
    measured = truth + unit * sigma_rad
    sigma_rad = np.broadcast_to(sigma_rad, (n, noise.size)).copy()
    return measured, sigma_rad[:, 0] if noise.size == 1 else sigma_rad

"""Simulated orientation measurements: turntable errors, hidden effects, a schedule, noise, a seed.

Users rehearse a measurement campaign with it and the tests make data with known, hidden effects.
The truth goes through the same exact chain the fit uses (:class:`OrientationModel`), with the
chosen effect parameters; noise is Gaussian with the stated sigma on each of the three angles.
The output is the CSV of ``docs/measurements.md`` with the seed and the truth in comment lines.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..core.csv_table import write_csv_table
from ..core.exceptions import InputError, check_seed
from ..core.sizes import MAX_SIMULATED_ROWS, check_count, turn_grid_count
from ..core.units import ARCSEC_PER_RAD, DEG_PER_RAD
from ..model.errors import ANGULAR_ERROR_NAMES, TurntableErrors
from .catalogue import resolve_effect
from .data import (
    MAX_MEASURED_ANGLE_ARCSEC,
    MAX_TIME_S,
    MIN_SIGMA_ARCSEC,
    OrientationMeasurements,
)
from .effect_model import OrientationModel
from .effects.base import Effect, PositionVariables
from .table import measured_table

__all__ = [
    "ROW_BYTES",
    "APPROACHES",
    "MAX_NOISE_ARCSEC",
    "ORDERS",
    "Schedule",
    "SimulatedMeasurements",
    "simulate_measurements",
]

ORDERS = ("grid", "random")
"""Measurement orders a :class:`Schedule` knows."""
APPROACHES = ("random", "motion", "positive")
"""Approach-direction rules a :class:`Schedule` knows."""

MAX_NOISE_ARCSEC = MAX_MEASURED_ANGLE_ARCSEC / 10.0
"""Largest simulated noise sigma, arc seconds (1800, half a degree): a tenth of the largest angle
a measurement file may hold, so that noise alone never makes a file that cannot be read back."""

ROW_BYTES = 1024
"""Memory a simulated row costs while it is built and written (rough upper bound), bytes."""


@dataclass(frozen=True)
class Schedule:
    """Which positions are measured, in which order, when, and from which side.

    Attributes:
        phi1_step_deg, phi2_step_deg, phi3_step_deg: grid steps of each joint (a table with
            fewer joints ignores the others); the grid covers [start, start + 360).
        phi1_start_deg, phi2_start_deg, phi3_start_deg: first grid angles.
        order: ``grid`` (phi1 outer loop, the last joint's angle inner loop) or ``random``
            (shuffled).
        repeats: how many times each position is measured.
        dwell_s: time between consecutive measurements.
        approach: ``random`` (each axis from a random side), ``motion`` (the side the move from the
            previous position came from; unchanged when the axis did not move) or ``positive``.
    """

    phi1_step_deg: float = 30.0
    phi2_step_deg: float = 30.0
    phi1_start_deg: float = 0.0
    phi2_start_deg: float = 0.0
    phi3_step_deg: float = 30.0
    phi3_start_deg: float = 0.0
    order: str = "grid"
    repeats: int = 1
    dwell_s: float = 60.0
    approach: str = "random"

    def __post_init__(self) -> None:
        for name in ("phi1_step_deg", "phi2_step_deg", "phi3_step_deg"):
            step = getattr(self, name)
            if not 0 < step <= 360:
                raise InputError(f"{name} must be in (0, 360], got {step:g}")
        if self.order not in ORDERS:
            raise InputError(f"order must be one of {', '.join(ORDERS)}, got '{self.order}'")
        if self.approach not in APPROACHES:
            raise InputError(f"approach must be one of {', '.join(APPROACHES)}")
        if self.repeats < 1:
            raise InputError(f"repeats must be >= 1, got {self.repeats}")
        check_count(
            float(turn_grid_count(self.phi1_step_deg))
            * turn_grid_count(self.phi2_step_deg)
            * self.repeats,
            MAX_SIMULATED_ROWS,
            "rows of simulated measurements",
            ROW_BYTES,
        )
        if self.dwell_s <= 0:
            raise InputError(f"dwell_s must be > 0, got {self.dwell_s:g}")

    def _steps(self, n_joints: int) -> list[tuple[float, float]]:
        return [
            (getattr(self, f"phi{k}_start_deg"), getattr(self, f"phi{k}_step_deg"))
            for k in range(1, n_joints + 1)
        ]

    def count(self, n_joints: int = 2) -> int:
        """Number of measurements on a table with ``n_joints`` joints."""
        out = self.repeats
        for _, step in self._steps(n_joints):
            out *= turn_grid_count(step)
        return int(out)

    def duration_s(self, n_joints: int = 2) -> float:
        """Time from the first to the last measurement, seconds (``time_s`` of the last row)."""
        return (self.count(n_joints) - 1) * float(self.dwell_s)

    def positions_deg(self, rng: np.random.Generator, n_joints: int = 2) -> tuple[np.ndarray, ...]:
        """Commanded joint angles (phi1, phi2, ...) in degrees, in measurement order."""
        axes = [start + np.arange(0.0, 360.0 - 1e-9, step) for start, step in self._steps(n_joints)]
        grids = np.meshgrid(*axes, indexing="ij")
        out = [np.tile(g.ravel(), self.repeats) for g in grids]
        if self.order == "random":
            perm = rng.permutation(out[0].size)
            out = [a[perm] for a in out]
        return tuple(out)

    def directions(self, phi_deg: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """Approach direction (+1 / -1) of one axis at each measurement."""
        if self.approach == "positive":
            return np.ones(phi_deg.size)
        if self.approach == "random":
            return rng.choice([-1.0, 1.0], size=phi_deg.size)
        out = np.ones(phi_deg.size)
        for i in range(1, phi_deg.size):
            move = phi_deg[i] - phi_deg[i - 1]
            out[i] = out[i - 1] if move == 0 else np.sign(move)
        return out


@dataclass(frozen=True)
class SimulatedMeasurements:
    """Simulated data and the truth behind it.

    Attributes:
        data: the measurements (with sigma, time and directions).
        errors: the turntable errors used (the paper's ``TurntableErrors``, or ``{name: value in
            user units}`` of another table: ``<error>_arcsec``, ``<offset>_mm``).
        effects: ``{effect: {parameter: value in user units}}`` hidden in the data.
        noise_arcsec: the noise sigma.
        seed: the random seed.
        schedule: the :class:`Schedule` measured.
        truth_rad: noise-free ``dpsi, dtheta, dgamma`` (N, 3).
    """

    data: OrientationMeasurements
    errors: TurntableErrors | dict[str, float]
    effects: dict[str, dict[str, float]]
    noise_arcsec: float
    seed: int
    schedule: Schedule
    truth_rad: np.ndarray = field(repr=False)

    def comment(self, *, hide_truth: bool = False) -> str:
        """The comment lines written above the CSV header.

        With ``hide_truth`` only the seed, noise and schedule are written, not the errors and the
        hidden effects, so that the file can be used to rehearse a blind diagnosis.
        """
        user = self.errors.to_user_units() if hasattr(self.errors, "to_user_units") else self.errors
        errors = ", ".join(f"{k}={v:.6g}" for k, v in user.items() if not k.endswith("_mm"))
        effects = "; ".join(
            f"{name}: " + ", ".join(f"{p}={v:.6g}" for p, v in params.items())
            for name, params in self.effects.items()
        )
        s = self.schedule
        lines = [
            "simulated by turntable-pin simulate",
            f"seed={self.seed}",
            f"noise_arcsec={self.noise_arcsec:g}",
            "schedule: "
            + " ".join(
                f"phi{k}_step_deg={getattr(s, f'phi{k}_step_deg'):g}"
                for k in range(1, self.data.n_joints + 1)
            )
            + f" order={s.order} repeats={s.repeats} dwell_s={s.dwell_s:g} "
            f"approach={s.approach}",
        ]
        if hide_truth:
            return "\n".join([*lines, "errors and hidden effects: not recorded (--hide-truth)"])
        return "\n".join(
            [*lines, f"errors (arcsec): {errors}", f"hidden effects: {effects or 'none'}"]
        )

    def write_csv(
        self, path: str | Path, *, with_sigma: bool = True, hide_truth: bool = False
    ) -> Path:
        """Write the CSV of ``docs/measurements.md`` atomically, seed (and truth) as comments."""
        columns = self.data.columns()
        if not with_sigma:
            columns.pop("sigma_arcsec", None)
        return write_csv_table(path, columns, comment=self.comment(hide_truth=hide_truth))


def simulate_measurements(
    errors: TurntableErrors | np.ndarray | None = None,
    effects: Mapping[str, Mapping[str, float]] | None = None,
    *,
    schedule: Schedule | None = None,
    noise_arcsec: float = 1.0,
    seed: int = 0,
    turntable=None,
    catalogue: Sequence[Effect] = (),
) -> SimulatedMeasurements:
    """Simulate a measurement run.

    Args:
        errors: turntable errors (default none): the paper's ``TurntableErrors``, or for another
            table its error vector (rad, m) in ``GenericTable.parameter_names`` order.
        effects: ``{effect name: {parameter name: value in user units}}`` (parameters not given
            are zero; units are the effect's, e.g. arcsec, arcsec/g, arcsec/h).
        schedule: positions, order, time and approach directions (default: 30-degree grid).
        noise_arcsec: 1-sigma Gaussian noise on each angle (in ``[MIN_SIGMA_ARCSEC,
            MAX_NOISE_ARCSEC]``: the file must read back).
        seed: seed of every random choice (order, directions, noise): a whole number
            0 <= seed < 2**63.

    Every effect needs at least one parameter, each within ``+-MAX_MEASURED_ANGLE_ARCSEC`` in its
    user unit; the run may last at most ``MAX_TIME_S`` and the simulated angles must stay within
    what a measurement file may hold, or :class:`InputError` says which.
        turntable: the table (``GenericTable``, ``TurntableModel`` or ``None``: the paper's).
        catalogue: effects besides the table's catalogue that ``effects`` may name (the user's).
    """
    limit = MAX_MEASURED_ANGLE_ARCSEC
    if not noise_arcsec > 0:
        raise InputError(f"noise_arcsec must be > 0, got {noise_arcsec:g}")
    if not MIN_SIGMA_ARCSEC <= noise_arcsec <= MAX_NOISE_ARCSEC:
        raise InputError(
            f"noise_arcsec must be in [{MIN_SIGMA_ARCSEC:g}, {MAX_NOISE_ARCSEC:g}], got "
            f"{noise_arcsec:g}"
        )
    seed = check_seed(seed)
    table = measured_table(turntable)
    n_joints = table.n_joints
    if table.paper:
        errors = errors or TurntableErrors.zero()
        base_values = dict(zip(ANGULAR_ERROR_NAMES, errors.angular_array_rad(), strict=True))
    else:
        vector = np.zeros(len(turntable.parameter_names)) if errors is None else errors
        vector = np.asarray(vector, dtype=float)
        errors = turntable.to_user_units(vector)
        base_values = {
            n: v for n, v in zip(turntable.parameter_names, vector, strict=True)
            if n in table.base_names
        }  # fmt: skip
    schedule = schedule or Schedule()
    check_count(schedule.count(n_joints), MAX_SIMULATED_ROWS, "rows of simulated measurements",
                ROW_BYTES)  # fmt: skip
    effects = {name: dict(params) for name, params in (effects or {}).items()}
    for name, params in effects.items():
        if not params:
            raise InputError(
                f"effect '{name}' is given without parameters, so it would simulate nothing; "
                "give at least one"
            )
        for pname, value in params.items():
            try:
                number = float(value)
            except (TypeError, ValueError):
                number = math.nan
            if not abs(number) <= limit:
                raise InputError(
                    f"effect '{name}', parameter '{pname}' = {value!r}: must be a number within "
                    f"+-{limit:g} (in its user unit: arcsec, arcsec/g or arcsec/h)"
                )
    rng = np.random.default_rng(seed)
    angles_deg = schedule.positions_deg(rng, n_joints)
    n = angles_deg[0].size
    if schedule.duration_s(n_joints) > MAX_TIME_S:
        raise InputError(
            f"dwell_s {schedule.dwell_s:g}: the run of {n} measurements would last "
            f"{schedule.duration_s(n_joints):.7g} s, more than {MAX_TIME_S:.7g} s (a year)"
        )
    variables = PositionVariables(
        np.stack(angles_deg, axis=1) / DEG_PER_RAD,
        time_s=np.arange(n) * schedule.dwell_s,
        dirs=tuple(schedule.directions(a, rng) for a in angles_deg),
    )
    effect_objects = [resolve_effect(name, table, catalogue) for name in effects]
    effects = {e.name: effects[name] for e, name in zip(effect_objects, effects, strict=True)}
    model = OrientationModel(variables, effect_objects, table)
    values = dict(base_values)
    for effect in effect_objects:
        specs = {s.name: s for s in effect.parameters(variables)}
        for pname, value in effects[effect.name].items():
            if pname not in specs:
                raise InputError(
                    f"effect '{effect.name}' has no parameter '{pname}'; "
                    f"its parameters: {', '.join(specs)}"
                )
            values[f"{effect.name}.{pname}"] = float(value) * specs[pname].per_user_unit
    truth = model.predict(model.parameter_vector(values))
    sigma_rad = noise_arcsec / ARCSEC_PER_RAD
    measured = truth + rng.normal(0.0, sigma_rad, truth.shape)
    largest = float(np.max(np.abs(measured))) * ARCSEC_PER_RAD
    if not largest <= limit:
        raise InputError(
            f"the simulated orientation errors reach {largest:g} arcsec, beyond the +-{limit:g} "
            "arcsec a measurement may have (docs/measurements.md); give smaller errors, effect "
            "parameters or noise"
        )
    data = OrientationMeasurements(
        joint_rad=variables.joint_rad,
        angles_rad=measured,
        sigma_rad=np.full(n, sigma_rad),
        time_s=variables.time_s,
        dirs=variables.dirs,
        source=f"simulated (seed {seed})",
        joint_names=() if table.paper else table.joint_names,
    )
    return SimulatedMeasurements(
        data=data,
        errors=errors,
        effects=effects,
        noise_arcsec=float(noise_arcsec),
        seed=int(seed),
        schedule=schedule,
        truth_rad=truth,
    )

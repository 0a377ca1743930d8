"""Simulated GyroWheel calibration runs: table errors, instrument effects, noise, outliers, a seed.

The outputs follow the *exact* path, independent of any linearised model, so that they check
the run diagnosis' first-order columns:

- the table turns the payload by ``dR = Rd^T Rt``, the exact chain of its errors and effects
  (``measurement.effect_model.OrientationModel``);
- the GyroWheel sits turned by its mount ``M = exp([m]x)``, ``m = (mx, my, mz)`` about payload
  x, y, z, and senses (row vectors) ``a = a0 Rd dR M``, ``w = w0 Rd dR M`` (``a0 = (0, 0, 1) g``,
  ``w0`` the earth rate in F0: x north, y west, z up);
- channel c reads ``w_c + A_c(a) beta_c`` (eq. 1, Table 1 by default) plus what the run
  catalogue's instrument effects plant and Gaussian noise; a few seeded rows get a gross outlier.

The run CSV is what ``calibration.run.read_run`` reads, the seed, noise and positions (and unless
hidden the truth) in its ``#`` lines.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import yaml

from ..calibration.gyrowheel import AXES, GyroWheelModel, regressor_matrix
from ..calibration.positions import PositionSet, base_frame_inputs, position_inputs
from ..calibration.rate_error import orientation_error_rotation
from ..calibration.run import MAX_RUN_OUTPUT_DPH, MIN_RUN_SIGMA_DPH
from ..core.exceptions import InputError, check_seed
from ..core.files import write_text_atomic
from ..core.sizes import MAX_TIME_S
from ..core.units import ARCSEC_PER_RAD, deg_to_rad, rad_to_deg
from ..core.words import argument, command
from ..measurement.effects.base import PositionVariables
from ..measurement.simulated import (
    SimulatedFile,
    checked_column,
    checked_noise,
    checked_values,
    planted_model,
    run_times_s,
)
from ..model.angles import ANGLE_ENTRIES
from ..model.errors import MAX_ANGULAR_ERROR_DEG
from .effects import INSTRUMENT_EFFECTS, RunEffect
from .effects.base import Sensed
from .effects.mount import Mount
from .effects.temperature import TEMPERATURE_COLUMN

__all__ = [
    "DEFAULT_DWELL_S",
    "DEFAULT_OUTLIER_SIGMAS",
    "SIMULATED_INSTRUMENT_EFFECTS",
    "SimulatedRun",
    "TemperatureProfile",
    "simulate_calibration_run",
]

DEFAULT_DWELL_S = 60.0
"""Time per position when no ``time_s`` is given, s."""
DEFAULT_OUTLIER_SIGMAS = 30.0
"""Size of a gross outlier when ``outlier_dph`` is not given: this many sigma of its channel."""
SIMULATED_INSTRUMENT_EFFECTS: dict[str, RunEffect] = {c.name: c() for c in INSTRUMENT_EFFECTS}
"""The instrument effects a simulated run may plant, by name: the run catalogue's, each planting
what its :meth:`~.effects.base.RunEffect.planted_dph` says (a mount turns what is sensed)."""


def _checked_instrument(instrument) -> dict[str, dict[str, float]]:
    """``{effect: {parameter: value}}`` of :data:`SIMULATED_INSTRUMENT_EFFECTS`, each checked
    (``checked_values``, within the effect's ``limit``) and every parameter filled (zero when not
    given); InputError for an unknown name, listing the known ones."""
    out: dict[str, dict[str, float]] = {}
    for name, params in dict(instrument or {}).items():
        effect = SIMULATED_INSTRUMENT_EFFECTS.get(str(name))
        if effect is None:
            raise InputError(
                f"unknown instrument effect '{name}'; instrument effects: "
                f"{', '.join(SIMULATED_INSTRUMENT_EFFECTS)}"
            )
        specs = {s.name: s for s in effect.parameters(None)}
        values = dict.fromkeys(specs, 0.0)
        values.update(checked_values("instrument effect", name, params, specs, effect.limit))
        out[effect.name] = values
    return out


@dataclass(frozen=True)
class TemperatureProfile:
    """A temperature history, degC, ``t`` in s since the start: ``T(t) = start_c + ramp_c_per_h
    t / 3600 + swing_c sin(2 pi t / (period_h 3600))``."""

    start_c: float
    ramp_c_per_h: float = 0.0
    swing_c: float = 0.0
    period_h: float = 1.0

    def __post_init__(self) -> None:
        for name, value in asdict(self).items():
            if not (isinstance(value, (int, float)) and math.isfinite(value)):
                raise InputError(f"temperature profile: {name} must be a finite number")
        if not -100.0 <= self.start_c <= 200.0:
            raise InputError(f"temperature profile: start {self.start_c:g} degC is no lab")
        if not abs(self.ramp_c_per_h) <= 100.0 or not abs(self.swing_c) <= 100.0:
            raise InputError("temperature profile: ramp and swing must be within +-100 degC")
        if not self.period_h > 0:
            raise InputError(f"temperature profile: period_h must be > 0, got {self.period_h:g}")

    def at(self, time_s) -> np.ndarray:
        """The temperature (degC) at ``time_s`` (s)."""
        t = np.asarray(time_s, dtype=float)
        phase = 2.0 * np.pi * t / (self.period_h * 3600.0)
        return self.start_c + self.ramp_c_per_h * t / 3600.0 + self.swing_c * np.sin(phase)

    def to_dict(self) -> dict[str, float]:
        """The four numbers by name."""
        return {name: float(value) for name, value in asdict(self).items()}


@dataclass(frozen=True)
class SimulatedRun(SimulatedFile):
    """A simulated calibration run and the truth behind it.

    Attributes:
        positions: the commanded positions (and the table); latitude_rad: the site's, rad.
        outputs_dph: (N, 2) ``out_x, out_y`` as measured; exact_outputs_dph: without noise and
            outliers, deg/h; noise_dph: ``(sigma_x, sigma_y)``, deg/h.
        time_s: (N,) s since the start; temperature_c: (N,) degC, or ``None``.
        truth: what made the run, JSON-ready (errors in arcsec, effects in their user units).
        seed: the random seed.
    """

    positions: PositionSet = field(repr=False, compare=False)
    latitude_rad: float
    outputs_dph: np.ndarray = field(repr=False)
    exact_outputs_dph: np.ndarray = field(repr=False)
    noise_dph: tuple[float, float]
    time_s: np.ndarray = field(repr=False)
    temperature_c: np.ndarray | None = field(repr=False)
    truth: dict = field(repr=False)
    seed: int

    @property
    def n_positions(self) -> int:
        """Number of positions (rows) N."""
        return len(self.positions)

    def columns(self, *, with_sigma: bool = True) -> dict[str, np.ndarray]:
        """The run CSV's columns: ``phiK_deg``, ``out_x_dph, out_y_dph``, ``sigma_dph`` (with
        ``with_sigma``, both channels' noise equal and > 0), ``time_s``, ``temperature_c``."""
        angles = rad_to_deg(self.positions.angles_rad).T
        out: dict[str, np.ndarray] = {f"phi{k}_deg": a for k, a in enumerate(angles, start=1)}
        out["out_x_dph"] = self.outputs_dph[:, 0]
        out["out_y_dph"] = self.outputs_dph[:, 1]
        sx, sy = self.noise_dph
        if with_sigma and sx == sy and sx >= MIN_RUN_SIGMA_DPH:
            out["sigma_dph"] = np.full(self.n_positions, sx)
        out["time_s"] = self.time_s
        if self.temperature_c is not None:
            out["temperature_c"] = self.temperature_c
        return out

    _hidden = "coefficients, table errors, effects and outliers"

    def _made(self) -> list[str]:
        truth = self.truth
        lines = [
            f"simulated GyroWheel calibration run ({command('simulate', run=True)})",
            f"seed={self.seed}",
            "noise_dph={:g},{:g} (x,y)".format(*self.noise_dph),
            f"positions: {truth['positions']} ({truth['n_positions']}), table {truth['table']}, "
            f"latitude {truth['latitude_deg']:g} deg",
        ]
        if truth.get("temperature_profile"):
            profile = truth["temperature_profile"]
            lines.append(
                "temperature_c: profile start {start_c:g} degC, ramp {ramp_c_per_h:g} degC/h, "
                "swing {swing_c:g} degC, period {period_h:g} h".format(**profile)
            )
        return lines

    def _truth(self) -> list[str]:
        return ["truth: " + json.dumps(self.truth, sort_keys=False)]

    def write_truth(self, path: str | Path, *, data: str = "", command: str = "") -> Path:
        """Write the truth as YAML, atomically (with the run file ``data`` and the ``command``
        that made it)."""
        head = {"data": data or None, "command": command or None}
        body = {k: v for k, v in head.items() if v is not None} | self.truth
        title = f"# The truth behind {data}.\n" if data else "# The truth behind a simulated run.\n"
        text = yaml.safe_dump(body, sort_keys=False, default_flow_style=None, width=100)
        return write_text_atomic(path, title + text)


def _checked_errors(table, table_errors_rad: Mapping[str, float]):
    """The table's error vector (rad, m) and its non-zero errors in user units, each checked."""
    limit_rad = deg_to_rad(MAX_ANGULAR_ERROR_DEG)
    vector = table.values(dict(table_errors_rad or {}))
    for name, value in zip(table.parameter_names, vector, strict=True):
        if not math.isfinite(value):
            raise InputError(f"table error '{name}' must be a finite number, got {value!r}")
        if name in table.angular_names and abs(value) > limit_rad:
            raise InputError(
                f"table error '{name}' = {value:g} rad is no small error: it must be within "
                f"+-{MAX_ANGULAR_ERROR_DEG:g} deg"
            )
    return vector, {k: v for k, v in table.to_user_units(vector).items() if v != 0.0}


def _table_rotation_errors(
    positions: PositionSet,
    table_errors_rad: Mapping[str, float],
    table_effects: Mapping[str, Mapping[str, float]],
    time_s: np.ndarray,
    catalogue: Sequence,
) -> tuple[np.ndarray, dict[str, float], dict[str, dict[str, float]]]:
    """``dR`` (N, 3, 3) of the exact chain, the errors in user units (non-zero ones) and the
    effects by their catalogue names."""
    table = positions.table
    vector, errors = _checked_errors(table, table_errors_rad)
    angles = positions.angles_rad
    if not table_effects:
        return table.rotation_error(vector, list(angles.T)), errors, {}
    variables = PositionVariables(np.array(angles), time_s=np.array(time_s))
    lacks = "a simulated calibration run does not have (it has time_s only)"
    model, params, effects = planted_model(
        table, vector, table_effects, variables, catalogue, "table effect", lacks
    )
    rotation = model.rotation_error(params)
    # Terms a (user) effect adds to a measured angle itself, outside the chain, turn the payload
    # by that much more.
    predicted = model.predict(params)
    added = predicted - np.stack([rotation[:, i, j] for i, j in ANGLE_ENTRIES], axis=1)
    if np.any(added != 0.0):
        rotation = rotation @ orientation_error_rotation(*added.T, exact=True)
    return rotation, errors, effects


def simulate_calibration_run(
    positions: PositionSet,
    latitude_rad: float,
    *,
    gyrowheel: GyroWheelModel | None = None,
    table_errors_rad: Mapping[str, float] | None = None,
    table_effects: Mapping[str, Mapping[str, float]] | None = None,
    instrument: Mapping[str, Mapping[str, float]] | None = None,
    noise_dph: float | Sequence[float] = (0.0, 0.0),
    time_s=None,
    dwell_s: float = DEFAULT_DWELL_S,
    temperature_c=None,
    outliers: int = 0,
    outlier_dph: float | None = None,
    seed: int = 0,
    catalogue: Sequence = (),
) -> SimulatedRun:
    """Simulate a GyroWheel calibration run along the exact path (module docstring).

    Args:
        positions: the commanded positions; ``positions.table`` is the table.
        latitude_rad: latitude of the test site, rad.
        gyrowheel: the true drift coefficients (default paper Table 1).
        table_errors_rad: ``{error: value}`` of the table's ``parameter_names`` (rad; m for
            offsets, which turn nothing); missing errors are zero.
        table_effects: ``{effect: {parameter: value in its user unit}}``, e.g.
            ``{"inner_wobble_harmonics": {"x_c1": 15}}`` (arcsec).
        instrument: instrument effects ``{effect: {parameter: value}}`` of
            :data:`SIMULATED_INSTRUMENT_EFFECTS` in their units.
        noise_dph: 1-sigma Gaussian noise of ``out_x, out_y`` (one number for both), deg/h.
        time_s: (N,) time of each row, s; default ``index * dwell_s`` in measurement order.
        dwell_s: time per position when ``time_s`` is not given, s.
        temperature_c: (N,) degC, or a :class:`TemperatureProfile` (at ``time_s``), or None.
        outliers: number of rows (a seeded pick) given a gross error on one channel.
        outlier_dph: size of that error, deg/h, sign seeded (default 30 sigma of the channel).
        seed: seed of the noise and the outliers (noise drawn first), 0 <= seed < 2**63.
        catalogue: user effects besides the table's catalogue that ``table_effects`` may name.

    Raises:
        InputError: an unknown name (naming the known ones), a value out of range, a
            temperature coefficient without a temperature, too many outliers.
    """
    seed = check_seed(seed)
    gyrowheel = GyroWheelModel.nominal() if gyrowheel is None else gyrowheel
    sigma = checked_noise(noise_dph, "noise_dph", (2, "two (x, y)"), 0.0, MAX_RUN_OUTPUT_DPH / 100)
    sigma = tuple(float(v) for v in np.broadcast_to(sigma, (2,)))
    instrument = _checked_instrument(instrument)
    n = len(positions)
    time_given = time_s is not None
    time_s = run_times_s(n, dwell_s) if time_s is None else time_s
    time_s = checked_column(time_s, n, "time_s", 0.0, MAX_TIME_S)
    profile, temperature_c = _temperatures(temperature_c, time_s, instrument)
    outliers = _checked_outliers(outliers, outlier_dph, n, sigma)
    table_dR, errors, effects = _table_rotation_errors(
        positions, table_errors_rad or {}, table_effects or {}, time_s, catalogue
    )
    force, rate = _sensed(positions, latitude_rad, table_dR, instrument)
    exact = _exact_outputs(Sensed(force, rate, time_s, temperature_c), gyrowheel, instrument)
    measured, outlier_rows = _measured(exact, sigma, seed, outliers, outlier_dph)
    truth = {
        **_run_truth(positions, latitude_rad, seed, sigma, time_given, dwell_s, gyrowheel),
        "table_errors": errors,
        "table_effects": effects,
        **_instrument_truth(instrument),
        "temperature_profile": None if profile is None else profile.to_dict(),
        "outliers": outlier_rows,
    }
    exact.setflags(write=False)
    measured.setflags(write=False)
    return SimulatedRun(
        positions=positions,
        latitude_rad=float(latitude_rad),
        outputs_dph=measured,
        exact_outputs_dph=exact,
        noise_dph=sigma,
        time_s=time_s,
        temperature_c=temperature_c,
        truth=truth,
        seed=seed,
    )


def _run_truth(positions, latitude_rad, seed, sigma, time_given, dwell_s, gyrowheel) -> dict:
    """The truth's head: the simulator, the seed, the table, positions, site, noise, time and the
    drift coefficients."""
    return {
        "simulator": "turntable_pin.instrument.simulate_calibration_run",
        "seed": seed,
        "table": positions.table.label,
        "positions": positions.name,
        "n_positions": len(positions),
        "latitude_deg": float(rad_to_deg(latitude_rad)),
        "noise_dph": {"x": sigma[0], "y": sigma[1]},
        "time": "given" if time_given else {"dwell_s": float(dwell_s)},
        "gyrowheel": {axis: gyrowheel.axis(axis).to_dict() for axis in AXES},
    }


def _instrument_truth(instrument) -> dict:
    """The instrument effects of the truth: their non-zero parameters and their units."""
    return {
        "instrument_effects": {
            k: {p: v for p, v in ps.items() if v} for k, ps in instrument.items()
        },
        "instrument_units": {
            k: SIMULATED_INSTRUMENT_EFFECTS[k].parameters(None)[0].unit for k in instrument
        },
    }


def _temperatures(temperature_c, time_s, instrument):
    """``(profile or None, temperature (N,) degC or None)``, checked; a temperature coefficient
    needs one."""
    profile = None
    if isinstance(temperature_c, TemperatureProfile):
        profile, temperature_c = temperature_c, temperature_c.at(time_s)
    if temperature_c is not None:
        temperature_c = checked_column(temperature_c, len(time_s), "temperature_c", -273.15, 1e3)
    column = TEMPERATURE_COLUMN  # the effects needing it say so
    needs = [k for k in instrument if column in SIMULATED_INSTRUMENT_EFFECTS[k].required_columns]
    if needs and temperature_c is None:
        raise InputError(
            f"instrument effect '{needs[0]}' needs a temperature: give "
            f"{argument('temperature_c')} (a start, a ramp per hour, a swing and its period)"
        )
    return profile, temperature_c


def _checked_outliers(outliers, outlier_dph, n: int, sigma) -> int:
    """The number of outlier rows, checked with their size."""
    outliers = int(outliers)
    if not 0 <= outliers <= n // 2:
        raise InputError(f"outliers: expected 0 .. {n // 2} rows of a run of {n}, got {outliers}")
    if outlier_dph is not None and not (math.isfinite(outlier_dph) and outlier_dph > 0):
        raise InputError(f"outlier_dph must be a number > 0, got {outlier_dph!r}")
    if outliers and outlier_dph is None and min(sigma) == 0.0:
        raise InputError("outliers of a noise-free run need their size: give outlier_dph")
    return outliers


def _sensed(positions, latitude_rad, table_dR, instrument):
    """The specific force (g) and earth rate (deg/h) the GyroWheel senses (N, 3) through the
    exact chain: the payload's rotation, the table's errors, the instrument's mount."""
    inputs = position_inputs(positions, latitude_rad)
    mount = {"mx": 0.0, "my": 0.0, "mz": 0.0}
    for name, values in instrument.items():
        if isinstance(SIMULATED_INSTRUMENT_EFFECTS[name], Mount):
            mount.update(values)
    m_rad = {k: v / ARCSEC_PER_RAD for k, v in mount.items()}
    mount_rotation = orientation_error_rotation(m_rad["my"], m_rad["mz"], m_rad["mx"], exact=True)
    chain = inputs.payload_rotation @ table_dR @ mount_rotation
    force0, rate0 = base_frame_inputs(latitude_rad)
    return np.einsum("i,nij->nj", force0, chain), np.einsum("i,nij->nj", rate0, chain)


def _exact_outputs(sensed: Sensed, gyrowheel, instrument) -> np.ndarray:
    """(N, 2) the noise-free outputs: eq. 1 at what is sensed, plus what the instrument effects
    plant."""
    rate, force = sensed.rate_dph, sensed.force_g
    exact = np.stack(
        [
            rate[:, c] + regressor_matrix(axis, force) @ gyrowheel.axis(axis).as_array()
            for c, axis in enumerate(AXES)
        ],
        axis=1,
    )
    for name, values in instrument.items():
        exact = exact + SIMULATED_INSTRUMENT_EFFECTS[name].planted_dph(values, sensed)
    return exact


def _measured(exact, sigma, seed: int, outliers: int, outlier_dph):
    """The outputs as measured (seeded noise, then outliers: :func:`_add_outliers`), checked
    against the range a run may hold, and the outliers' records."""
    rng = np.random.default_rng(seed)
    measured = exact + rng.standard_normal(exact.shape) * np.array(sigma)
    outlier_rows = _add_outliers(measured, rng, outliers, outlier_dph, sigma)
    largest = float(np.max(np.abs(measured)))
    if not largest <= MAX_RUN_OUTPUT_DPH:
        raise InputError(
            f"the simulated outputs reach {largest:g} deg/h, beyond the +-{MAX_RUN_OUTPUT_DPH:g} "
            "deg/h a run may hold; give smaller coefficients, effects or noise"
        )
    return measured, outlier_rows


def _add_outliers(measured, rng, outliers: int, outlier_dph, sigma) -> list[dict]:
    """Gross errors added in place to ``outliers`` seeded rows, one channel each; their records
    (``index``: the position, 0 = the first data row, whatever comment lines the CSV has)."""
    if not outliers:
        return []
    n = measured.shape[0]
    rows = np.sort(rng.choice(n, size=outliers, replace=False))
    channels = rng.integers(0, 2, outliers)
    signs = rng.choice(np.array([-1.0, 1.0]), outliers)
    out = []
    for row, channel, sign in zip(rows, channels, signs, strict=True):
        size = DEFAULT_OUTLIER_SIGMAS * sigma[channel] if outlier_dph is None else outlier_dph
        measured[row, channel] += sign * size
        record = {"index": int(row), "column": f"out_{AXES[channel]}_dph"}
        out.append({**record, "offset_dph": float(sign * size)})
    return out

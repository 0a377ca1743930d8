"""Simulated GyroWheel calibration runs: table errors, instrument effects, noise, outliers, a seed.

The outputs follow the *exact* path, independent of any linearised model, so that they check
the run diagnosis' first-order columns:

- the table turns the payload by ``dR = Rd^T Rt``: the exact chain of its errors, with table
  effects that of ``measurement.effect_model.OrientationModel``;
- the GyroWheel sits turned by its mount ``M = exp([m]x)``, ``m = (mx, my, mz)`` about payload
  x, y, z, and senses (row vectors) ``a = a0 Rd dR M``, ``w = w0 Rd dR M`` (``a0 = (0, 0, 1) g``,
  ``w0`` the earth rate in F0: x north, y west, z up);
- channel c reads ``(1 + s_c 1e-6) w_c + A_c(a) beta_c`` (eq. 1, Table 1 by default) plus the
  instrument effects (the run catalogue's names and units) and Gaussian noise; a few seeded rows
  get a gross outlier on one channel.

The run CSV is what ``calibration.run.read_run`` reads, with the seed, the noise and the
positions in ``#`` comment lines and, unless hidden, the truth.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from ..calibration.gyrowheel import AXES, MAX_COEFFICIENT_DPH, GyroWheelModel, regressor_matrix
from ..calibration.positions import PositionSet, base_frame_inputs, position_inputs
from ..calibration.rate_error import orientation_error_rotation
from ..calibration.run import MAX_RUN_OUTPUT_DPH, MIN_RUN_SIGMA_DPH
from ..core.csv_table import write_csv_table
from ..core.exceptions import InputError, check_seed
from ..core.files import write_text_atomic
from ..core.sizes import MAX_TIME_S
from ..core.units import ARCSEC_PER_RAD, deg_to_rad, rad_to_deg
from ..core.words import argument, command
from ..measurement.catalogue import resolve_effect
from ..measurement.effect_model import OrientationModel
from ..measurement.effects.base import PositionVariables
from ..measurement.simulation import effect_values
from ..measurement.table import measured_table
from ..model.angles import ANGLE_ENTRIES
from ..model.errors import MAX_ANGULAR_ERROR_DEG

__all__ = [
    "DEFAULT_DWELL_S",
    "DEFAULT_OUTLIER_SIGMAS",
    "SIMULATED_INSTRUMENT_EFFECTS",
    "MAX_RUN_TIME_S",
    "InstrumentEffect",
    "SimulatedRun",
    "TemperatureProfile",
    "check_instrument_effects",
    "simulate_calibration_run",
]

DEFAULT_DWELL_S = 60.0
"""Time per position when no ``time_s`` is given, s."""
DEFAULT_OUTLIER_SIGMAS = 30.0
"""Size of a gross outlier when ``outlier_dph`` is not given: this many sigma of its channel."""
MAX_RUN_TIME_S = MAX_TIME_S
"""Longest simulated run, s (a year): a run file's ``time_s`` is at most that
(:data:`~turntable_pin.core.sizes.MAX_TIME_S`)."""
_MOUNT_LIMIT_ARCSEC = MAX_ANGULAR_ERROR_DEG * 3600.0


@dataclass(frozen=True)
class InstrumentEffect:
    """One effect of the instrument itself on a simulated run: its ``name``, its
    ``parameter_names`` (zero when not given), the ``unit`` of all, the ``limit`` of a
    ``|value|`` in it, and a ``description`` (what it is, how it enters the outputs)."""

    name: str
    parameter_names: tuple[str, ...]
    unit: str
    limit: float
    description: str

    def parameters(self, variables=None) -> tuple:
        """The parameters (``name``, ``unit``) as ``parse_effect_spec`` reads them."""
        return tuple(_Parameter(n, self.unit) for n in self.parameter_names)


@dataclass(frozen=True)
class _Parameter:
    name: str
    unit: str


SIMULATED_INSTRUMENT_EFFECTS: dict[str, InstrumentEffect] = {
    e.name: e
    for e in (
        InstrumentEffect(
            "instrument_tilt", ("mx", "my"), "arcsec", _MOUNT_LIMIT_ARCSEC,
            "the GyroWheel tilted on the payload about payload x and y: with the heading, it "
            "senses a M and w M, M = exp([m]x), m = (mx, my, mz)",
        ),
        InstrumentEffect(
            "instrument_heading", ("mz",), "arcsec", _MOUNT_LIMIT_ARCSEC,
            "the GyroWheel turned on the payload about payload z (mz of the same M)",
        ),
        InstrumentEffect(
            "bias_drift", ("x", "y"), "deg/h per h", 1e3,
            "a bias that drifts linearly in time: out_c += d_c * time_s / 3600",
        ),
        InstrumentEffect(
            "temperature_coefficient", ("x", "y"), "deg/h/degC", 1e3,
            "a bias that follows the temperature: out_c += k_c * (T - mean(T)) "
            "(needs temperature_c)",
        ),
        InstrumentEffect(
            "earth_rate_scale", ("x", "y"), "ppm", 1e5,
            "a scale-factor error on the sensed rate: out_c = (1 + s_c 1e-6) w_c + drift",
        ),
        InstrumentEffect(
            "g_squared_terms", ("x_xz", "x_yz", "y_xz", "y_yz"), "deg/h/g^2",
            MAX_COEFFICIENT_DPH,
            "g^2 terms eq. 1 leaves out: out_x += x_xz ax az + x_yz ay az, "
            "out_y += y_xz ax az + y_yz ay az",
        ),
    )
}  # fmt: skip
"""The instrument effects a simulated run may hold, by name."""


def check_instrument_effects(
    instrument: Mapping[str, Mapping[str, float]],
) -> dict[str, dict[str, float]]:
    """``{effect: {parameter: value}}`` checked against :data:`SIMULATED_INSTRUMENT_EFFECTS`
    (known names, at least one parameter, finite values within the limit), every parameter
    filled (zero when not given); InputError otherwise, listing the known names."""
    out: dict[str, dict[str, float]] = {}
    for name, params in dict(instrument or {}).items():
        effect = SIMULATED_INSTRUMENT_EFFECTS.get(str(name))
        if effect is None:
            raise InputError(
                f"unknown instrument effect '{name}'; instrument effects: "
                f"{', '.join(SIMULATED_INSTRUMENT_EFFECTS)}"
            )
        if not isinstance(params, Mapping) or not params:
            raise InputError(
                f"instrument effect '{name}' needs at least one of its parameters "
                f"({', '.join(effect.parameter_names)}, {effect.unit})"
            )
        values = dict.fromkeys(effect.parameter_names, 0.0)
        for pname, value in params.items():
            if pname not in values:
                raise InputError(
                    f"instrument effect '{name}' has no parameter '{pname}'; its parameters: "
                    f"{', '.join(effect.parameter_names)} ({effect.unit})"
                )
            try:
                number = float(value)
            except (TypeError, ValueError):
                number = math.nan
            if isinstance(value, bool) or not abs(number) <= effect.limit:
                raise InputError(
                    f"instrument effect '{name}', parameter '{pname}' = {value!r}: must be a "
                    f"number within +-{effect.limit:g} {effect.unit}"
                )
            values[pname] = number
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
        for name in ("start_c", "ramp_c_per_h", "swing_c", "period_h"):
            value = getattr(self, name)
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
        return {
            "start_c": float(self.start_c),
            "ramp_c_per_h": float(self.ramp_c_per_h),
            "swing_c": float(self.swing_c),
            "period_h": float(self.period_h),
        }


@dataclass(frozen=True)
class SimulatedRun:
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

    def comment(self, *, hide_truth: bool = False) -> str:
        """The ``#`` lines above the CSV header: seed, noise, positions, the truth (a JSON line)."""
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
        if hide_truth:
            lines.append(
                "coefficients, table errors, effects and outliers: not recorded "
                f"({argument('hide_truth')})"
            )
        else:
            lines.append("truth: " + json.dumps(truth, sort_keys=False))
        return "\n".join(lines)

    def write_csv(
        self, path: str | Path, *, hide_truth: bool = False, with_sigma: bool = True
    ) -> Path:
        """Write the run CSV atomically with its :meth:`comment` lines."""
        return write_csv_table(
            path, self.columns(with_sigma=with_sigma), comment=self.comment(hide_truth=hide_truth)
        )

    def write_truth(self, path: str | Path, *, data: str = "", command: str = "") -> Path:
        """Write the truth as YAML, atomically (with the run file ``data`` and the ``command``
        that made it)."""
        head = {"data": data or None, "command": command or None}
        body = {k: v for k, v in head.items() if v is not None} | self.truth
        title = f"# The truth behind {data}.\n" if data else "# The truth behind a simulated run.\n"
        text = yaml.safe_dump(body, sort_keys=False, default_flow_style=None, width=100)
        return write_text_atomic(path, title + text)


def _noise(noise_dph) -> tuple[float, float]:
    values = np.atleast_1d(np.asarray(noise_dph, dtype=float))
    if values.size not in (1, 2):
        raise InputError(f"noise_dph takes one number or two (x, y), got {values.size}")
    values = np.broadcast_to(values, (2,))
    for value in values:
        if not 0.0 <= value <= MAX_RUN_OUTPUT_DPH / 100.0:
            raise InputError(
                f"noise_dph must be in [0, {MAX_RUN_OUTPUT_DPH / 100.0:g}] deg/h, got {value!r}"
            )
    return float(values[0]), float(values[1])


def _column(values, n: int, name: str, low: float, high: float) -> np.ndarray:
    array = np.asarray(values, dtype=float).reshape(-1)
    if array.size != n:
        raise InputError(f"{name}: {array.size} values for a run of {n} positions")
    if not np.all(np.isfinite(array)):
        raise InputError(f"{name}: values must be finite numbers")
    if array.min() < low or array.max() > high:
        raise InputError(f"{name}: values must be within [{low:g}, {high:g}]")
    return array


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


def _resolved_effects(table_effects, measured, variables, catalogue):
    """The catalogued table effects named in ``table_effects`` and their parameters by name."""
    objects, effects = [], {}
    for name, params in dict(table_effects).items():
        effect = resolve_effect(str(name), measured, tuple(catalogue))
        if not params:
            raise InputError(
                f"table effect '{effect.name}' is given without parameters, so it would "
                "simulate nothing; give at least one"
            )
        missing = effect.missing_columns(variables)
        if missing:
            raise InputError(
                f"table effect '{effect.name}' needs {', '.join(missing)}, which a simulated "
                "calibration run does not have (it has time_s only)"
            )
        objects.append(effect)
        effects[effect.name] = {str(k): float(v) for k, v in params.items()}
    return objects, effects


def _effect_values(objects, effects, variables) -> dict[str, float]:
    """``{effect.parameter: internal value}`` of the effects' given parameters, each checked."""
    values = effect_values(objects, effects, variables, "table effect")
    for name, params in effects.items():
        for pname, value in params.items():
            if not abs(value) <= _MOUNT_LIMIT_ARCSEC:
                raise InputError(
                    f"table effect '{name}', parameter '{pname}' = {value!r}: must be "
                    f"within +-{_MOUNT_LIMIT_ARCSEC:g} (in its user unit)"
                )
    return values


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
    measured = measured_table(table)
    variables = PositionVariables.of(PositionSet(angles, table=table, time_s=time_s))
    objects, effects = _resolved_effects(table_effects, measured, variables, catalogue)
    model = OrientationModel(variables, objects, measured)
    values = {
        n: float(v) for n, v in zip(table.parameter_names, vector, strict=True)
        if n in measured.base_names
    }  # fmt: skip
    values.update(_effect_values(objects, effects, variables))
    params = model.parameter_vector(values)
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
    sigma = _noise(noise_dph)
    instrument = check_instrument_effects(instrument or {})
    n = len(positions)
    time_given = time_s is not None
    time_s = _run_times(time_s, dwell_s, n)
    profile, temperature_c = _temperatures(temperature_c, time_s, instrument)
    outliers = _checked_outliers(outliers, outlier_dph, n, sigma)
    table_dR, errors, effects = _table_rotation_errors(
        positions, table_errors_rad or {}, table_effects or {}, time_s, catalogue
    )
    force, rate = _sensed(positions, latitude_rad, table_dR, instrument)
    exact = _exact_outputs(force, rate, gyrowheel, instrument, time_s, temperature_c)
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
        "instrument_units": {k: SIMULATED_INSTRUMENT_EFFECTS[k].unit for k in instrument},
    }


def _temperatures(temperature_c, time_s, instrument):
    """``(profile or None, temperature (N,) degC or None)``, checked; a temperature coefficient
    needs one."""
    profile = None
    if isinstance(temperature_c, TemperatureProfile):
        profile, temperature_c = temperature_c, temperature_c.at(time_s)
    if temperature_c is not None:
        temperature_c = _column(temperature_c, len(time_s), "temperature_c", -273.15, 1000.0)
    if "temperature_coefficient" in instrument and temperature_c is None:
        raise InputError(
            "instrument effect 'temperature_coefficient' needs a temperature: give "
            f"{argument('temperature_c')} (a start, a ramp per hour, a swing and its period)"
        )
    return profile, temperature_c


def _run_times(time_s, dwell_s: float, n: int) -> np.ndarray:
    """The rows' times, s: ``time_s`` checked, or ``index * dwell_s``."""
    if time_s is None:
        if not (math.isfinite(dwell_s) and dwell_s > 0):
            raise InputError(f"dwell_s must be a number > 0, got {dwell_s!r}")
        time_s = np.arange(n) * float(dwell_s)
    return _column(time_s, n, "time_s", 0.0, MAX_RUN_TIME_S)


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
    for name in ("instrument_tilt", "instrument_heading"):
        mount.update(instrument.get(name, {}))
    m_rad = {k: v / ARCSEC_PER_RAD for k, v in mount.items()}
    mount_rotation = orientation_error_rotation(m_rad["my"], m_rad["mz"], m_rad["mx"], exact=True)
    chain = inputs.payload_rotation @ table_dR @ mount_rotation
    force0, rate0 = base_frame_inputs(latitude_rad)
    return np.einsum("i,nij->nj", force0, chain), np.einsum("i,nij->nj", rate0, chain)


def _exact_outputs(force, rate, gyrowheel, instrument, time_s, temperature_c) -> np.ndarray:
    """(N, 2) the noise-free outputs: eq. 1 plus the instrument effects."""
    scale = instrument.get("earth_rate_scale", {"x": 0.0, "y": 0.0})
    drift = instrument.get("bias_drift", {"x": 0.0, "y": 0.0})
    thermal = instrument.get("temperature_coefficient", {"x": 0.0, "y": 0.0})
    g2 = instrument.get("g_squared_terms", dict.fromkeys(("x_xz", "x_yz", "y_xz", "y_yz"), 0.0))
    exact = np.empty((len(time_s), 2))
    for c, axis in enumerate(AXES):
        out = (1.0 + scale[axis] * 1e-6) * rate[:, c]
        out = out + regressor_matrix(axis, force) @ gyrowheel.axis(axis).as_array()
        out = out + g2[f"{axis}_xz"] * force[:, 0] * force[:, 2]
        out = out + g2[f"{axis}_yz"] * force[:, 1] * force[:, 2]
        out = out + drift[axis] * time_s / 3600.0
        if temperature_c is not None:
            out = out + thermal[axis] * (temperature_c - temperature_c.mean())
        exact[:, c] = out
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

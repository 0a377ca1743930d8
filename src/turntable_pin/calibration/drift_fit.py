"""Multi-position calibration of the GyroWheel drift coefficients by least squares (eqs. 2-6).

For each sensing axis, ``b1 - b2 = A beta`` (eq. 5) over the test positions, with ``b1`` the
measured outputs, ``b2`` the earth-rate components and ``A`` the regressor rows of eq. 2. The fit
reports the coefficients, their standard errors, the residual per position and the condition
number of ``A``; a position set that cannot determine all seven coefficients raises
:class:`IdentifiabilityError` naming why.

Calibration run files (CSV, one row per position): one angle column per joint of the table
(``phi1_deg .. phiN_deg`` in chain order or ``<joint>_deg``, see
:mod:`~turntable_pin.calibration.positions`: ``phi1_deg, phi2_deg`` on the paper's table),
``out_x_dph, out_y_dph`` and optionally ``sigma_dph`` (1-sigma output noise of the row) and
``time_s``; the latitude is a parameter of the run. A run is refused, naming file, row and
column, when an output or a ``sigma_dph`` is beyond :data:`MAX_RUN_OUTPUT_DPH`, a ``sigma_dph``
is <= 0 or below :data:`MIN_RUN_SIGMA_DPH`, a ``time_s`` is negative, a commanded angle is beyond
``MAX_COMMANDED_ANGLE_DEG``, or two rows are the same measurement (equal angles and, when
present, ``time_s``: a copied row), as the measurement reader does (positions too few to
determine the coefficients are reported before a copied row).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..core.csv_table import write_csv_table
from ..core.exceptions import IdentifiabilityError, InputError, check_seed
from ..core.notebook import NotebookResult
from ..core.units import rad_to_deg
from .gyrowheel import (
    AXES,
    N_COEFFICIENTS,
    TERM_NAMES,
    DriftCoefficients,
    GyroWheelModel,
    regressor_matrix,
)
from .positions import PositionInputs, PositionSet
from .run import (
    MAX_RUN_OUTPUT_DPH,
    CalibrationRun,
    read_run,
    refuse_copied_rows,
)

__all__ = [
    "AxisCalibration",
    "CalibrationResult",
    "calibrate",
    "calibrate_read_run",
    "calibrate_run",
    "check_identifiable",
    "fit_axis",
    "gravity_words",
    "require_identifiable",
    "simulate_run",
    "write_simulated_run",
]


@dataclass(frozen=True)
class AxisCalibration:
    """The least-squares fit of one axis.

    Attributes:
        axis: ``"x"`` or ``"y"``.
        coefficients_dph: (7,) fitted coefficients in :data:`TERM_NAMES` order.
        standard_errors_dph: (7,) 1-sigma standard errors; NaN when there are no degrees of
            freedom and no ``sigma_dph`` to scale by.
        residuals_dph: (N,) measured minus fitted output per position, deg/h.
        condition_number: 2-norm condition number of ``A``.
        rank: numerical rank of ``A`` (7 here; lower ranks raise).
        dof: degrees of freedom ``N - 7``.
        sigma_source: ``"sigma_dph"`` (weights from the file) or ``"residuals"``.
    """

    axis: str
    coefficients_dph: np.ndarray
    standard_errors_dph: np.ndarray
    residuals_dph: np.ndarray
    condition_number: float
    rank: int
    dof: int
    sigma_source: str

    @property
    def names(self) -> tuple[str, ...]:
        """The seven coefficient names of this axis, in fit order."""
        return TERM_NAMES[self.axis]

    @property
    def rms_dph(self) -> float:
        """Root mean square of the residuals, deg/h."""
        return float(np.sqrt(np.mean(self.residuals_dph**2)))

    def to_dict(self) -> dict:
        """The fit as a JSON-ready dict (coefficients and standard errors by name, deg/h)."""
        return {
            "coefficients_dph": dict(zip(self.names, self.coefficients_dph, strict=True)),
            "standard_errors_dph": dict(zip(self.names, self.standard_errors_dph, strict=True)),
            "condition_number": self.condition_number,
            "rank": self.rank,
            "dof": self.dof,
            "rms_residual_dph": self.rms_dph,
            "sigma_source": self.sigma_source,
        }


@dataclass(frozen=True)
class CalibrationResult(NotebookResult):
    """Both axes' fits and the set-up they came from."""

    x: AxisCalibration
    y: AxisCalibration
    inputs: PositionInputs

    def axis(self, name: str) -> AxisCalibration:
        """The fit of axis ``name`` (``"x"`` or ``"y"``)."""
        return getattr(self, name)

    def model(self, source: str = "calibration") -> GyroWheelModel:
        """The fitted coefficients as a :class:`GyroWheelModel`."""
        return GyroWheelModel(
            DriftCoefficients("x", tuple(self.x.coefficients_dph)),
            DriftCoefficients("y", tuple(self.y.coefficients_dph)),
            source=source,
        )

    def to_dict(self) -> dict:
        """Both fits and the residual per position as a JSON-ready dict (degrees, deg/h)."""
        positions = self.inputs.positions
        return {
            "positions": positions.name,
            "n_positions": len(positions),
            "latitude_deg": float(rad_to_deg(self.inputs.latitude_rad)),
            "x": self.x.to_dict(),
            "y": self.y.to_dict(),
            "residuals": [
                {
                    **dict(zip(positions.column_names, map(float, angles), strict=True)),
                    "residual_x_dph": float(rx),
                    "residual_y_dph": float(ry),
                }
                for angles, rx, ry in zip(
                    rad_to_deg(positions.angles_rad),
                    self.x.residuals_dph,
                    self.y.residuals_dph,
                    strict=True,
                )
            ],
        }

    def report(self) -> str:
        """A human-readable summary: coefficients with standard errors, residuals per position."""
        d = self.to_dict()
        lines = [
            f"positions: {d['positions']} ({d['n_positions']}), latitude {d['latitude_deg']:g} deg"
        ]
        for axis in AXES:
            fit = self.axis(axis)
            lines.append(
                f"axis {axis}: cond(A) = {fit.condition_number:.4g}, rms residual "
                f"{fit.rms_dph:.4g} deg/h, sigma from {fit.sigma_source}"
            )
            for name, value, error in zip(
                fit.names, fit.coefficients_dph, fit.standard_errors_dph, strict=True
            ):
                lines.append(f"  D{axis}{name:3s} = {value:12.6f} +- {error:.3g}")
        angle_keys = self.inputs.positions.column_names
        width = max(9, *(len(k) for k in angle_keys))
        lines.append(
            " ".join(f"{k:>{width}s}" for k in angle_keys)
            + f" {'res_x_dph':>12s} {'res_y_dph':>12s}"
        )
        for row in d["residuals"]:
            lines.append(
                " ".join(f"{row[k]:{width}.3f}" for k in angle_keys)
                + f" {row['residual_x_dph']:12.3e} {row['residual_y_dph']:12.3e}"
            )
        return "\n".join(lines)


def check_identifiable(design: np.ndarray, axis: str, positions: PositionSet) -> int:
    """Raise :class:`IdentifiabilityError` unless ``A`` determines all seven coefficients.

    Returns the rank (7). The message says whether there are too few distinct positions or which
    combination of regressor columns the positions cannot tell apart.
    """
    distinct = positions.distinct_count()
    if distinct < N_COEFFICIENTS:
        raise IdentifiabilityError(
            f"too few distinct positions: {distinct} distinct position(s) cannot determine the "
            f"{N_COEFFICIENTS} drift coefficients of axis {axis} (at least 7 are needed)"
        )
    distinct_rows = np.unique(np.round(design, 12), axis=0).shape[0]
    if distinct_rows < N_COEFFICIENTS:
        raise IdentifiabilityError(
            f"too few distinct gravity directions: the {distinct} positions give only "
            f"{distinct_rows} distinct regressor rows for axis {axis}; 7 coefficients need 7"
        )
    _, singular, vt = np.linalg.svd(design, full_matrices=False)
    tol = singular[0] * max(design.shape) * np.finfo(float).eps
    rank = int(np.sum(singular > tol))
    if rank < N_COEFFICIENTS:
        names = TERM_NAMES[axis]
        combos = []
        for null in vt[rank:]:
            null = null / np.max(np.abs(null))
            combos.append(
                " + ".join(
                    f"{v:.3g}*D{axis}{n}" for v, n in zip(null, names, strict=True) if abs(v) > 1e-6
                )
            )
        why = gravity_words(design[:, 1:4])
        physics = (
            f"on these positions {' and '.join(why)}, so some coefficients cannot be told apart"
            if why
            else "these positions turn gravity through too few directions, so some coefficients "
            "cannot be told apart"
        )
        raise IdentifiabilityError(
            f"axis {axis}: {physics} (the positions give A of rank {rank} < 7; they cannot "
            f"determine {'; '.join(combos)}); choose positions where those regressors vary "
            "independently"
        )
    return rank


def gravity_words(specific_force_g: np.ndarray) -> list[str]:
    """What a set of positions never does with gravity, in plain words: a component along the
    GyroWheel that stays the same at every position, or a product of two that is zero at every
    position (gravity never between those axes)."""
    a = np.asarray(specific_force_g, dtype=float)
    out = [
        f"gravity's {name} component along the GyroWheel stays {a[0, i]:.3g} g at every position"
        for i, name in enumerate("xyz")
        if np.ptp(a[:, i]) < 1e-9
    ]
    if not out:
        for (i, j), name in (((0, 1), "ax*ay"), ((0, 2), "ax*az"), ((1, 2), "ay*az")):
            if np.max(np.abs(a[:, i] * a[:, j])) < 1e-9:
                out.append(
                    f"the product {name} is zero at every position (gravity never lies between "
                    "those two axes, as on a 90-degree grid)"
                )
    return [w.replace("stays -0 g", "stays 0 g") for w in out]


def fit_axis(
    axis: str,
    inputs: PositionInputs,
    outputs_dph: np.ndarray,
    sigma_dph: np.ndarray | None = None,
) -> AxisCalibration:
    """Least squares of eq. 6 for one axis (weighted by ``1/sigma^2`` when given)."""
    outputs = np.asarray(outputs_dph, dtype=float)
    if outputs.shape != (len(inputs),):
        raise InputError(f"axis {axis}: expected {len(inputs)} outputs, got shape {outputs.shape}")
    if not np.all(np.isfinite(outputs)):
        raise InputError(f"axis {axis}: outputs must be finite numbers (found NaN or inf)")
    design = regressor_matrix(axis, inputs.specific_force_g)
    rank = check_identifiable(design, axis, inputs.positions)
    rhs = outputs - inputs.earth_rate_dph[:, AXES.index(axis)]
    if sigma_dph is not None:
        sigma = np.asarray(sigma_dph, dtype=float)
        if np.any(~np.isfinite(sigma)) or np.any(sigma <= 0):
            raise InputError("sigma_dph must be finite and positive")
        weights = 1.0 / sigma
    else:
        weights = np.ones_like(rhs)
    weighted = design * weights[:, None]
    coefficients, *_ = np.linalg.lstsq(weighted, rhs * weights, rcond=None)
    residuals = rhs - design @ coefficients
    dof = len(inputs) - N_COEFFICIENTS
    # (W A)^T (W A) inverted through the SVD of W A: V S^-2 V^T, whose diagonal is a sum of
    # squares (an inverse of the normal matrix of a barely identifying position set had tiny
    # negative variances from rounding).
    _, s, vt = np.linalg.svd(weighted, full_matrices=False)
    cov_unit = (vt.T / s**2) @ vt
    if sigma_dph is not None:
        covariance = cov_unit
        source = "sigma_dph"
    elif dof > 0:
        covariance = cov_unit * float(np.sum(residuals**2)) / dof
        source = "residuals"
    else:
        covariance = np.full_like(cov_unit, np.nan)
        source = "none (no degrees of freedom)"
    return AxisCalibration(
        axis=axis,
        coefficients_dph=coefficients,
        standard_errors_dph=np.sqrt(np.diag(covariance)),
        residuals_dph=residuals,
        condition_number=float(np.linalg.cond(design)),
        rank=rank,
        dof=dof,
        sigma_source=source,
    )


def calibrate(
    inputs: PositionInputs,
    out_x_dph: np.ndarray,
    out_y_dph: np.ndarray,
    sigma_dph: np.ndarray | None = None,
) -> CalibrationResult:
    """Fit the seven coefficients of both axes to measured outputs (eqs. 5-6)."""
    return CalibrationResult(
        x=fit_axis("x", inputs, out_x_dph, sigma_dph),
        y=fit_axis("y", inputs, out_y_dph, sigma_dph),
        inputs=inputs,
    )


def require_identifiable(inputs: PositionInputs, *, every_coefficient: bool = True) -> None:
    """Raise :class:`IdentifiabilityError` (naming the positions) unless the positions of
    ``inputs`` determine the seven drift coefficients of both axes (see
    :func:`check_identifiable`).

    ``every_coefficient=False`` asks only what a rate-error analysis (eqs. 7-16) needs: that the
    positions turn gravity through all three payload axes. They may then leave a coefficient
    they never excite undetermined (``ax ay`` on a 90-degree grid: eq. 6's ``beta1`` is reported
    as undetermined), on any table; gravity kept in a plane or on a line is refused as above.
    """
    if not every_coefficient and np.linalg.matrix_rank(inputs.specific_force_g) == 3:
        return
    for axis in AXES:
        design = regressor_matrix(axis, inputs.specific_force_g)
        try:
            check_identifiable(design, axis, inputs.positions)
        except IdentifiabilityError as exc:
            name = inputs.positions.name
            raise IdentifiabilityError(f"positions{' ' + name if name else ''}: {exc}") from None


def calibrate_run(path: str | Path, latitude_rad: float, table=None) -> CalibrationResult:
    """Read a calibration run CSV (:func:`~.run.read_run`) and fit it.

    ``table``: the :class:`~turntable_pin.model.generic_table.GenericTable` whose run this is
    (default the paper's table).
    """
    return calibrate_read_run(read_run(path, latitude_rad, table))


def calibrate_read_run(run: CalibrationRun) -> CalibrationResult:
    """Fit a calibration run already read (:func:`~.run.read_run`), as :func:`calibrate_run`
    does: positions that cannot determine the coefficients are named first, then copied rows."""
    try:
        result = calibrate(run.inputs, run.outputs_dph[:, 0], run.outputs_dph[:, 1], run.sigma_dph)
    except IdentifiabilityError as exc:
        if not run.source:
            raise
        raise IdentifiabilityError(f"{run.source}: {exc}") from None
    # After the fit: positions that cannot determine the coefficients are the first problem.
    refuse_copied_rows(run)
    return result


def simulate_run(
    gyrowheel: GyroWheelModel,
    inputs: PositionInputs,
    *,
    noise_dph: float,
    seed: int,
) -> dict[str, np.ndarray]:
    """Outputs of eq. 1 at the ideal orientation plus seeded Gaussian noise, as run columns.

    ``noise_dph`` is a finite number in [0, :data:`MAX_RUN_OUTPUT_DPH`]; ``seed`` a whole number
    0 <= seed < 2**63.
    """
    if not 0.0 <= float(noise_dph) <= MAX_RUN_OUTPUT_DPH:
        raise InputError(
            f"noise_dph must be in [0, {MAX_RUN_OUTPUT_DPH:g}] deg/h, got {noise_dph!r}"
        )
    rng = np.random.default_rng(check_seed(seed))
    outputs = gyrowheel.outputs_dph(inputs.specific_force_g, inputs.earth_rate_dph)
    outputs = outputs + rng.normal(0.0, noise_dph, size=outputs.shape)
    angles = rad_to_deg(inputs.positions.angles_rad).T
    columns = {f"phi{i + 1}_deg": a for i, a in enumerate(angles)}  # chain order, any table
    columns |= {"out_x_dph": outputs[:, 0], "out_y_dph": outputs[:, 1]}
    if noise_dph > 0:
        columns["sigma_dph"] = np.full(len(inputs), float(noise_dph))
    return columns


def write_simulated_run(
    path: str | Path,
    gyrowheel: GyroWheelModel,
    inputs: PositionInputs,
    *,
    noise_dph: float,
    seed: int,
) -> Path:
    """Write :func:`simulate_run` as a calibration run CSV whose comment records the seed."""
    columns = simulate_run(gyrowheel, inputs, noise_dph=noise_dph, seed=seed)
    comment = (
        f"simulated GyroWheel calibration run: coefficients {gyrowheel.source or 'given'}, "
        f"positions {inputs.positions.name}, latitude {rad_to_deg(inputs.latitude_rad):g} deg, "
        f"noise {noise_dph:g} deg/h, seed {seed}"
    )
    return write_csv_table(path, columns, comment=comment)

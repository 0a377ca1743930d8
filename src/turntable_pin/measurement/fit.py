"""Fitting orientation measurements with the base error model plus chosen effects.

:class:`OrientationFitProblem` adapts :class:`OrientationModel` and :class:`OrientationMeasurements`
to the :class:`FitProblem` of :mod:`turntable_pin.stats.least_squares` (observations position by
position, ``dpsi, dtheta, dgamma``, those not measured left out); :func:`fit_orientation` returns
an :class:`OrientationFit` that knows its data, model, residuals and parameters.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..core.exceptions import InputError
from ..core.notebook import NotebookResult
from ..core.sizes import FIT_ROW_BYTES, MAX_FITTED_ROWS, check_count
from ..core.units import ARCSEC_PER_RAD
from ..stats.least_squares import (
    RANK_RTOL,
    FitResult,
    ZeroPoint,
    analyse_identifiability,
    combination_name,
    fit_least_squares,
    zero_point,
)
from .data import ANGLE_NAMES, OrientationMeasurements
from .effect_model import OrientationModel
from .effects.base import Effect
from .pointing_terms import fitted_pointing_terms

__all__ = [
    "MAX_UNEXPLAINED_ARCSEC",
    "RELINEARISE_RAD",
    "ZERO_POINT_BLOCK",
    "OrientationFit",
    "OrientationFitProblem",
    "fit_orientation",
    "orientation_zero_point",
    "refuse_repeated_shapes",
]

ZERO_POINT_BLOCK = 8192
"""Positions per block of :meth:`OrientationFitProblem.zero_point_blocks` (a few MB each)."""

RELINEARISE_RAD = 1e-3
"""Fitted base errors beyond this (rad, 3.4 arcmin: a mount not synced, an encoder index off)
make :func:`fit_orientation` fit a model with effects again from the base errors' solution: the
fit from zero takes the minimum-norm split of what the data do not determine at zero errors,
which with degrees of offset is no longer equivalent (a German-equatorial mount 1 deg off in
hour angle, roll not measured: chi2 3273 with declination wobble, 385 without, 384 from the
base solution). Arc-second tables never reach it."""

MAX_UNEXPLAINED_ARCSEC = 18000.0
"""Largest residual a fit may leave, arc seconds (5 deg, the small-error limit
``MAX_ANGULAR_ERROR_DEG``): what the fitted errors of the table do not explain is a small error
(noise, an effect) or no orientation error of the table at all (another star, a wrong sign, a
unit mix-up); :func:`fit_orientation` refuses the rows beyond it."""


class OrientationFitProblem:
    """A :class:`FitProblem`: orientation data and a base + effects model."""

    user_unit_scale = ARCSEC_PER_RAD
    observation_unit = "arcsec"

    def __init__(self, data: OrientationMeasurements, model: OrientationModel) -> None:
        self.data = data
        self.model = model
        self.parameter_names = model.parameter_names
        self.parameter_units = model.parameter_units
        self.per_user_unit = model.per_user_unit
        self.mask = data.measured.reshape(-1)
        self.all_measured = bool(self.mask.all())
        self.observed = self._measured(data.angles_rad.reshape(-1))
        self.sigma = None if data.sigma_rad is None else self._measured(data.sigma_rad.reshape(-1))
        self.sigma_relative = bool(data.sigma_relative and data.sigma_rad is not None)

    def _measured(self, values: np.ndarray) -> np.ndarray:
        return values if self.all_measured else values[self.mask]

    def predict(self, params: np.ndarray) -> np.ndarray:
        """Predicted ``dpsi, dtheta, dgamma`` of the measured angles, position by position, rad."""
        return self._measured(self.model.predict(params).reshape(-1))

    def jacobian(self, params: np.ndarray) -> np.ndarray:
        """Derivative of :meth:`predict` with respect to the parameters, (m, n_params)."""
        return self._measured(self.model.jacobian(params).reshape(-1, self.model.n_params))

    def zero_point_blocks(self, block: int = ZERO_POINT_BLOCK):
        """``(weighted jacobian, weighted residuals, weights)`` at zero parameters, ``block``
        positions at a time (the measured angles only), for ``zero_point`` of
        :mod:`..stats.least_squares`."""
        data, model = self.data, self.model
        zeros = np.zeros(model.n_params)
        for start in range(0, data.n_positions, block):
            rows = slice(start, min(start + block, data.n_positions))
            predicted, jac = model.predict_and_jacobian(zeros, rows)
            mask = data.measured[rows].reshape(-1)
            observed = data.angles_rad[rows].reshape(-1)[mask]
            if data.sigma_rad is None:
                weights = np.ones_like(observed)
            else:
                weights = 1.0 / data.sigma_rad[rows].reshape(-1)[mask]
            jac = jac.reshape(-1, model.n_params)[mask] * weights[:, None]
            yield jac, (observed - predicted.reshape(-1)[mask]) * weights, weights

    def predict_and_jacobian(self, params: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`predict` (rad) and :meth:`jacobian` (a new array) from one pass of the model."""
        predicted, jac = self.model.predict_and_jacobian(params)
        return (
            self._measured(predicted.reshape(-1)),
            self._measured(jac.reshape(-1, self.model.n_params)),
        )


@dataclass(frozen=True)
class OrientationFit(NotebookResult):
    """A fit of orientation data: the generic result plus the data, model and effects."""

    data: OrientationMeasurements
    model: OrientationModel
    result: FitResult

    def per_angle(self, values: np.ndarray) -> np.ndarray:
        """Per-observation values (m,) of the result as (N, 3), NaN where not measured."""
        mask = self.data.measured.reshape(-1)
        out = np.full(mask.size, np.nan)
        out[mask] = values
        return out.reshape(-1, 3)

    @property
    def effects(self) -> tuple[Effect, ...]:
        """The effects fitted besides the base errors."""
        return self.model.effects

    @property
    def effect_names(self) -> tuple[str, ...]:
        """The catalogue names of :attr:`effects`."""
        return tuple(e.name for e in self.model.effects)

    @property
    def residuals_rad(self) -> np.ndarray:
        """Measured minus fitted ``dpsi, dtheta, dgamma`` per position, (N, 3) (NaN: not
        measured)."""
        return self.per_angle(self.result.residuals)

    @property
    def normalised_residuals(self) -> np.ndarray:
        """Residuals in units of the noise sigma (given or estimated), (N, 3)."""
        r = self.result.residuals * self.result.weights / np.sqrt(self.result.noise_variance)
        return self.per_angle(r)

    @property
    def sigma_angles_rad(self) -> np.ndarray:
        """The noise sigma of each angle used to judge the fit (given or estimated), (N, 3)."""
        return self.per_angle(np.sqrt(self.result.noise_variance) / self.result.weights)

    @property
    def sigma_rad(self) -> np.ndarray:
        """The noise sigma of each position (the median over its measured angles), (N,)."""
        return np.nanmedian(self.sigma_angles_rad, axis=1)

    def unobserved_combinations(self) -> list[str]:
        """The error combinations these positions would determine with every angle measured but
        do not with the cells left empty (``[]`` when every angle was measured); e.g. without
        ``dtheta`` on the paper's table, ``dphi_z2 + dalpha_z1``."""
        if self.data.measured.all():
            return []
        names = self.model.parameter_names
        jac = self.model.jacobian(np.zeros(self.model.n_params)).reshape(-1, len(names))
        full = analyse_identifiability(jac, names)
        now = self.result.identifiability
        q, _ = np.linalg.qr(now.determined.T) if now.rank else (np.zeros((len(names), 0)), None)
        lost = full.determined.T - q @ (q.T @ full.determined.T)  # (n, rank_full)
        u, s, _ = np.linalg.svd(lost, full_matrices=False)
        keep = s > 1e-6 * max(1.0, float(np.abs(full.determined).max(initial=1.0)))
        if not keep.any():
            return []
        rows = analyse_identifiability(u[:, keep].T, names).determined  # RREF of the lost space
        return [combination_name(row, names) for row in rows]

    def fitted_rad(self) -> np.ndarray:
        """The model's ``dpsi, dtheta, dgamma`` at the measured positions, (N, 3)."""
        return self.model.predict(self.result.params)

    def with_noise_variance(self, noise_variance: float) -> OrientationFit:
        """The same fit judged with another noise variance (sigma-unknown data only)."""
        if self.result.sigma_known:
            return self
        return OrientationFit(
            self.data, self.model, self.result.with_noise_variance(noise_variance)
        )

    def to_dict(self) -> dict:
        """The fit as a JSON-ready dict (the generic result plus effects and sigma in arcsec; on a
        telescope mount also ``pointing_terms``, TPOINT's terms by name)."""
        out = {
            "n_positions": self.data.n_positions,
            "effects": list(self.effect_names),
            "sigma_arcsec": float(np.median(self.sigma_rad) * ARCSEC_PER_RAD),
            "not_measured": {
                name: int(np.sum(~self.data.measured[:, i])) for i, name in enumerate(ANGLE_NAMES)
            },
            "unobserved_combinations": self.unobserved_combinations(),
        }
        out.update(self.result.to_dict())
        terms = fitted_pointing_terms(self)
        if terms is not None:  # a telescope mount: TPOINT's terms by name
            out["pointing_terms"] = terms
        return out


def fit_orientation(
    data: OrientationMeasurements,
    effects: Sequence[Effect] = (),
    *,
    noise_variance: float | None = None,
    turntable=None,
    zero_point: ZeroPoint | None = None,
    base_fit: OrientationFit | None = None,
) -> OrientationFit:
    """Fit the base error model plus ``effects`` to ``data``, from zero errors; with effects and
    base errors beyond :data:`RELINEARISE_RAD`, again from the base errors' own solution (effects
    at zero), the better fit kept.

    Args:
        data: the measurements.
        effects: catalogued effects to include.
        noise_variance: for data without sigmas, the unit-weight variance (rad^2) to judge the fit
            with (default: estimated from this fit).
        turntable: the table (a ``MeasuredTable`` or ``GenericTable``; default: the bundled
            paper table).
        zero_point: :func:`orientation_zero_point` of these data with these effects and maybe
            more (fits of many effect sets of one data set share it).
        base_fit: the fit of the base errors alone to these ``data``, when at hand (fitted here
            when needed and not given).

    Raises:
        InputError: more rows than :data:`~turntable_pin.core.sizes.MAX_FITTED_ROWS`; residuals
            beyond :data:`MAX_UNEXPLAINED_ARCSEC` (naming the rows: no error set of the table
            explains them).
    """
    check_count(data.n_positions, MAX_FITTED_ROWS, "measurement rows", FIT_ROW_BYTES)
    model = OrientationModel(data.variables(), effects, turntable)
    problem = OrientationFitProblem(data, model)
    result = fit_least_squares(problem, noise_variance=noise_variance, zero_point=zero_point)
    n_base = len(model.base_names)
    if model.effects and np.max(np.abs(result.params[:n_base]), initial=0.0) > RELINEARISE_RAD:
        if base_fit is None:
            base_fit = fit_orientation(data, (), noise_variance=noise_variance, turntable=turntable)
        origin = np.zeros(model.n_params)
        origin[:n_base] = base_fit.result.params
        refit = fit_least_squares(
            problem, noise_variance=noise_variance, zero_point=zero_point, origin=origin
        )
        if refit.rss < result.rss:
            result = refit
    fit = OrientationFit(data, model, result)
    _refuse_unexplained(fit)
    return fit


def refuse_repeated_shapes(data: OrientationMeasurements, effects, turntable=None) -> None:
    """:class:`InputError` when one of ``effects`` adds nothing the others do not already add on
    these data (its Jacobian columns, beyond the base errors, lie in the span of another's:
    ``inner_encoder_harmonics`` and ``dphi_z2~h1(phi2)`` together), naming both; a fit would
    otherwise show a lower rank and split the shape between them silently."""
    if len(effects) < 2:
        return
    model = OrientationModel(data.variables(), effects, turntable)
    jac = model.jacobian(np.zeros(model.n_params)).reshape(-1, model.n_params)
    jac = jac[data.measured.reshape(-1)]
    n_base = len(model.base_names)

    def span(columns: np.ndarray) -> np.ndarray:
        u, s, _ = np.linalg.svd(columns, full_matrices=False)
        return u[:, s > RANK_RTOL * (s[0] if s.size else 1.0)]

    base = span(jac[:, :n_base])
    blocks = []
    start = n_base
    for effect in effects:
        count = len(effect.parameters(data.variables()))
        block = jac[:, start : start + count]
        blocks.append(block - base @ (base.T @ block))
        start += count
    for i, a in enumerate(effects):
        own = blocks[i]
        if not np.linalg.norm(own) > 0:
            continue
        for j, b in enumerate(effects):
            if i == j or not np.linalg.norm(blocks[j]) > 0:
                continue
            other = span(blocks[j])
            left = own - other @ (other.T @ own)
            if np.linalg.norm(left) <= 1e-6 * np.linalg.norm(own):
                raise InputError(
                    f"effect '{a.name}' adds nothing that '{b.name}' does not already add on "
                    "these data (the same shape given twice); give it once"
                )


def _refuse_unexplained(fit: OrientationFit) -> None:
    """:class:`InputError` naming the rows whose residual exceeds
    :data:`MAX_UNEXPLAINED_ARCSEC`."""
    residual_arcsec = np.abs(fit.residuals_rad) * ARCSEC_PER_RAD
    bad = np.flatnonzero(np.nanmax(np.where(fit.data.measured, residual_arcsec, 0.0), axis=1)
                         > MAX_UNEXPLAINED_ARCSEC)  # fmt: skip
    if not bad.size:
        return
    rows = [int(r) for r in fit.data.rows[bad]]
    shown = ", ".join(str(r) for r in rows[:10]) + (
        f" and {len(rows) - 10} more" if len(rows) > 10 else ""
    )
    worst = float(np.nanmax(residual_arcsec[bad])) / 3600.0
    raise InputError(
        f"row(s) {shown} of {fit.data.source or 'the data'}: the best fit of the table's errors "
        f"leaves up to {worst:.3g} deg unexplained, beyond {MAX_UNEXPLAINED_ARCSEC / 3600:g} deg: "
        "no error set of this table explains them (another star, a wrong sign or unit, another "
        "table?); correct or remove them"
    )


def orientation_zero_point(
    data: OrientationMeasurements, effects: Sequence[Effect] = (), *, turntable=None
) -> ZeroPoint:
    """The weighted Jacobian at zero of the base errors plus ``effects`` on ``data``, reduced
    (:class:`~turntable_pin.stats.least_squares.ZeroPoint`): computed block by block of
    positions, it serves every fit of these data whose effects are among ``effects``."""
    check_count(data.n_positions, MAX_FITTED_ROWS, "measurement rows", FIT_ROW_BYTES)
    model = OrientationModel(data.variables(), effects, turntable)
    problem = OrientationFitProblem(data, model)
    return zero_point(model.parameter_names, problem.zero_point_blocks())

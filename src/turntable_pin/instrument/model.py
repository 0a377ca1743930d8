"""The model of a calibration run: the 2 x 7 drift coefficients plus effects, and its fit.

``out_c = w_c + A_c(a) beta_c + sum_e J_e p_e`` at each position (c = x, y; eq. 1 plus each
effect's columns). Linear in every parameter: the table's effects enter through the rate
sensitivity at the *reference* coefficients (the run's plain calibration, eq. 6); the product of
an effect (1e-5 rad) with the change of coefficients it causes is far below the noise. The
observations are the two outputs of each position, record by record.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..calibration.gyrowheel import AXES, N_COEFFICIENTS, TERM_NAMES
from ..core.user_code import is_user_code
from ..stats.least_squares import FitResult, fit_least_squares
from .effects.base import RunContext, RunEffect, run_variables
from .effects.contract import check_run_effect
from .sensitivity import drift_regressor, rate_sensitivity_dph

__all__ = [
    "BASE_NAMES",
    "BASE_UNITS",
    "CHANNELS",
    "RunFit",
    "RunModel",
    "fit_run",
    "reference_coefficients",
    "run_context",
]

CHANNELS = ("out_x", "out_y")
"""The two observations of a position (the residual components)."""

BASE_NAMES: tuple[str, ...] = tuple(f"D{axis}{name}" for axis in AXES for name in TERM_NAMES[axis])
"""The 14 coefficients as parameters (``DxDF``, ``Dxx``... ``Dyyx``; eq. 1's names)."""

_UNIT_OF_TERM = {"DF": "deg/h", "x": "deg/h/g", "y": "deg/h/g", "z": "deg/h/g"}
BASE_UNITS: tuple[str, ...] = tuple(
    _UNIT_OF_TERM.get(name, "deg/h/g^2") for axis in AXES for name in TERM_NAMES[axis]
)
"""The unit of each of :data:`BASE_NAMES`."""


def reference_coefficients(run, mask: np.ndarray | None = None) -> np.ndarray:
    """The plain calibration of ``run``, (2, 7) (eq. 6, weighted by ``sigma_dph`` when given;
    minimum-norm where undetermined), from the observations ``mask`` (N, 2) (default all)."""
    design = drift_regressor(run.inputs.specific_force_g)
    rhs = run.outputs_dph - run.inputs.earth_rate_dph[:, :2]
    weights = np.ones(run.n_positions) if run.sigma_dph is None else 1.0 / run.sigma_dph
    out = np.zeros((2, N_COEFFICIENTS))
    for c in range(2):
        keep = slice(None) if mask is None else mask[:, c]
        block = design[keep, c, c * N_COEFFICIENTS : (c + 1) * N_COEFFICIENTS]
        w = weights[keep]
        out[c] = np.linalg.lstsq(block * w[:, None], rhs[keep, c] * w, rcond=None)[0]
    return out


def run_context(run, coefficients: np.ndarray | None = None) -> RunContext:
    """The :class:`RunContext` of ``run`` at ``coefficients`` (default its plain calibration)."""
    beta = reference_coefficients(run) if coefficients is None else np.asarray(coefficients)
    return RunContext(
        run=run,
        sensitivity=rate_sensitivity_dph(run.inputs, beta),
        coefficients=beta,
        variables=run_variables(run),
    )


class RunModel:
    """The outputs of a run from the 14 coefficients and ``effects`` (a ``FitProblem``) in
    ``context`` (:func:`run_context`), the outputs ``mask`` (N, 2) fitted (default all), with the
    relative noise ``channel_sigma`` (2,) of ``out_x``, ``out_y`` or ``None`` (then the
    unit-weight variance is estimated: ``sigma_relative``)."""

    observation_unit = "dph"
    user_unit_scale = 1.0

    def __init__(
        self,
        context: RunContext,
        effects: Sequence[RunEffect] = (),
        mask: np.ndarray | None = None,
        channel_sigma: np.ndarray | None = None,
    ) -> None:
        run = context.run
        self.context = context
        self.run = run
        self.effects = tuple(effects)
        self.effect_names = tuple(e.name for e in self.effects)
        n = run.n_positions
        self.mask = np.ones((n, 2), bool) if mask is None else np.asarray(mask, bool)
        blocks = [_memo(context, ("base",), lambda: drift_regressor(run.inputs.specific_force_g))]
        names, units, scale = list(BASE_NAMES), list(BASE_UNITS), [1.0] * len(BASE_NAMES)
        for effect in self.effects:
            specs, columns = _specs_and_columns(effect, context)
            blocks.append(columns)
            names += [f"{effect.name}.{s.name}" for s in specs]
            units += [s.unit for s in specs]
            scale += [s.per_user_unit for s in specs]
        self.columns = np.concatenate(blocks, axis=2)  # (N, 2, n)
        self.parameter_names = tuple(names)
        self.parameter_units = tuple(units)
        self.per_user_unit = np.array(scale)
        flat = self.mask.reshape(-1)
        self._jacobian = self.columns.reshape(-1, len(names))[flat]
        self._offset = run.inputs.earth_rate_dph[:, :2].reshape(-1)[flat]
        self.observed = run.outputs_dph.reshape(-1)[flat]
        sigma = None
        if run.sigma_dph is not None:
            sigma = np.repeat(run.sigma_dph, 2)[flat]
        if channel_sigma is not None:
            per = np.broadcast_to(np.asarray(channel_sigma, float), (n, 2)).reshape(-1)[flat]
            sigma = per if sigma is None else sigma * per
        self.sigma = sigma
        self.sigma_relative = channel_sigma is not None

    @property
    def n_params(self) -> int:
        """Number of parameters: the 14 coefficients plus the effects'."""
        return len(self.parameter_names)

    def predict(self, params) -> np.ndarray:
        """The fitted outputs (flattened, the observed cells), deg/h."""
        return self._offset + self._jacobian @ np.asarray(params, dtype=float)

    def jacobian(self, params) -> np.ndarray:
        """The (constant) derivative of :meth:`predict`, (m, n)."""
        return self._jacobian.copy()

    def full_prediction(self, params) -> np.ndarray:
        """The outputs at every position (N, 2), the left-out ones too, deg/h."""
        run = self.run
        return run.inputs.earth_rate_dph[:, :2] + np.einsum("ncp,p->nc", self.columns, params)


def _specs_and_columns(effect: RunEffect, context: RunContext):
    """``effect``'s parameters and columns in ``context`` (computed once per context; a user's
    effect checked against its contract first)."""
    if is_user_code(effect):
        return _memo(context, ("contract", id(effect)), lambda: check_run_effect(effect, context))
    columns = _memo(context, ("effect", effect.name, id(effect)), lambda: effect.columns(context))
    return effect.parameters(context.run), columns


def _memo(context: RunContext, key: tuple, compute):
    if key not in context.memo:
        context.memo[key] = compute()
    return context.memo[key]


@dataclass(frozen=True)
class RunFit:
    """A fit of a run's model: the result, the coefficients, the residuals per output."""

    model: RunModel
    result: FitResult

    @property
    def run(self):
        """The fitted run."""
        return self.model.run

    @property
    def effect_names(self) -> tuple[str, ...]:
        """The names of the effects in the model."""
        return self.model.effect_names

    @property
    def coefficients_dph(self) -> np.ndarray:
        """(2, 7) the fitted drift coefficients (deg/h-based units)."""
        return self.result.params[: 2 * N_COEFFICIENTS].reshape(2, N_COEFFICIENTS)

    @property
    def fitted_dph(self) -> np.ndarray:
        """(N, 2) the model's outputs at every position, deg/h."""
        return self.model.full_prediction(self.result.params)

    @property
    def residuals_dph(self) -> np.ndarray:
        """(N, 2) measured minus fitted, NaN where an output was left out."""
        out = self.run.outputs_dph - self.fitted_dph
        return np.where(self.model.mask, out, np.nan)

    @property
    def sigma_dph(self) -> np.ndarray:
        """(N, 2) the 1-sigma noise of each output the fit is judged with, deg/h."""
        full = np.full((self.run.n_positions, 2), np.nan)
        full[self.model.mask] = np.sqrt(self.result.noise_variance) / self.result.weights
        return full

    @property
    def normalised_residuals(self) -> np.ndarray:
        """(N, 2) residuals over their sigma (NaN where left out)."""
        return self.residuals_dph / self.sigma_dph

    def with_noise_variance(self, noise_variance: float) -> RunFit:
        """The same fit judged with another unit-weight noise variance."""
        return replace(self, result=self.result.with_noise_variance(noise_variance))

    def to_dict(self) -> dict:
        """The fit as a JSON-ready dict: coefficients by axis, effects, combinations."""
        table = self.result.parameter_table()
        return {
            "effects": list(self.effect_names),
            "coefficients_dph": {
                axis: {name: table[f"D{axis}{name}"] for name in TERM_NAMES[axis]} for axis in AXES
            },
            **self.result.to_dict(),
        }


def fit_run(
    run,
    effects: Sequence[RunEffect] = (),
    *,
    context: RunContext | None = None,
    mask: np.ndarray | None = None,
    channel_sigma: np.ndarray | None = None,
    noise_variance: float | None = None,
    zero_point=None,
) -> RunFit:
    """Fit the 14 coefficients and ``effects`` to ``run`` (see :class:`RunModel`)."""
    context = context or run_context(run)
    model = RunModel(context, effects, mask, channel_sigma)
    result = fit_least_squares(model, noise_variance=noise_variance, zero_point=zero_point)
    return RunFit(model, result)

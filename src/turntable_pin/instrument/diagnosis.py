"""Diagnose a calibration run: is the missing effect the table's or the instrument's?

:class:`RunFamily` is the run's family for the one diagnosis (``stats.diagnosis_engine``): the
base is the 2 x 7 drift coefficients (eq. 1), the candidates the run catalogue (:mod:`.effects`:
the table's errors and effects through eqs. 8-13, and the instrument's own), outliers grouped per
output (``out_x``/``out_y``), a noise level per output when sigma is not given and they differ.

Probes of the structure search: ``out_x k/rev in phiK`` (k = 1 .. 5, fewer with fewer distinct
angles; ``phiA+phiB``, ``phiA-phiB`` for k = 1, 2) on each output; ``dpsi k/rev in phiK`` (and
``dtheta``, ``dgamma``), a harmonic orientation error of the table through the rate
sensitivity; ``out_x drift in time``, ``out_x in <column>``: a quadratic in ``time_s`` or another
numeric column (``temperature_c``...).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..calibration.drift_fit import gravity_words
from ..calibration.positions import PositionSet, position_inputs
from ..calibration.run import CalibrationRun
from ..calibration.site import DEFAULT_LATITUDE_DEG
from ..core.exceptions import InputError
from ..core.units import DEG_PER_RAD
from ..core.words import Command, argument
from ..measurement.diagnosis import (
    dense_joint_grid,
    design_command,
    harmonic_basis,
    joint_harmonics,
    mount_option,
    polynomial_basis,
    urdf_option,
)
from ..measurement.effects.base import TURNTABLE
from ..measurement.table import measured_table
from ..model.angles import ANGLE_NAMES
from ..stats.diagnosis_engine import (
    SEPARATION_CHI2,
    DataFamily,
    PageWords,
    SeparationWords,
    diagnose_data,
)
from ..stats.least_squares import zero_point
from ..stats.model_selection import Diagnosis
from ..stats.outliers import outlier_rule_words
from ..stats.structure_search import Probe
from .effects import TABLE, run_catalogue
from .effects.base import RunEffect
from .effects.table_side import TableErrors
from .model import CHANNELS, RunFit, RunModel, fit_run, reference_coefficients, run_context
from .residuals import run_residuals
from .table_errors import table_from_run

__all__ = ["OUTLIER_RULE", "RunFamily", "diagnose_run", "run_design_command", "run_results"]

OUTLIER_RULE = outlier_rule_words("outputs", "the same output channel", "both", "outputs")
"""The outlier rule of :func:`diagnose_run` in words (``turntable_pin.stats.outliers``)."""


class RunFamily(DataFamily):
    """A calibration run, its 14 coefficients and the run catalogue (a ``DataFamily``).

    Args:
        run: the :class:`~turntable_pin.calibration.run.CalibrationRun`.
        catalogue: the candidate effects (default the run catalogue of the run's table).
        mask: (N, 2) the outputs fitted (False: left out as outliers).
        channel_sigma: (2,) relative noise of ``out_x``, ``out_y`` (deg/h) when sigma is unknown
            and they differ: every model is fitted at its own per-output noise, starting from
            these; ``None``: one noise level.
    """

    columns = CHANNELS
    column_key = "output"
    record_label = "positions"
    record_words = "run rows"
    observations = "outputs"
    observation_unit = "dph"
    unit_words = "deg/h"
    user_unit_scale = 1.0
    outlier_rule = OUTLIER_RULE
    machine_kind = TURNTABLE
    noise_subject = "the two outputs'"
    noise_column = "output"
    noise_how = "each output is weighted by its own estimated noise"
    page = PageWords(
        title="GyroWheel calibration run diagnosis",
        page_title="turntable-pin run report",
        sections=(
            ("run_intro", ""),
            ("warnings", ""),
            ("outliers", ""),
            ("base", "1. The base model: eq. 1's 2 x 7 coefficients"),
            ("diagnosis", "2. Which effect is missing: the table or the instrument?"),
            ("added", "3. Add it and watch the error fall"),
            ("run_results", "4. Coefficients and the table"),
        ),
        fit_columns=("rms", "chi2_reduced", "rank", "n_params"),
        candidate_columns=(
            "side",
            "delta_bic",
            "rms",
            "chi2_reduced",
            "added_rank",
            "alternatives",
        ),
        structure_shapes="harmonic shapes of each output and of the table's orientation errors "
        "through the outputs, drifts in time and terms in other columns",
    )

    def __init__(
        self,
        run,
        catalogue: Sequence[RunEffect] | None = None,
        mask: np.ndarray | None = None,
        channel_sigma: np.ndarray | None = None,
    ) -> None:
        self.run = self.data = run
        self.table = measured_table(run.table)
        self.mask = np.ones((run.n_positions, 2), bool) if mask is None else mask
        self.channel_sigma = channel_sigma
        self.context = run_context(run, reference_coefficients(run, self.mask))
        super().__init__(
            catalogue if catalogue is not None else run_catalogue(self.table),
            self.mask,
            sigma_scale=float(np.median(run.sigma_dph)) if run.sigma_dph is not None else 1.0,
            noise_per_column=channel_sigma is not None,
        )

    def fit_model(self, effects: Sequence[RunEffect], zero_point) -> RunFit:
        """The fit of the 14 coefficients plus ``effects`` (:func:`~.model.fit_run`)."""
        return fit_run(self.run, effects, context=self.context, mask=self.mask,
                       channel_sigma=self.channel_sigma, zero_point=zero_point)  # fmt: skip

    def zero_point_of(self, effects: Sequence[RunEffect]):
        """The reduced Jacobian at zero of the coefficients and ``effects``."""
        model = RunModel(self.context, effects, self.mask, self.channel_sigma)
        w = 1.0 / model.sigma if model.sigma is not None else np.ones(model.observed.size)
        jac = model.jacobian(None) * w[:, None]
        res = (model.observed - model.predict(np.zeros(model.n_params))) * w
        return zero_point(model.parameter_names, [(jac, res, w)])

    def initial_column_sigma(self) -> np.ndarray | None:
        """The per-channel levels the outputs are weighted with first."""
        return self.channel_sigma

    def refit(self, fit: RunFit, column_sigma: np.ndarray) -> RunFit:
        """``fit``'s model fitted again with the relative noise ``column_sigma`` (2,) deg/h."""
        return fit_run(self.run, fit.model.effects, context=self.context, mask=self.mask,
                       channel_sigma=column_sigma)  # fmt: skip

    def residual_table(self, fit: RunFit) -> np.ndarray:
        """(N, 2) the residuals of ``fit``, deg/h, NaN where left out."""
        return fit.residuals_dph

    def full_residuals(self, fit: RunFit) -> np.ndarray:
        """(N, 2) the outputs minus ``fit``'s, deg/h, those left out too."""
        return self.run.outputs_dph - fit.fitted_dph

    def residual_set(self, fit: RunFit):
        """The residuals of ``fit`` for the figures (:func:`~.residuals.run_residuals`)."""
        return run_residuals(fit)

    @property
    def source(self) -> str | None:
        """The file the run was read from."""
        return self.run.source

    def sigma_table(self) -> np.ndarray | None:
        """(N, 2) the outputs' sigmas (stated, times the channels' relative noise), or None."""
        run = self.run
        if run.sigma_dph is None and self.channel_sigma is None:
            return None
        rows = np.ones(run.n_positions) if run.sigma_dph is None else run.sigma_dph
        channels = np.ones(2) if self.channel_sigma is None else self.channel_sigma
        return rows[:, None] * channels[None, :]

    @property
    def sigma_given(self) -> bool:
        """Whether the run states its noise (``sigma_dph``)."""
        return self.run.sigma_dph is not None

    @property
    def rows(self) -> np.ndarray:
        """The run file's row number of each position."""
        return self.run.rows

    def without(self, cells: np.ndarray) -> RunFamily:
        """The family on this run with the outputs ``cells`` (N, 2) left out as outliers."""
        return RunFamily(self.run, self.catalogue, self.mask & ~cells, self.channel_sigma)

    def with_column_noise(self, column_sigma: np.ndarray) -> RunFamily:
        """The family on this run with every model fitted at its own per-channel noise,
        starting from ``column_sigma`` (2,) deg/h."""
        return RunFamily(self.run, self.catalogue, self.mask, column_sigma)

    def screen_fit(self, cells: np.ndarray, effects: Sequence[RunEffect]):
        """The fit of base + ``effects`` without the outputs ``cells``, at the reference
        coefficients of the outputs kept."""
        mask = self.mask & ~cells
        context = run_context(self.run, reference_coefficients(self.run, mask))
        return fit_run(self.run, effects, context=context, mask=mask,
                       channel_sigma=self.channel_sigma).result  # fmt: skip

    @property
    def doubt_words(self) -> str:
        """The doubt about the run: the stated sigma, the latitude or the table."""
        return (
            "no catalogued effect of the table or the instrument makes this run; is the stated "
            f"sigma_dph too small, the latitude or the table ({argument('urdf')}) wrong?"
        )

    def complete(self, diagnosis: Diagnosis) -> None:
        """The run's own data in the result (:func:`run_results`)."""
        run_results(diagnosis)

    @property
    def data_columns(self):
        """The run's columns (the :class:`~turntable_pin.calibration.run.CalibrationRun`)."""
        return self.run

    def base_inputs(self) -> set[str]:
        """The joint angles (``phi1``...): the probes in them are not suspects."""
        return {f"phi{k}" for k in range(1, self.run.joint_rad.shape[1] + 1)}

    def design_warnings(self, base_fit: RunFit) -> list[str]:
        """What the positions cannot tell: the coefficients they leave undetermined (and why),
        too few angles for the harmonic shapes."""
        out = []
        undetermined = base_fit.result.undetermined_combinations()
        if undetermined:
            why = gravity_words(self.run.inputs.specific_force_g)
            reason = (
                f"on these positions {'; '.join(why)}, so "
                if why
                else "these positions turn gravity through too few directions, so "
            )
            out.append(
                f"{reason}these coefficients cannot be told apart: "
                + "; ".join(undetermined[:6])
                + " (each is fitted as the combination the positions see; an effect that moves "
                "the outputs the same way is indistinguishable from them; the table's effects are "
                "judged at the minimum-norm coefficients, so a table verdict here is a caution, "
                "not a finding: calibrate at positions that turn gravity through every axis)"
            )
        wrapped = np.round(np.mod(np.degrees(self.run.joint_rad), 360.0), 6) % 360.0
        for k in range(wrapped.shape[1]):
            count = np.unique(wrapped[:, k]).size
            if 1 < count < 5:
                out.append(
                    f"phi{k + 1} takes only {count} distinct angles: k/rev shapes in phi{k + 1} "
                    "of order (count - 1) / 2 and above cannot be tested"
                )
        return out

    def _weights(self, fit: RunFit) -> np.ndarray:
        """(N, 2) the weights of ``fit``'s residuals, 0 where an output was left out."""
        w = np.zeros(self.mask.shape)
        w[self.mask] = fit.result.weights
        return w

    def _shape_probes(self, directions, plot, shape, text, spec) -> list[Probe]:
        """:meth:`shape_probes` of ``directions`` ``(site, description, (N, 2) direction)``,
        each described as ``text`` and its description."""
        sites = [(site, direction, f"{text} {what}") for site, what, direction in directions]
        return self.shape_probes(plot, shape, spec, sites)

    def probes(self, fit: RunFit) -> list[Probe]:
        """The structure-search probes, weighted like the residuals of ``fit`` (module)."""
        run = self.run
        w = self._weights(fit)
        channels = []
        for c, name in enumerate(CHANNELS):
            d = np.zeros_like(w)
            d[:, c] = w[:, c]
            channels.append((name, f"on {name} itself", d))
        sensitivity = fit.model.context.sensitivity
        angles = [
            (name, f"of the table's {name}, through the outputs", sensitivity[:, :, a] * w)
            for a, name in enumerate(ANGLE_NAMES)
        ]
        probes = []
        labels = [f"phi{k}" for k in range(1, run.joint_rad.shape[1] + 1)]
        # each harmonic on each output and through each of the table's angles; those coupling
        # two joint angles on each output only
        for var, values, k, coupled in joint_harmonics(labels, run.joint_rad):
            plot = (var, values, harmonic_basis(k), DEG_PER_RAD, "deg")
            probes += self._shape_probes(
                channels if coupled else channels + angles, plot, f"{k}/rev in {var}",
                f"a {k}/rev term in {var}", f"h{k}({var})",
            )  # fmt: skip
        columns = {"time_s": run.time_s, **run.extra}
        for column, values in columns.items():
            if values is None or not np.ptp(values) > 0:
                continue
            unit = "s" if column == "time_s" else ""
            plot = (column, values, polynomial_basis(values), 1.0, unit)
            shape = "drift in time" if column == "time_s" else f"in {column}"
            probes += self._shape_probes(
                channels, plot, shape, f"a term linear and quadratic in {column}", "poly2("
                f"{column})",
            )  # fmt: skip
        return probes

    def _dense_run(self):
        """The run on a dense grid over every joint within its limits (``dense_joint_grid``),
        time and extra columns spread over their ranges in random order."""
        run = self.run
        joints = dense_joint_grid(self.table)
        positions = PositionSet(joints, table=run.table, name="dense grid")
        inputs = position_inputs(positions, run.inputs.latitude_rad)
        n = len(positions)
        rng = np.random.default_rng(0)

        def spread(v):
            return None if v is None else rng.permutation(np.linspace(v.min(), v.max(), n))

        extra = {k: spread(v) for k, v in run.extra.items()}
        return CalibrationRun(inputs, np.zeros((n, 2)), None, spread(run.time_s), extra)

    def misfit(self, fit_a: RunFit, effect_b: RunEffect, dense: bool) -> float:
        """The noise-free chi2 left when the model with ``effect_b`` instead of ``fit_a``'s last
        effect is fitted to ``fit_a``'s prediction, on the run's positions or (``dense``) on
        :meth:`_dense_run`. Raises :class:`InputError` when ``effect_b`` cannot be evaluated
        there (a column the grid has not)."""
        if dense:
            context = run_context(self._dense_run(), fit_a.model.context.coefficients)
            mask = None
        else:
            context, mask = fit_a.model.context, self.mask
        truth = RunModel(context, fit_a.model.effects, mask).predict(fit_a.result.params)
        model = RunModel(context, [*fit_a.model.effects[:-1], effect_b], mask)
        jac = model.jacobian(None)
        target = truth - model.predict(np.zeros(model.n_params))
        w = 1.0 / model.sigma if model.sigma is not None and not dense else 1.0
        coef = np.linalg.lstsq(jac * np.reshape(w, (-1, 1)), target * w, rcond=None)[0]
        sigma = np.sqrt(fit_a.result.noise_variance)
        if dense:
            sigma *= self.sigma_scale
        return float(np.sum(((target - jac @ coef) * w) ** 2)) / sigma**2

    def dense_misfit(self, fit_a: RunFit, effect_b: RunEffect) -> float:
        """:meth:`misfit` on the dense grid."""
        return self.misfit(fit_a, effect_b, dense=True)

    def separation_words(self) -> SeparationWords:
        """The dense grid in words (its step and size), and the checks."""
        joints = dense_joint_grid(self.table)
        step = "30" if joints.shape[1] > 2 else "15"
        grid = f"{step}-degree grid within the joints' limits ({joints.shape[0]} positions)"
        return SeparationWords(
            grid=grid,
            grid_cannot=grid,
            grid_mimics=grid,
            position="position of the table",
            check="test",
            more_data="calibrating at more varied positions",
        )

    def other_side(self, fit_a: RunFit) -> list[dict]:
        """The effects of the other side that move the outputs like ``fit_a``'s last effect on
        this run's positions (misfit chi2 below :data:`SEPARATION_CHI2`): for an instrument
        effect, the table's errors together (``table:errors``) and each table effect; for a
        table effect, each instrument effect. Each entry: ``effect``, ``side``, ``chi2_run``,
        ``chi2_dense`` (None when not evaluable on the grid) and :meth:`separation`'s ``words``."""

        a = fit_a.model.effects[-1]
        if a.side == TABLE:
            rivals = [e for e in self.catalogue if e.side != TABLE]
        else:
            rivals = [TableErrors(self.table), *(e for e in self.catalogue if e.side == TABLE)]
        out = []
        for b in rivals:
            if self.untestable_reason(b):
                continue
            try:
                chi2_run = self.misfit(fit_a, b, dense=False)
            except InputError:
                continue
            if chi2_run > SEPARATION_CHI2:
                continue
            try:
                chi2_dense = self.misfit(fit_a, b, dense=True)
            except InputError:
                chi2_dense = None
            out.append({"effect": b.name, "side": b.side, "chi2_run": chi2_run,
                        "chi2_dense": chi2_dense, "words": self.separation(fit_a, b)})  # fmt: skip
        return sorted(out, key=lambda e: e["chi2_run"])


def run_design_command(run, pair: tuple[str, str]) -> Command:
    """The ``design`` command that chooses the calibration positions telling the two effects
    apart, or says that none do (:mod:`.separate`), with ``urdf``, ``mount`` and
    ``latitude_deg`` when they are not the defaults (the one
    :func:`~turntable_pin.measurement.diagnosis.design_command`)."""
    latitude = float(np.degrees(run.inputs.latitude_rad))
    default = abs(latitude - DEFAULT_LATITUDE_DEG) <= 1e-9
    return design_command(run.source, pair, urdf_option(run.table), mount_option(run.table),
                          data_argument="run",
                          latitude_deg=None if default else f"{latitude:g}")  # fmt: skip


def diagnose_run(
    run,
    *,
    until_explained: bool = False,
    catalogue: Sequence[RunEffect] | None = None,
    outliers: bool = True,
) -> Diagnosis:
    """Diagnose a calibration run against the run catalogue: ``diagnose_data`` on its
    :class:`RunFamily` (InputError beyond ``MAX_DIAGNOSED_ROWS`` rows)."""
    family = RunFamily(run, catalogue)
    return diagnose_data(family, until_explained=until_explained, outliers=outliers)


def run_results(diagnosis: Diagnosis) -> None:
    """Fill a run diagnosis with the run's own data: the side of every candidate and of the
    verdict and the effects of the other side (``family_verdict``), the ``design`` commands that
    settle each rival, the best model's coefficients and what the run tells about the table
    (``family_results``)."""

    family = diagnosis.family
    run = family.run
    sides = {e.name: e.side for e in family.catalogue}
    named = diagnosis.missing_effects
    side = None if not named else sides[named[0]] if len({sides[n] for n in named}) == 1 else "both"
    other_side = []
    if diagnosis.steps:
        other_side = family.other_side(family.fit(diagnosis.best_fit.model.effects[:1]))
    diagnosis.family_verdict = {"sides": sides, "side": side, "other_side": other_side}
    if diagnosis.steps and run.source:
        rivals = [*diagnosis.separations, *(r["effect"] for r in other_side)]
        known = {e.name for e in family.catalogue}
        diagnosis.separation_commands = {
            name: run_design_command(run, (diagnosis.missing_effect, name))
            for name in dict.fromkeys(rivals)
            if name in known
        }
    best = diagnosis.best_fit.with_noise_variance(diagnosis.noise_variance)
    diagnosis.family_results = {
        "coefficients_dph": best.to_dict()["coefficients_dph"],
        "refit_command": "calibrate",
        "base_label": "the coefficients",
        "source": run.source,
        "latitude_deg": float(np.degrees(run.inputs.latitude_rad)),
        "table_from_run": table_from_run(
            run, family.table, mask=family.mask, context=family.context
        ).to_dict(),
    }

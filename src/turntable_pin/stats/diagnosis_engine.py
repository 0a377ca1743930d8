"""One diagnosis over families of data (as statsmodels' GLM is one engine over families).

A kind of data (orientation measurements, a calibration run's outputs) is a :class:`DataFamily`
supplying only what is its own: its observation columns and unit, the fit of its base model plus
effects, the candidates, the structure search's probes and its words. Written here once:

- the fits of one data set, cached per effect list, sharing one zero point, each refitted at its
  own per-column noise when the columns' noise differ (:meth:`DataFamily.fit`);
- which effect is missing (:func:`~.model_selection.diagnose`), gross outliers left out by the
  stated rule in two passes (:func:`~.outliers.screened_diagnosis`) and listed;
- without sigmas, the F test of the columns' noise and the diagnosis again with a noise level per
  column (:func:`column_noise`);
- the doubt when even the best model stays far from the stated noise (:data:`DOUBT_CHI2_REDUCED`).

:func:`diagnose_data` is the one entry point. The engine carries no domain names or units.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.exceptions import InputError
from ..core.sizes import DIAGNOSIS_ROW_BYTES, MAX_DIAGNOSED_ROWS, check_count
from .model_selection import Diagnosis, diagnose
from .outliers import column_variances, screen_cells, screened_diagnosis, variances_differ
from .structure_search import Probe, ProbeFactors

__all__ = [
    "DATA_PLACEHOLDER",
    "DOUBT_CHI2_REDUCED",
    "NOISE_ITERATIONS",
    "NOISE_PER_COLUMN_ALPHA",
    "NOISE_RTOL",
    "SEPARATION_CHI2",
    "DataFamily",
    "PageWords",
    "SeparationWords",
    "column_noise",
    "column_noise_note",
    "diagnose_data",
    "diagnose_screened",
    "doubt",
    "outlier_records",
    "residual_sets",
]

DOUBT_CHI2_REDUCED = 9.0
"""With sigma given, a best model still this far from the noise (residuals three times the stated
sigma) makes the diagnosis doubt the family itself (another table, a wrong stated sigma)."""

NOISE_PER_COLUMN_ALPHA = 0.01
"""Without sigmas, the observation columns get their own noise level when an F test of their
residual variances rejects equal noise at this level (over the pairs, Bonferroni)."""

NOISE_ITERATIONS = 20
"""Most refits of a model with its own per-column noise (:meth:`DataFamily.own_column_noise`)."""

NOISE_RTOL = 1e-2
"""The per-column noise levels have converged when none moves by more than this fraction (the
profiled likelihood is stationary: what is left changes a score by its square)."""

DATA_PLACEHOLDER = "DATA.csv"
"""The data file a command names when the data were made in memory."""

SEPARATION_CHI2 = 25.0
"""Noise-free misfit chi2 above which a denser set of positions is said to separate two effects
(five sigma)."""


@dataclass(frozen=True)
class PageWords:
    """A family's words for the HTML page of its diagnosis (``report.html_report`` lays it out).

    Attributes:
        title, page_title: the page's heading and the browser's title (when the caller gives none).
        sections: ``(section, heading)`` of each section, in order (empty heading: none).
        fit_columns: the columns of each table of fits, among ``rms``, ``chi2_reduced``,
            ``rank``, ``n_params``, ``p_value``.
        candidate_columns: the columns of the candidates' table, among ``side``, ``delta_bic``,
            ``after_first``, ``rms``, ``chi2_reduced``, ``added_rank``, ``alternatives``.
        parts: the optional parts the page shows, by the report's names.
        structure_shapes: the shapes the structure search tries, in words.
    """

    title: str
    page_title: str
    sections: tuple[tuple[str, str], ...]
    fit_columns: tuple[str, ...] = ("rms", "chi2_reduced", "rank", "n_params", "p_value")
    candidate_columns: tuple[str, ...] = (
        "delta_bic", "rms", "chi2_reduced", "added_rank", "alternatives",
    )  # fmt: skip
    parts: frozenset[str] = frozenset()
    structure_shapes: str = "the probes of the family"


@dataclass(frozen=True)
class SeparationWords:
    """A family's words for :meth:`DataFamily.separation`.

    Attributes:
        grid: the dense set of positions (``on a {grid}``) where no position separates them;
            grid_cannot: where the effect cannot be evaluated; grid_mimics: where they separate.
        position: what one position is (``at every {position}``).
        check: the independent check that tells them apart (``an independent {check}``).
        more_data: what separates two effects that only these positions confuse.
    """

    grid: str
    grid_cannot: str
    grid_mimics: str
    position: str
    check: str
    more_data: str


class DataFamily:
    """A family of data bound to one data set (some cells maybe left out as outliers, maybe a
    noise level per column): what the diagnosis asks of a family. A subclass sets the
    class attributes, calls ``DataFamily.__init__`` and implements the hooks that raise
    ``NotImplementedError`` here; :meth:`complete` may add its own data to the result.

    Attributes:
        columns: the names of the K observation columns of a record.
        column_key: the key naming the column of an outlier record.
        record_label: what a record is (the key ``n_<label>`` of the result).
        record_words: the records in words, for the size limit of a diagnosis.
        observations: the observations in words, plural (the outlier rule's note).
        observation_unit: the key suffix of ``rms_``/``sigma_`` in the result.
        unit_words: the user unit in sentences; user_unit_scale: user units per internal unit.
        outlier_rule: the outlier rule in words (the result's ``outlier_rule``).
        noise_subject, noise_column, noise_how: the words of :func:`column_noise_note`.
        page: the words of the HTML page of its diagnosis (:class:`PageWords`).
        machine_kind: the kind of machine the data come from, the key of the catalogue's
            plausible scales (``CandidateEffect.plausibility``).
        catalogue: the candidate effects (objects with a ``name``), in catalogue order.
        n_records: number of records R; observed: (R, K) the cells fitted here.
        noise_per_column: whether every model is fitted at its own per-column noise.
        sigma_scale: the observations' typical sigma in user units (the unit-weight noise).
    """

    columns: tuple[str, ...] = ()
    column_key: str = "column"
    record_label: str = "records"
    record_words: str = "records"
    observations: str = "observations"
    observation_unit: str = ""
    unit_words: str = ""
    user_unit_scale: float = 1.0
    outlier_rule: str = ""
    noise_subject: str = "the columns'"
    noise_column: str = "column"
    noise_how: str = "each column is weighted by its own estimated noise"
    page: PageWords = PageWords("Diagnosis", "diagnosis", ())
    machine_kind: str = ""

    def __init__(
        self,
        catalogue: Sequence[Any],
        observed: np.ndarray,
        *,
        sigma_scale: float,
        noise_per_column: bool = False,
    ) -> None:
        self.catalogue = tuple(catalogue)
        self.observed = np.asarray(observed, bool)
        self.n_records = int(self.observed.shape[0])
        self.sigma_scale = sigma_scale
        self.noise_per_column = noise_per_column
        self._cache: dict[tuple[str, ...], Any] = {}
        self._zero: tuple[Any] | None = None

    def fit_model(self, effects: Sequence[Any], zero_point) -> Any:
        """The fit (with a ``result``, a ``FitResult``) of the base model plus ``effects``, from
        ``zero_point`` (or None)."""
        raise NotImplementedError

    def zero_point_of(self, effects: Sequence[Any]):
        """The ``least_squares.zero_point`` of the base model plus ``effects`` on these data."""
        raise NotImplementedError

    def refit(self, fit, column_sigma: np.ndarray) -> Any:
        """``fit``'s model refitted at the relative noise ``column_sigma`` (K,) per column."""
        raise NotImplementedError

    def residual_table(self, fit) -> np.ndarray:
        """(R, K) the residuals of ``fit``, NaN where no observation is fitted."""
        raise NotImplementedError

    def full_residuals(self, fit) -> np.ndarray:
        """(R, K) the observed minus ``fit``'s values at every cell, those left out too."""
        raise NotImplementedError

    def residual_set(self, fit):
        """The residuals of ``fit`` for the figures (the family's ``ResidualSet``)."""
        raise NotImplementedError

    @property
    def source(self) -> str | None:
        """The file the data were read from, or None (made in memory)."""
        return None

    def sigma_table(self) -> np.ndarray | None:
        """(R, K) the sigmas of these data (stated, or relative weights), or None."""
        return None

    @property
    def sigma_given(self) -> bool:
        """Whether the data state their noise (then no per-column noise is estimated)."""
        raise NotImplementedError

    @property
    def rows(self) -> np.ndarray:
        """(R,) the row number of each record, as outlier records name it."""
        raise NotImplementedError

    def without(self, cells: np.ndarray) -> DataFamily:
        """The family on these data with the cells ``cells`` (R, K) left out as outliers."""
        raise NotImplementedError

    def with_column_noise(self, column_sigma: np.ndarray) -> DataFamily:
        """The family fitting every model at its own per-column noise, from ``column_sigma``."""
        raise NotImplementedError

    @property
    def data_columns(self):
        """The data's columns (``column(name)``, ``missing_columns_words(names)``)."""
        raise NotImplementedError

    def dense_misfit(self, fit_a, effect_b) -> float:
        """The noise-free chi2 left when the model with ``effect_b`` in place of ``fit_a``'s last
        effect is fitted to ``fit_a``'s signal on dense positions (``InputError``: not there)."""
        raise NotImplementedError

    def separation_words(self) -> SeparationWords:
        """The family's words of :meth:`separation`."""
        raise NotImplementedError

    def screen_fit(self, cells: np.ndarray, effects: Sequence[Any]):
        """The ``FitResult`` of base + ``effects`` without the cells ``cells`` (the screen)."""
        raise NotImplementedError

    @property
    def doubt_words(self) -> str:
        """What the doubt asks when the best model stays far from the stated noise."""
        return "no catalogued effect makes these data; is the stated sigma too small?"

    def complete(self, diagnosis: Diagnosis) -> None:
        """Fill ``diagnosis``'s ``separation_commands``, ``family_verdict``, ``family_results``."""

    def fit(self, effects: Sequence[Any], noise_variance: float | None = None) -> Any:
        """The fit of the base model plus ``effects`` (cached; sharing :meth:`zero_point`; with a
        noise level per column, at its own noise)."""
        key = tuple(e.name for e in effects)
        if key not in self._cache:
            fit = self.fit_model(effects, self.zero_point())
            self._cache[key] = self.own_column_noise(fit) if self.noise_per_column else fit
        return self._cache[key]

    def zero_point(self):
        """The zero point of the base and every testable effect, shared by the family's fits
        (None when they cannot share one model: each fit is then made on its own)."""
        if self._zero is None:
            testable = [e for e in self.catalogue if not self.untestable_reason(e)]
            try:
                self._zero = (self.zero_point_of(testable),)
            except InputError:
                self._zero = (None,)
        return self._zero[0]

    def initial_column_sigma(self) -> np.ndarray | None:
        """The per-column noise (K,) the family's models are weighted with first, or None."""
        return None

    def own_column_noise(self, fit) -> Any:
        """``fit`` refitted at the per-column noise it estimates itself until it settles
        (:data:`NOISE_RTOL`, :data:`NOISE_ITERATIONS`); each observation's column is its group."""
        sigma = self.initial_column_sigma()
        for _ in range(NOISE_ITERATIONS):
            variance, counts, _ = self.column_variances(fit)
            seen = counts > 0
            new = np.sqrt(np.where(seen, variance, np.mean(variance[seen])))
            if sigma is not None and np.all(np.abs(new - sigma) <= NOISE_RTOL * sigma):
                break
            sigma = new
            fit = self.refit(fit, sigma)
        groups = np.broadcast_to(np.arange(self.observed.shape[1]), self.observed.shape)
        result = dataclasses.replace(fit.result, noise_groups=groups[self.observed])
        return dataclasses.replace(fit, result=result)

    def column_variances(self, fit) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(variance, counts, dof)`` of each column's residuals under ``fit``."""
        return column_variances(self.residual_table(fit), fit.result.dof, fit.result.n_obs)

    def untestable_reason(self, effect) -> str | None:
        """Why ``effect`` cannot be tested here (its data columns are missing), or None."""
        columns = self.data_columns
        missing = effect.missing_columns(columns)
        if missing:
            return f"needs the column(s) {columns.missing_columns_words(missing)}"
        return None

    def implausibility(self, effect, fit) -> str | None:
        """What one would have to believe to accept ``effect``'s fitted amplitude in ``fit`` (a
        fit with it) on this family's :attr:`machine_kind`, when it is beyond the physical scale
        its catalogue gives (``effect.implausibility``); else None."""
        judge = getattr(effect, "implausibility", None)
        if judge is None or not self.machine_kind:
            return None
        prefix = f"{effect.name}."
        values = {
            name[len(prefix) :]: entry["value"]
            for name, entry in fit.result.parameter_table().items()
            if name.startswith(prefix)
        }
        return judge(values, self.machine_kind) if values else None

    def separation(self, fit_a, effect_b) -> str:
        """Whether more positions would separate effect A (``fit_a``'s last) from ``effect_b``,
        or only an independent check: :meth:`dense_misfit` against :data:`SEPARATION_CHI2`."""
        a, b = fit_a.model.effects[-1], effect_b
        words = self.separation_words()
        both = f"For {a.name}: {a.confirm} For {b.name}: {b.confirm}"
        try:
            chi2 = self.dense_misfit(fit_a, b)
        except InputError as exc:  # B cannot be evaluated everywhere (infinite somewhere)
            return (
                f"{b.name} cannot be compared with {a.name} on a {words.grid_cannot} "
                f"({exc.detail}); an independent {words.check} tells them apart. {both}"
            )
        if chi2 > SEPARATION_CHI2:
            return (
                f"{b.name} mimics {a.name} on these positions only: on a {words.grid_mimics} it "
                f"would leave chi2 = {chi2:.0f} of misfit at the same noise, so "
                f"{words.more_data} separates them"
            )
        return (
            f"{b.name} reproduces the fitted {a.name} at every {words.position} (noise-free "
            f"misfit chi2 = {chi2:.2g} on a {words.grid}), so no set of positions separates "
            f"them; an independent {words.check} does. {both}"
        )

    def effect(self, name: str):
        """The catalogued effect called ``name``."""
        return next(e for e in self.catalogue if e.name == name)

    def describe(self, effect) -> dict:
        """The effect's story (``effect.describe()``), the effect given or named."""
        return (self.effect(effect) if isinstance(effect, str) else effect).describe()

    def inputs(self, effect) -> set[str]:
        """``effect``'s ``required_columns``: a shape in one is its own kind, not a mimic's."""
        return set(getattr(effect, "required_columns", ()))

    def probes(self, fit) -> list[Probe]:
        """The structure-search probes in the residuals of ``fit``."""
        raise NotImplementedError

    def base_inputs(self) -> set[str]:
        """The base model's own inputs (probes in them are no suspects)."""
        return set()

    def suspect_probes(self, fit) -> list[Probe]:
        """The probes in inputs other than the base model's (``a+b``/``a-b`` of base inputs
        count as base): what an effect may mimic through the measurement order, but not be."""
        own = self.base_inputs()

        def of_base(probe) -> bool:
            variable = probe.factors.variable if probe.factors is not None else ""
            return bool(variable) and set(variable.replace("-", "+").split("+")) <= own

        return [p for p in self.probes(fit) if not of_base(p)]

    def probe(
        self, name: str, description: str, factors: ProbeFactors, spec: str, basis: np.ndarray
    ) -> Probe:
        """A probe: ``factors``' direction (R, K) times ``basis`` (R, g), its functions at the
        data, over the observations fitted; ``spec``: its ``effect_spec``."""
        mask = self.observed.reshape(-1)
        factors = dataclasses.replace(factors, basis=basis)

        def columns():
            cols = factors.direction_matrix()[:, :, None] * basis[:, None, :]
            cols = cols.reshape(-1, cols.shape[-1])
            return cols if mask.all() else cols[mask]

        return Probe(name, description, columns, self.user_unit_scale, self.unit_words, factors,
                     effect_spec=spec)  # fmt: skip

    def shape_probes(self, plot: tuple, shape: str, spec: str, directions) -> list[Probe]:
        """One probe ``<site> <shape>`` (``effect_spec`` ``<site>~<spec>``) per ``(site,
        direction (R, K) or a function giving it, description)`` of ``directions``; ``plot`` is
        ``(variable, values, functions, value scale, unit)``, its basis computed once."""
        var, values, functions, scale, unit = plot
        basis = functions(values)
        probes = []
        for site, direction, description in directions:
            factors = ProbeFactors(var, values, functions, direction, scale, unit, self.observed)
            probes.append(
                self.probe(f"{site} {shape}", description, factors, f"{site}~{spec}", basis)
            )
        return probes


def residual_sets(diagnosis: Diagnosis) -> tuple[Any, Any]:
    """The residual sets of a diagnosis' base and best fits, judged at its noise variance."""
    family = diagnosis.family
    return tuple(
        family.residual_set(fit.with_noise_variance(diagnosis.noise_variance))
        for fit in (diagnosis.base_fit, diagnosis.best_fit)
    )


def diagnose_data(
    family: DataFamily, *, until_explained: bool = False, outliers: bool = True
) -> Diagnosis:
    """Which catalogued effect is missing from ``family``'s data (module docstring).

    ``family`` holds all the data. With ``outliers`` gross outliers are left out by the family's
    rule and listed (:func:`diagnose_screened`). Without sigmas, when the columns' noise differ
    (:func:`column_noise`), the diagnosis is made again at each model's own per-column noise, and
    a warning says so. :func:`doubt` and :meth:`DataFamily.complete` complete the result.

    Raises:
        InputError: more records than :data:`MAX_DIAGNOSED_ROWS` (of ``core.sizes``).
    """
    check_count(family.n_records, MAX_DIAGNOSED_ROWS, family.record_words, DIAGNOSIS_ROW_BYTES)
    diagnosis = diagnose_screened(family, until_explained=until_explained, outliers=outliers)
    if not family.sigma_given:
        noise = column_noise(diagnosis)
        if noise is not None:
            sigma, found = noise
            family = family.with_column_noise(sigma)
            diagnosis = None  # free the first one's fits before the second
            diagnosis = diagnose_screened(family, until_explained=until_explained,
                                          outliers=outliers)  # fmt: skip
            diagnosis.warnings.append(column_noise_note(diagnosis, found))
    diagnosis.doubt = doubt(diagnosis)
    diagnosis.family.complete(diagnosis)
    return diagnosis


def diagnose_screened(
    family: DataFamily, *, until_explained: bool = False, outliers: bool = True
) -> Diagnosis:
    """One pass of :func:`diagnose_data`, with the outlier rule
    (:func:`~.outliers.screened_diagnosis`) or, without ``outliers``, on every observation."""

    def diagnose_without(cells):
        return diagnose(family.without(cells), until_explained=until_explained)

    if not outliers:
        return diagnose_without(np.zeros(family.observed.shape, bool))

    def screen(effects, first):
        def fit_without(flagged):
            if first is not None and not flagged.any():
                return first.result
            return family.screen_fit(flagged, effects)

        return screen_cells(fit_without, family.observed, family.observations)

    return screened_diagnosis(
        diagnose_without,
        screen,
        lambda diagnosis, cells: outlier_records(diagnosis, family, cells),
        family.outlier_rule,
    )


def outlier_records(diagnosis: Diagnosis, family: DataFamily, cells: np.ndarray) -> list[dict]:
    """``{"row", <family.column_key>, "residual_sigma"}`` of each outlier cell under the final
    model, worst first, in the verdict's noise: the best model's per column, else the data's
    sigmas (stated or relative) times the unit-weight noise, else the unit-weight noise."""
    residual = family.full_residuals(diagnosis.best_fit)
    table = family.sigma_table()
    if diagnosis.group_variance is not None:  # per noise group: the columns with observations
        per_column = np.full(cells.shape[1], np.nan)
        per_column[np.unique(diagnosis.best_fit.result.noise_groups)] = diagnosis.group_variance
        sigma = np.broadcast_to(np.sqrt(per_column), cells.shape)
    elif table is not None:
        sigma = table * np.sqrt(diagnosis.noise_variance)
    else:
        sigma = np.full(cells.shape, np.sqrt(diagnosis.noise_variance))
    out = [
        {"row": int(family.rows[i]), family.column_key: family.columns[c],
         "residual_sigma": float(residual[i, c] / sigma[i, c])}
        for i, c in zip(*np.nonzero(cells), strict=True)
    ]  # fmt: skip
    return sorted(out, key=lambda o: -abs(o["residual_sigma"]))


def _levels(family: DataFamily, sigma: np.ndarray, columns) -> str:
    """``name level, ...`` of the columns ``columns`` in the family's user unit."""
    scale = family.user_unit_scale
    return ", ".join(f"{family.columns[c]} {sigma[c] * scale:.3g}" for c in columns)


def column_noise(diagnosis: Diagnosis) -> tuple[np.ndarray, str] | None:
    """Without sigmas, when the columns' noise differ (F test at
    :data:`NOISE_PER_COLUMN_ALPHA`): each column's residual rms under the best model (the mean
    level for a column too small to test) and a sentence; else None."""

    family = diagnosis.family
    variance, counts, dof = family.column_variances(diagnosis.best_fit)
    differ, present = variances_differ(variance, counts, dof, NOISE_PER_COLUMN_ALPHA)
    if not differ:
        return None
    sigma = np.sqrt(variance)
    for c in set(range(len(counts))) - set(present):
        sigma[c] = np.sqrt(np.mean(variance[present]))
    return sigma, (
        f"sigma not given, and {family.noise_subject} noise differ (estimated "
        f"{_levels(family, sigma, present)} {family.unit_words}; F test p < "
        f"{NOISE_PER_COLUMN_ALPHA:g}): {family.noise_how}"
    )


def column_noise_note(diagnosis: Diagnosis, found: str) -> str:
    """The warning of a diagnosis at each model's own per-column noise: why (``found``, from
    :func:`column_noise`) and the best model's levels."""
    family = diagnosis.family
    variance, counts, _ = family.column_variances(diagnosis.best_fit)
    levels = _levels(family, np.sqrt(variance), [c for c in range(len(counts)) if counts[c]])
    return (
        f"{found}; every model was fitted and compared at its own per-{family.noise_column} "
        f"noise (the best model's: {levels} {family.unit_words})"
    )


def doubt(diagnosis: Diagnosis) -> str | None:
    """Why the family itself is in doubt (:data:`DOUBT_CHI2_REDUCED`), or None."""
    best = diagnosis.best_fit.result
    if not best.sigma_known or best.dof <= 0:
        return None
    chi2_reduced = best.rss / best.dof
    if chi2_reduced <= DOUBT_CHI2_REDUCED:
        return None
    return (
        f"with every accepted effect the residuals are still {chi2_reduced**0.5:.1f} times the "
        f"stated noise (chi2_reduced {chi2_reduced:.3g}): {diagnosis.family.doubt_words}"
    )

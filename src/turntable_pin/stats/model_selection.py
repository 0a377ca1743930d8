"""Which catalogued effect is missing from a model: compare, rank, decide, and say so.

Generic over a :class:`ModelFamily` (a base model, a catalogue of effects that extend it, and
probes for the structure search), so any model with a catalogue of extensions can use it.

Decision rule, and why. Each testable effect is fitted together with the current model and
compared by the Bayesian information criterion, ``delta_bic = delta_chi2 + added_rank ln m``
(sigma given) or ``w ln(rss_new / rss_old) + added_rank ln m`` (sigma estimated: the variance
profiled out, ``w`` about the residual degrees of freedom so that the ratio keeps the F test's
tail on small samples, :func:`~.structure_search.profiled_weight`), where ``added_rank`` is the
number of *new* determined combinations (parameters the current model already absorbs do not
count) and ``m`` the number of observations. An effect is
accepted when ``delta_bic <= -6 - 2 ln K`` for the K candidates tested in that round (the
look-elsewhere penalty the structure search pays for its probes: trying K effects is K chances of
a false alarm). On clean data the improvement is chi2-distributed with ``added_rank`` degrees of
freedom, so for m = 432 observations and K = 9 the false-alarm probability of one candidate is
P(chi2_k > k ln m + 10.4): 5e-5 (k=1), 1.4e-5 (k=2); on small designs (m = 72..120, where
``ln m`` is small) the penalty is what keeps the whole catalogue quiet, while an effect of a few
sigma lowers chi2 by hundreds. A plain
likelihood-ratio test at a fixed level would not penalise the 8-parameter
wobble series more than a 1-parameter sag, and BIC does.

Alternatives: effects that are themselves accepted and whose fit is as good as the best one's
(``|chi2_B - chi2_A| <= chi2_0.99(max(added_rank_A, added_rank_B))``) explain the data as well; the
family then says whether more data could separate them or only an independent measurement.

Unexplained: the best model still fails the fit test, i.e. its chi2 p-value is below
``FIT_TEST_ALPHA`` (sigma given), or the structure search finds a term it lacks (any sigma; the
only test possible when sigma is estimated, because chi2 with an estimated sigma is 1 by
construction). The structure search pays a look-elsewhere penalty of ``2 ln G`` for its G probes
(:mod:`structure_search`).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from ..core.blas_threads import one_blas_thread
from ..core.exceptions import IdentifiabilityError, InputError
from .least_squares import FitResult, chi2_quantile, chi2_sf, tall_r_factor
from .structure_search import (
    BIC_THRESHOLD,
    FoundTerm,
    Probe,
    delta_bic,
    profiled_weight,
    search_structure,
)

__all__ = [
    "ALTERNATIVE_LEVEL",
    "DETERMINED_SIGMAS",
    "MAX_CORRELATION",
    "MAX_CORRELATION_ALL",
    "UNDETERMINED_GAIN_RATIO",
    "parameter_determination",
    "undetermined_parameters",
    "acceptance_threshold",
    "FIT_TEST_ALPHA",
    "Candidate",
    "Diagnosis",
    "ModelFamily",
    "Step",
    "compare_effects",
    "diagnose",
]

FIT_TEST_ALPHA = 1e-3
"""A model fails the chi2 goodness-of-fit test when its p-value is below this."""

ALTERNATIVE_LEVEL = 0.99
"""Quantile of chi2(added_rank) within which another effect's fit counts as equally good."""

DETERMINED_SIGMAS = 3.0
"""An effect is significant in its values when one of its parameters reaches this many standard
errors (:func:`undetermined_parameters`)."""

UNDETERMINED_GAIN_RATIO = 2.0
"""A significant undetermined effect still ranks first when it lowers the misfit (rss) by more
than this many times what the best determined one does."""

MAX_CORRELATION = 0.95
"""A parameter is traded off against the base errors above this multiple correlation."""

MAX_CORRELATION_ALL = 0.995
"""... and against all the model's other parameters (its own effect's too) above this one."""


class ModelFamily(Protocol):
    """What :func:`diagnose` needs: fits of base + effects, reasons, probes, separation advice.

    Attributes:
        catalogue: the candidate effects (objects with a ``name``), in catalogue order.
        n_records: number of data records (e.g. rows of a data file).
        record_label: what a record is, for the key ``n_<label>`` of :meth:`Diagnosis.to_dict`.
        observation_unit: name of the observations' user unit (key suffix of ``rms_``/``sigma_``).
        sigma_scale: the observations' typical sigma in user units (the unit-weight noise).
    """

    catalogue: tuple[Any, ...]
    n_records: int
    record_label: str
    observation_unit: str
    sigma_scale: float

    def fit(self, effects: Sequence[Any], noise_variance: float | None = None) -> Any:
        """A fit object with a ``result`` (:class:`FitResult`)."""

    def untestable_reason(self, effect: Any) -> str | None:
        """Why ``effect`` cannot be tested on these data, or None."""

    def probes(self, fit: Any) -> list[Probe]:
        """Candidate shapes for the structure search in the residuals of ``fit``."""

    def separation(self, fit_a: Any, effect_b: Any) -> str:
        """Whether more data could separate the fitted effect of ``fit_a`` from ``effect_b``."""

    def describe(self, effect: Any) -> dict:
        """The effect's story (``title``, ``explanation``, ``confirm``...) for the reports."""

    def design_warnings(self, base_fit: Any) -> list[str]:
        """What the data's design cannot tell (e.g. too few distinct inputs), in words."""

    def suspect_probes(self, fit: Any) -> list[Probe]:
        """Optional: the probes of shapes no catalogued effect has (terms in other inputs of
        the data), tried when judging whether an accepted effect only mimics one of them."""

    def inputs(self, effect: Any) -> set[str]:
        """Optional: the data inputs ``effect`` itself depends on beyond the base model's (a
        drift's time): a suspect shape in one of them is the effect's own kind, not one it
        mimics (the probes' ``factors.variable`` names the inputs)."""


@dataclass
class Candidate:
    """One effect tested against the current model."""

    effect: str
    testable: bool
    reason: str | None = None
    fit: Any = field(default=None, repr=False)
    added_rank: int = 0
    delta_bic: float | None = None
    alternatives: list[str] = field(default_factory=list)
    threshold: float = BIC_THRESHOLD
    parameters: list[dict] = field(default_factory=list)

    @property
    def significant(self) -> bool:
        """Whether the effect lowers BIC by at least its round's threshold (:func:`threshold`)."""
        return self.delta_bic is not None and self.delta_bic <= self.threshold

    @property
    def determined(self) -> bool:
        """Whether the data determine the effect (:func:`parameter_determination`; true when its
        parameters were not examined): at least one of its parameters is determined on its own,
        and every such one is determined (significant, not traded off against the model). The
        parameters that only move along combinations the data cannot see (absorbed into the
        model's errors, or acting on an angle not measured) do not count either way."""
        return not self.parameters or not undetermined_parameters(self.parameters)

    @property
    def undetermined_parameters(self) -> list[str]:
        """The added parameters that make it undetermined (:func:`undetermined_parameters`)."""
        return undetermined_parameters(self.parameters)


def undetermined_parameters(entries: Sequence[dict]) -> list[str]:
    """The names among :func:`parameter_determination` ``entries`` that make an effect
    undetermined; empty: the effect is determined.

    An effect is determined when the data see at least one of its parameters on its own, every
    such parameter is determined (not traded off: :func:`parameter_determination`) and at
    least one is significant (``|value| >=``
    :data:`DETERMINED_SIGMAS` ``std``). Parameters that only move along combinations the data
    cannot see (absorbed into the model's errors, or acting on an angle not measured) count
    neither way; a coefficient determined to be near zero (the 2/rev term of a 1/rev
    eccentricity) is determined, not a flaw.
    """
    seen = [p for p in entries if p["std"] is not None]
    if not seen:
        return [p["name"] for p in entries]
    loose = [p["name"] for p in seen if not p["determined"]]
    if loose:
        return loose
    if not any(p["sigmas"] >= DETERMINED_SIGMAS for p in seen):
        return [p["name"] for p in seen]
    return []


def parameter_determination(
    result: FitResult, names: Sequence[str], base_names: Sequence[str], base_rank: int
) -> list[dict]:
    """Whether the data determine each parameter ``names`` of a fit, in user units.

    Each entry: ``name``, ``value``, ``std`` (None when the parameter is not determined on its
    own: it moves along a combination the data cannot see), ``unit``, ``sigmas``
    (``|value| / std``), ``correlation``, ``correlation_all`` and ``determined``.

    ``correlation`` is the parameter's largest correlation with any combination of the base
    parameters ``base_names``: the multiple correlation ``|P_base J_i| / |J_i|`` of its
    weighted Jacobian column with the span of theirs, cut to ``base_rank`` directions (the
    base model's rank, so that directions a large error makes barely visible at second order
    do not count); ``correlation_all`` the same with all the other parameters (the effect's own
    others too, span cut to the fit's rank - 1). Both are 1 when the parameter is not
    determined alone. A parameter is ``determined`` when ``correlation <=``
    :data:`MAX_CORRELATION` and ``correlation_all <=`` :data:`MAX_CORRELATION_ALL`: it is not
    traded off against the base errors, nor hopelessly against its siblings (the practice of
    pointing-model fitting). Whether the effect as a whole is significant is
    :func:`undetermined_parameters`' question.
    """
    table = result.parameter_table()
    index = {n: i for i, n in enumerate(result.parameter_names)}
    # Angles between columns are those of the small triangular factor R (J = Q R, Q with
    # orthonormal columns): every projection below is done on R, not on the tall Jacobian.
    jac = tall_r_factor(result.jacobian_weighted)

    def span(columns: list[int], rank: int) -> np.ndarray:
        u, _, _ = np.linalg.svd(jac[:, columns], full_matrices=False)
        return u[:, : max(int(rank), 0)]

    base = span([index[n] for n in base_names], base_rank)
    out = []
    for name in names:
        i = index[name]
        entry = table[name]
        std = entry["std"]
        correlation = correlation_all = 1.0
        column = jac[:, i]
        norm = float(np.linalg.norm(column))
        if std is not None and std > 0 and norm > 0:
            correlation = min(float(np.linalg.norm(base.T @ column)) / norm, 1.0)
            others = span([k for k in range(jac.shape[1]) if k != i], result.rank - 1)
            correlation_all = min(float(np.linalg.norm(others.T @ column)) / norm, 1.0)
        out.append(
            {
                "name": name,
                "value": entry["value"],
                "std": std,
                "unit": entry["unit"],
                "sigmas": abs(entry["value"]) / std if std else None,
                "correlation": correlation,
                "correlation_all": correlation_all,
                "determined": bool(
                    std is not None
                    and correlation <= MAX_CORRELATION
                    and correlation_all <= MAX_CORRELATION_ALL
                ),
            }
        )
    return out


def acceptance_threshold(n_testable: int) -> float:
    """The delta_bic an effect must reach when ``n_testable`` candidates are tried at once:
    ``-6 - 2 ln K``, the look-elsewhere penalty of the structure search applied to the catalogue
    (K chances of a false alarm; -6 for a single candidate)."""
    return BIC_THRESHOLD - 2.0 * math.log(max(n_testable, 1))


def _chi2(result: FitResult, noise_variance: float, group_variance=None) -> float:
    """chi2 of ``result`` with the unit-weight ``noise_variance``; with the best model's noise
    per group (``group_variance``, :func:`_group_variance`) for a fit with noise groups, the
    groups' unweighted rss over those variances (every model judged at one noise)."""
    if group_variance is not None and result.noise_groups is not None:
        return float(np.sum(result.group_rss / group_variance))
    return result.rss / noise_variance


def _group_variance(best: FitResult) -> np.ndarray | None:
    """The best model's noise variance per group (its degrees of freedom shared out by the
    groups' sizes), or None without noise groups (or with sigma given)."""
    if best.sigma_known or best.noise_groups is None:
        return None
    _, counts = np.unique(best.noise_groups, return_counts=True)
    return best.group_rss / np.maximum(counts * best.dof / best.n_obs, 1.0)


def _summary(result: FitResult, noise_variance: float, group_variance=None) -> dict:
    chi2 = _chi2(result, noise_variance, group_variance)
    return {
        result.rms_key: result.rms_user,
        "chi2_reduced": chi2 / result.dof if result.dof > 0 else None,
        "n_params": result.n_params,
        "rank": result.rank,
        "p_value": chi2_sf(chi2, result.dof) if result.sigma_known else None,
    }


def compare_effects(family: ModelFamily, current: Sequence[Any], current_fit, candidates):
    """Fit each candidate effect on top of ``current`` and score it (delta_bic vs current)."""
    base = current_fit.result
    m = base.n_obs
    known = 1.0 if base.sigma_known else None
    out = []
    for effect in candidates:
        reason = family.untestable_reason(effect)
        if reason:
            out.append(Candidate(effect.name, False, reason))
            continue
        try:
            fit = family.fit([*current, effect])
        except (IdentifiabilityError, InputError) as exc:  # InputError: not defined here
            out.append(Candidate(effect.name, False, f"cannot be fitted on these data: {exc}"))
            continue
        added = fit.result.rank - base.rank
        if added <= 0:
            names = [c for c in fit.result.undetermined_combinations() if effect.name in c]
            out.append(
                Candidate(
                    effect.name,
                    False,
                    "indistinguishable from the model already fitted on these data: its "
                    "parameters only move along " + "; ".join(names[:4]),
                    fit=fit,
                )
            )
            continue
        dbic = delta_bic(_rss(fit.result), _rss(base), added, m, known, fit.result.rank)
        out.append(Candidate(effect.name, True, None, fit, added, float(dbic)))
    threshold = acceptance_threshold(sum(c.testable for c in out))
    known_names = set(base.parameter_names)
    for c in out:
        c.threshold = threshold
        if c.significant:
            added_names = [n for n in c.fit.result.parameter_names if n not in known_names]
            c.parameters = parameter_determination(
                c.fit.result, added_names, base.parameter_names, base.rank
            )
    # Best first: the significant effects whose parameters are determined, then the others by
    # delta_bic (a richer effect whose extra parameters the data do not determine is not
    # preferred to the simpler one that explains the signal with determined ones) -- unless the
    # undetermined one explains more than twice as much: a determined effect whose gain is
    # small beside it is not the same signal, and is not put first.
    base_rss = _rss(base)

    def gain(c: Candidate) -> float:
        return base_rss - _rss(c.fit.result)

    lead = max((gain(c) for c in out if c.significant and c.determined), default=0.0)

    def preferred(c: Candidate) -> bool:
        return c.significant and (c.determined or gain(c) > UNDETERMINED_GAIN_RATIO * lead)

    out.sort(
        key=lambda c: (
            not c.testable,
            not preferred(c),
            c.delta_bic if c.delta_bic is not None else 0.0,
        )
    )
    return out


def _rss(result: FitResult) -> float:
    """The rss a score compares: the weighted rss with sigma given; with the noise profiled, the
    one of :attr:`FitResult.profiled_rss` (per noise group, each model at its own noise)."""
    return result.rss if result.sigma_known else result.profiled_rss


def _described_rss(result: FitResult, structure, probes) -> float | None:
    """The rss (as :func:`_rss` compares) of ``result`` with the probe columns of the structure
    found added, or None when not comparable (a noise level per group and structure found)."""
    if not structure:
        return _rss(result)
    if result.noise_groups is not None and not result.sigma_known:
        return None
    columns = [result.determined_jacobian_weighted, *_term_columns(structure, probes)]
    return _projected_rss(result.residuals * result.weights, columns)[0]


def _noise_variance(best: FitResult) -> float:
    """Unit-weight noise variance used to report chi2: 1 if sigma given, else the best model's."""
    return 1.0 if best.sigma_known else best.rss / best.dof


def _mark_alternatives(
    candidates: list[Candidate], noise_variance: float, group_variance=None
) -> None:
    accepted = [c for c in candidates if c.significant]
    for a in accepted:
        chi2_a = _chi2(a.fit.result, noise_variance, group_variance)
        a.alternatives = [
            b.effect
            for b in accepted
            if b is not a
            and abs(_chi2(b.fit.result, noise_variance, group_variance) - chi2_a)
            <= chi2_quantile(ALTERNATIVE_LEVEL, max(a.added_rank, b.added_rank, 1))
        ]


@dataclass
class Step:
    """One step of the forward selection (``--until-explained``)."""

    added: str
    delta_bic: float
    fit: Any = field(repr=False)
    candidates: list[Candidate] = field(repr=False, default_factory=list)


@dataclass
class Diagnosis:
    """The outcome of :func:`diagnose`.

    Attributes:
        base_fit: the base model's fit.
        candidates: every catalogued effect tested against the base, best first.
        steps: accepted effects in order (forward selection while delta_bic <= -6; always run,
            because whether structure remains "that no catalogued effect removes" can only be
            judged on the model with every significant effect).
        best_fit: the fit of base + all accepted effects.
        noise_variance: unit-weight variance chi2 is reported with (1 when sigma is given).
        structure: terms the structure search finds in the best model's residuals.
        fails_fit_test: the best model's chi2 p-value is below ``FIT_TEST_ALPHA``.
        separations: advice per alternative of the accepted first effect.
        separation_commands: for entries of ``separations``, the command that would settle
            each (the caller's: e.g. a design of the next measurements); in the JSON, as its
            ``str``, only when there are some.
        until_explained: whether the verdict names every accepted effect (``missing_effects``)
            or the first one, with the others as ``also_significant``.
        after_first: delta_bic of each other effect on top of the first accepted one: an effect
            that only looked significant against a base that lacked the real effect (because
            it soaked up part of that effect's signal) is no longer significant there.
        warnings: what the data's design cannot tell (the family's ``design_warnings``).
        outliers: the records left out as gross outliers (the caller's rule and words; each a
            dict the caller defines), empty when none or when the rule was off.
        outlier_rule: the rule in words, or ``None`` when no rule was applied.
        unneeded_given_structure: effects the forward selection accepted that the best
            description of the data does not need (:func:`_least_needed`), with what removing
            each cost in BIC (below 6): they are not named.
        doubt: the caller's doubt about the model family itself (the data may not come from
            this model at all), said before the verdict; ``None`` when it has none.
        group_variance: with a noise level per group estimated with each model, the best
            model's (:func:`_group_variance`): every fit's chi2 is reported at it.
        family_verdict: the family's own entries of the verdict (JSON-ready; a calibration
            run's side of each effect and the effects of the other side), after the generic ones
            in :meth:`to_dict`; ``separation_commands`` then follow them (they settle the
            family's rivals too).
        family_results: the family's own entries of the result (JSON-ready; a calibration run's
            calibrated coefficients), after the generic ones in :meth:`to_dict`.
    """

    family: Any = field(repr=False)
    base_fit: Any = field(repr=False)
    candidates: list[Candidate]
    steps: list[Step]
    best_fit: Any = field(repr=False)
    noise_variance: float
    structure: list[FoundTerm]
    fails_fit_test: bool
    separations: dict[str, str]
    until_explained: bool
    after_first: dict[str, float | None] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    outliers: list[dict] = field(default_factory=list)
    outlier_rule: str | None = None
    unneeded_given_structure: dict[str, float] = field(default_factory=dict)
    doubt: str | None = None
    group_variance: np.ndarray | None = field(default=None, repr=False)
    separation_commands: dict[str, object] = field(default_factory=dict)
    family_verdict: dict[str, Any] = field(default_factory=dict)
    family_results: dict[str, Any] = field(default_factory=dict)

    @property
    def missing_effect(self) -> str | None:
        """The first accepted effect (the headline of the verdict), or None."""
        return self.steps[0].added if self.steps else None

    @property
    def missing_effects(self) -> list[str]:
        """Every accepted effect with ``until_explained``, else the first one."""
        names = [s.added for s in self.steps]
        return names if self.until_explained else names[:1]

    @property
    def also_significant(self) -> list[str]:
        """Effects still significant on top of the first one (plain diagnosis only)."""
        return [] if self.until_explained else [s.added for s in self.steps[1:]]

    @property
    def alternatives(self) -> list[str]:
        """Effects that explain the data as well as the first accepted one."""
        if not self.steps:
            return []
        first = next(c for c in self.candidates if c.effect == self.steps[0].added)
        return list(first.alternatives)

    @property
    def indistinguishable_from_base(self) -> list[str]:
        """Effects the base model absorbs completely on these data (no new combination)."""
        return [c.effect for c in self.candidates if not c.testable and c.fit is not None]

    @property
    def untestable(self) -> list[str]:
        """Effects whose data columns are missing."""
        return [c.effect for c in self.candidates if not c.testable and c.fit is None]

    @property
    def unexplained(self) -> bool:
        """Whether the best model fails the fit test or structure remains."""
        return bool(self.fails_fit_test or self.structure)

    @property
    def sigma_known(self) -> bool:
        """Whether the observations' sigmas were given (not estimated)."""
        return self.base_fit.result.sigma_known

    def _sigma_user(self) -> float:
        """The noise the verdict uses, in user units: the unit-weight noise times the family's
        typical sigma; with a noise level per group, their rms over the observations."""
        if self.group_variance is None:
            return float(math.sqrt(self.noise_variance) * self.family.sigma_scale)
        best = self.best_fit.result
        _, counts = np.unique(best.noise_groups, return_counts=True)
        pooled = float(np.sum(counts * self.group_variance) / best.n_obs)
        return math.sqrt(pooled) * best.user_unit_scale

    def named_parameters(self) -> dict[str, list[dict]]:
        """``{effect: parameter_determination entries}`` of every named effect in the best fit
        (values, standard errors, correlations with the base errors and with all the others)."""
        result = self.best_fit.result
        prefixes = tuple(f"{s.added}." for s in self.steps)
        base = [n for n in result.parameter_names if not n.startswith(prefixes)]
        out = {}
        for step in self.steps:
            names = [n for n in result.parameter_names if n.startswith(f"{step.added}.")]
            out[step.added] = (
                parameter_determination(result, names, base, self.base_fit.result.rank)
                if names
                else []
            )
        return out

    def _first_threshold(self) -> float:
        """The acceptance threshold of the first round (against the base model)."""
        return next((c.threshold for c in self.candidates if c.testable), BIC_THRESHOLD)

    def summary(self, fit) -> dict:
        """rms, chi2_reduced, rank and p-value of ``fit`` judged with this noise variance."""
        return _summary(fit.result, self.noise_variance, self.group_variance)

    def _candidate_dict(self, c: Candidate) -> dict:
        """One candidate of :meth:`to_dict`."""
        nv, gv = self.noise_variance, self.group_variance
        entry = {
            "effect": c.effect,
            "testable": c.testable,
            "delta_bic": c.delta_bic,
            self.base_fit.result.rms_key: c.fit.result.rms_user if c.fit is not None else None,
            "chi2_reduced": (_summary(c.fit.result, nv, gv)["chi2_reduced"] if c.fit else None),
            "added_rank": c.added_rank,
            "significant": c.significant,
            "alternatives": list(c.alternatives),
            "in_best_model": c.effect in {s.added for s in self.steps},
        }
        if c.parameters:
            entry["determined"] = c.determined
            entry["parameters"] = [dict(p) for p in c.parameters]
        if self.steps and c.effect != self.steps[0].added:
            entry["delta_bic_after_first"] = self.after_first.get(c.effect)
        if c.reason:
            entry["reason"] = c.reason
        return entry

    def _verdict_dict(self) -> dict:
        """The ``verdict`` of :meth:`to_dict`: the generic entries, then the family's own
        (``family_verdict``); the ``separation_commands`` after the rivals they settle."""
        named = {s.added for s in self.steps}
        verdict = {
            "doubt": self.doubt,
            "missing_effect": self.missing_effect,
            "alternatives": self.alternatives,
            "unexplained": self.unexplained,
            "missing_effects": self.missing_effects,
            "also_significant": self.also_significant,
            "fails_fit_test": self.fails_fit_test,
            "remaining_structure": [t.to_dict() for t in self.structure],
            "separations": dict(self.separations),
            "indistinguishable_from_base": self.indistinguishable_from_base,
            "untestable": self.untestable,
            "unneeded_given_structure": [
                {"effect": name, "bic_cost_of_removing": value}
                for name, value in self.unneeded_given_structure.items()
            ],
        }
        if self.separation_commands and not self.family_verdict:
            verdict["separation_commands"] = {
                k: str(c) for k, c in self.separation_commands.items()
            }
        named_parameters = self.named_parameters()
        verdict["named_parameters"] = named_parameters
        loose = {name: undetermined_parameters(e) for name, e in named_parameters.items() if e}
        verdict["named_undetermined"] = {name: names for name, names in loose.items() if names}
        verdict["not_named_undetermined"] = [
            {
                "effect": c.effect,
                "delta_bic": c.delta_bic,
                "undetermined": c.undetermined_parameters,
                "parameters": [dict(p) for p in c.parameters],
            }
            for c in self.candidates
            if c.significant and not c.determined and c.effect not in named
        ]
        if self.missing_effect:
            verdict["effect_story"] = self.family.describe(self.missing_effect)
        verdict.update(copy.deepcopy(self.family_verdict))
        if self.separation_commands and self.family_verdict:
            verdict["separation_commands"] = {
                k: str(c) for k, c in self.separation_commands.items()
            }
        return verdict

    def to_dict(self) -> dict:
        """The spec's diagnosis JSON (plus steps, structure and per-effect explanations), with
        the family's own results last (``family_results``): the one structured result the text
        and HTML reports render."""
        nv, gv = self.noise_variance, self.group_variance
        unit = self.family.observation_unit
        return {
            f"n_{self.family.record_label}": self.family.n_records,
            "n_observations": self.base_fit.result.n_obs,
            "sigma_source": "column" if self.sigma_known else "estimated",
            f"sigma_{unit}" if unit else "sigma": self._sigma_user(),
            "base": _summary(self.base_fit.result, nv, gv),
            "candidates": [self._candidate_dict(c) for c in self.candidates],
            "steps": [
                {"added": s.added, "delta_bic": s.delta_bic, **_summary(s.fit.result, nv, gv)}
                for s in self.steps
            ],
            "best": {
                "effects": [s.added for s in self.steps],
                **_summary(self.best_fit.result, nv, gv),
            },
            "verdict": self._verdict_dict(),
            "warnings": list(self.warnings),
            "outliers": [dict(o) for o in self.outliers],
            "outlier_rule": self.outlier_rule,
            "decision_rule": {
                "accept_effect": f"delta_bic <= {BIC_THRESHOLD:g} - 2 ln K (K testable candidates)",
                "threshold": self._first_threshold(),
                "alternative": f"|chi2 difference| within the {ALTERNATIVE_LEVEL:g} quantile "
                "of chi2(larger added_rank)",
                "fit_test_alpha": FIT_TEST_ALPHA if self.sigma_known else None,
            },
            **copy.deepcopy(self.family_results),
        }


def diagnose(family: ModelFamily, *, until_explained: bool = False) -> Diagnosis:
    """Test every catalogued effect against the base model and decide (module docstring).

    Runs with one BLAS thread (:func:`one_blas_thread` of ``core.blas_threads``): its
    products of tall, thin matrices were many times slower split over the threads of busy
    cores."""
    with one_blas_thread():
        return _diagnose(family, until_explained=until_explained)


def _diagnose(family: ModelFamily, *, until_explained: bool) -> Diagnosis:
    base_fit = family.fit([])
    candidates = compare_effects(family, [], base_fit, family.catalogue)
    steps: list[Step] = []
    current: list[Any] = []
    current_fit = base_fit
    round_candidates = candidates
    after_first: dict[str, float | None] = {}
    while True:
        accepted = [c for c in round_candidates if c.significant]
        if not accepted:
            break
        chosen = accepted[0]
        current.append(next(e for e in family.catalogue if e.name == chosen.effect))
        current_fit = chosen.fit
        steps.append(Step(chosen.effect, float(chosen.delta_bic), chosen.fit, round_candidates))
        rest = [e for e in family.catalogue if e not in current]
        if not rest:
            break
        round_candidates = compare_effects(family, current, current_fit, rest)
        if len(steps) == 1:
            after_first = {c.effect: c.delta_bic for c in round_candidates}
    known = 1.0 if current_fit.result.sigma_known else None
    structure, probes = _search(family, current_fit, known)
    # An accepted effect must explain its own share: judged against the best description of the
    # data -- the other accepted effects *and* the structure found -- not against a model whose
    # chi2 the unexplained structure inflates (a 3/rev term makes any 1/rev effect look good).
    unneeded: dict[str, float] = {}
    while current:
        worst = _least_needed(
            family, current, current_fit, structure, probes, known, candidates[0].threshold
        )
        if worst is None:
            break
        name, dbic = worst
        unneeded[name] = dbic
        current = [e for e in current if e.name != name]
        current_fit = family.fit(current)
        structure, probes = _search(family, current_fit, known)
    if unneeded:
        # The final description (the effects kept and the structure found) never fits worse
        # than a determined candidate it passed over: one that alone leaves less misfit is put
        # back first.
        kept = {e.name for e in current}
        described = _described_rss(current_fit.result, structure, probes)
        better = [
            c
            for c in candidates
            if c.significant
            and c.determined
            and c.effect not in kept
            and described is not None
            and _rss(c.fit.result) < described
        ]
        if better:
            restored = better[0].effect
            unneeded.pop(restored, None)
            current = [next(e for e in family.catalogue if e.name == restored), *current]
            current_fit = family.fit(current)
            structure, probes = _search(family, current_fit, known)
        steps = _steps_of(family, current, base_fit)
    best = current_fit.result
    noise_variance = _noise_variance(best)
    group_variance = _group_variance(best)
    _mark_alternatives(candidates, noise_variance, group_variance)
    fails = bool(best.sigma_known and best.dof > 0 and best.p_value < FIT_TEST_ALPHA)
    separations = {}
    if steps:
        first = next(c for c in candidates if c.effect == steps[0].added)
        named = {s.added for s in steps}
        # The equally good alternatives, and the significant candidates not named because
        # their parameters are not determined: each may be the same signal under another name.
        passed_over = [
            c.effect
            for c in candidates
            if c.significant and not c.determined and c.effect not in named
        ]
        for name in dict.fromkeys([*first.alternatives, *passed_over]):
            effect = next(e for e in family.catalogue if e.name == name)
            separations[name] = family.separation(first.fit, effect)
    return Diagnosis(
        family=family,
        base_fit=base_fit,
        candidates=candidates,
        steps=steps,
        best_fit=current_fit,
        noise_variance=noise_variance,
        structure=structure,
        fails_fit_test=fails,
        separations=separations,
        until_explained=until_explained,
        after_first=after_first,
        warnings=list(family.design_warnings(base_fit)),
        unneeded_given_structure=unneeded,
        group_variance=group_variance,
    )


def _search(
    family, fit, known, max_terms: int = 5, suspects_only: bool = False, skip_inputs=frozenset()
) -> tuple[list[FoundTerm], list[Probe]]:
    """The structure search in the residuals of ``fit``, with the probes it used (with
    ``suspects_only``, the family's ``suspect_probes`` when it has them, without those in the
    inputs ``skip_inputs``)."""
    if suspects_only and hasattr(family, "suspect_probes"):
        probes = [
            p
            for p in family.suspect_probes(fit)
            if p.factors is None or p.factors.variable not in skip_inputs
        ]
    else:
        probes = family.probes(fit)
    result = fit.result
    found = search_structure(
        result.residuals * result.weights,
        result.determined_jacobian_weighted,
        probes,
        noise_variance=known,
        max_terms=max_terms,
    )
    return found, probes


def _projected_rss(residuals: np.ndarray, blocks: Sequence[np.ndarray]) -> tuple[float, int]:
    """The rss of ``residuals`` (m,) left after projecting out the columns of ``blocks`` (tall
    matrices side by side), and their rank; residuals (m, g) give the sum over their columns.

    From the small Gram matrix of the unit-normalised columns (no tall matrix is copied or
    decomposed): ``rss = r.r - b^T G^+ b`` with ``b`` the columns' products with ``r``; the
    directions with eigenvalues below 1e-12 of the largest (singular values below 1e-6) are not
    in the span.
    """
    k = sum(b.shape[1] for b in blocks)
    gram = np.zeros((k, k))
    along = np.zeros((k, *residuals.shape[1:]))
    starts = np.cumsum([0] + [b.shape[1] for b in blocks])
    for i, a in enumerate(blocks):
        along[starts[i] : starts[i + 1]] = a.T @ residuals
        for j in range(i, len(blocks)):
            block = a.T @ blocks[j]
            gram[starts[i] : starts[i + 1], starts[j] : starts[j + 1]] = block
            gram[starts[j] : starts[j + 1], starts[i] : starts[i + 1]] = block.T
    # Unit-normalised columns (zero columns left out), scaled on the small matrices: no copy of
    # the tall blocks.
    norms = np.sqrt(np.diag(gram))
    nonzero = norms > 0
    scale = 1.0 / norms[nonzero]
    gram = gram[np.ix_(nonzero, nonzero)] * scale[:, None] * scale[None, :]
    along = along[nonzero] * scale.reshape(-1, *([1] * (along.ndim - 1)))
    values, vectors = np.linalg.eigh(gram)
    keep = values > 1e-12 * max(float(values.max(initial=0.0)), 1e-300)
    coordinates = (vectors[:, keep].T @ along).reshape(int(keep.sum()), -1)
    explained = float(np.sum(coordinates**2 / values[keep, None]))
    return max(float(np.sum(residuals**2)) - explained, 0.0), int(keep.sum())


def _least_needed(family, current, current_fit, structure, probes, known, threshold):
    """The accepted effect least needed in the best description of the data, with what removing
    it costs in BIC, or ``None`` when every accepted effect still earns its place.

    The best description is the accepted effects plus the structure found on top of them. An
    effect E earns its place when removing it costs at least ``-threshold`` (the acceptance
    rule itself, :func:`acceptance_threshold`), judged two ways:

    - with the same structure: an effect that only soaked up part of a structure it does not
      explain (a backlash taking a little of a 3/rev term) costs little to remove;
    - with the structure the search finds, among the family's suspect shapes (terms in inputs
      no catalogued effect depends on: time, other columns), in the residuals of the model
      without E (what E was standing for), when that structure is not E's own shape (it lies
      outside the span of the model with E) and fits the data at least as well as E does: then
      E is a mimic of a shape it does not have (an 8-parameter wobble following a slow
      temperature change through the measurement order), and the found shape describes the
      data better. When the found shape is E's own (a step with dir where E is a backlash) or
      fits worse, E is kept: it is the
      physical hypothesis, and its extra harmonics are not held against it.

    Each structure term pays the search's look-elsewhere penalty ``2 ln G`` besides its
    parameters. Linearised at the fits: the structure's probe columns join each model's
    Jacobian (the models are nearly linear).
    """
    m = current_fit.result.n_obs
    penalty = 2.0 * math.log(max(len(probes), 1))
    # With a noise level per group estimated with each model, the fits carry different
    # weights: they are all judged in the weights of the best description (its own noise
    # levels, unit variance there), as with sigma given.
    reference = None
    score_known = known
    if known is None and current_fit.result.noise_groups is not None:
        reference, score_known = current_fit.result.weights, 1.0

    def projected(fit, terms, term_probes, own_probes=False) -> tuple[float, int]:
        """(rss, rank) of ``fit`` with the probe columns of ``terms`` added (``own_probes``:
        the probes were weighted like ``fit``, not like the best description)."""
        result = fit.result
        columns = [result.determined_jacobian_weighted, *_term_columns(terms, term_probes)]
        if reference is None:
            return _projected_rss(result.residuals * result.weights, columns)
        scale = (reference / result.weights)[:, None]
        columns = [c * scale if k == 0 or own_probes else c for k, c in enumerate(columns)]
        return _projected_rss(result.residuals * reference, columns)

    full_rss, full_rank = projected(current_fit, structure, probes)
    # With the variance profiled, ln(rss) weighs as in delta_bic, with the residual degrees of
    # freedom of the best description (the larger model of each comparison).
    weight = profiled_weight(m, full_rank, 2)

    def score(fit, terms, term_probes, own_probes=False) -> tuple[float, float]:
        """(BIC, its fit part) of ``fit`` with the probe columns of ``terms`` added."""
        return bic(*projected(fit, terms, term_probes, own_probes), len(terms))

    def bic(rss: float, rank: int, n_terms: int) -> tuple[float, float]:
        if score_known is not None:
            fit_term = rss / score_known
        else:
            fit_term = weight * math.log(max(rss, 1e-300))
        return fit_term + rank * math.log(m) + penalty * n_terms, fit_term

    full, full_fit = bic(full_rss, full_rank, len(structure))
    worst = None
    for effect in current:
        try:
            without = family.fit([e for e in current if e is not effect])
        except IdentifiabilityError:
            continue
        # Structure terms describe what remains after the catalogued effects: when they span
        # E's own signal (a harmonic of the very error E moves), E is the physical name of
        # that signal and is not judged against them.
        costs = []
        if not _duplicated(current_fit.result, without.result, structure, probes):
            costs.append(score(without, structure, probes)[0] - full)
        # What E stood for, in at most two shapes (more would pay more than E's own
        # parameters in penalties), among inputs E does not depend on itself (a drift in time
        # is a thermal drift's own kind) and in no more parameters than E adds (a physical
        # effect does not lose to a generic shape with more parameters).
        inputs = family.inputs(effect) if hasattr(family, "inputs") else set()
        own, own_probes = _search(
            family, without, known, max_terms=2, suspects_only=True, skip_inputs=inputs
        )
        if (
            own
            and sum(len(t.coefficients) for t in own)
            <= current_fit.result.rank - without.result.rank
            and not _within(own, own_probes, current_fit.result.determined_jacobian_weighted)
        ):
            bic_own, fit_own = score(without, own, own_probes, own_probes=True)
            if fit_own <= full_fit:
                costs.append(bic_own - full)
        if not costs:
            continue
        cost = float(min(costs))
        if cost < -threshold and (worst is None or cost < worst[1]):
            worst = (effect.name, cost)
    return worst


OWN_SHAPE_FRACTION = 0.05
"""A found shape is an effect's own when less than this fraction of its columns (Frobenius norm)
lies outside the span of the model with the effect."""


def _inside(columns: np.ndarray, blocks: Sequence[np.ndarray]) -> bool:
    """Whether ``columns`` lie (up to :data:`OWN_SHAPE_FRACTION` of their Frobenius norm) in
    the span of the tall ``blocks`` side by side."""
    outside = _projected_rss(columns, blocks)[0]
    return bool(outside <= OWN_SHAPE_FRACTION**2 * float(np.sum(columns**2)))


def _term_columns(terms, term_probes) -> list[np.ndarray]:
    """The probe columns of the structure ``terms``, one block per term."""
    by_name = {p.name: p for p in term_probes}
    return [by_name[t.name].matrix() for t in terms]


def _duplicated(full: FitResult, without: FitResult, terms, term_probes) -> bool:
    """Whether the columns of the effect that ``full`` has and ``without`` lacks lie in the span
    of ``without``'s Jacobian and the probe columns of the structure ``terms`` (:func:`_inside`):
    the structure then describes the effect's own signal."""
    if not terms:
        return False
    known = set(without.parameter_names)
    own = [i for i, n in enumerate(full.parameter_names) if n not in known]
    if not own:
        return False
    blocks = [without.determined_jacobian_weighted, *_term_columns(terms, term_probes)]
    return _inside(full.jacobian_weighted[:, own], blocks)


def _within(terms, term_probes, jacobian_weighted: np.ndarray) -> bool:
    """Whether the probe columns of ``terms`` lie in the span of ``jacobian_weighted``
    (:func:`_inside`)."""
    return _inside(np.concatenate(_term_columns(terms, term_probes), axis=1), [jacobian_weighted])


def _steps_of(family, effects, base_fit) -> list[Step]:
    """The forward-selection steps of ``effects`` in their order (each fit cached by the
    family), with the delta_bic of each against the previous model."""
    steps = []
    previous = base_fit
    known = 1.0 if base_fit.result.sigma_known else None
    for k in range(len(effects)):
        fit = family.fit(effects[: k + 1])
        added = fit.result.rank - previous.result.rank
        result = fit.result
        dbic = delta_bic(
            _rss(result), _rss(previous.result), added, result.n_obs, known, result.rank
        )
        steps.append(Step(effects[k].name, float(dbic), fit, []))
        previous = fit
    return steps

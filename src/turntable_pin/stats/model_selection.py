"""Which catalogued effect is missing from a model: compare, rank, decide, and say so.

Generic over a family of data (:class:`~.diagnosis_engine.DataFamily`: a base model, a catalogue
of effects that extend it, probes for the structure search, its words).

Decision rule. Each testable effect is fitted with the current model and scored by BIC,
``delta_bic = delta_chi2 + added_rank ln m`` (sigma given) or ``w ln(rss_new / rss_old) +
added_rank ln m`` (sigma estimated, the variance profiled out; ``w`` about the residual degrees of
freedom so that the ratio keeps the F test's tail on small samples,
:func:`~.structure_search.profiled_weight`); ``added_rank`` counts only the *new* determined
combinations, ``m`` the observations. An effect is accepted when ``delta_bic <= -6 - 2 ln K`` for
the K candidates of the round: trying K effects is K chances of a false alarm, the look-elsewhere
penalty the structure search pays too. On clean data (m = 432, K = 9) one candidate's false-alarm
probability is P(chi2_k > k ln m + 10.4): 5e-5 (k=1), 1.4e-5 (k=2); on small designs (m = 72..120)
the penalty keeps the catalogue quiet, while an effect of a few sigma lowers chi2 by hundreds. A
plain likelihood-ratio test at a fixed level would not penalise an 8-parameter wobble series more
than a 1-parameter sag; BIC does.

Alternatives: accepted effects whose fit is as good as the best one's (``|chi2_B - chi2_A| <=
chi2_0.99(max(added_rank_A, added_rank_B))``); the family says whether more data could separate
them or only an independent measurement.

Parsimony over sets: when a round's chosen effect adds several parameters, a small beam search
(:func:`_simpler_set`) asks whether a set of two or three simpler candidates, with no more added
rank in all, reaches a BIC at least as good; if so the set is named instead (several simple causes
at once, not one many-parameter effect that absorbs them), and the comparison is recorded either
way (:class:`SetComparison`).

Plausible amplitudes: the family says whether an effect's fitted amplitude is beyond the physical
scale of its kind on the machine (``family.implausibility``); such a candidate is marked
``implausible`` with what one would have to believe, and is never named.

Unexplained: the best model's chi2 p-value is below ``FIT_TEST_ALPHA`` (sigma given), or the
structure search finds a term it lacks (any sigma; the only test when sigma is estimated, chi2
being 1 by construction then), paying ``2 ln G`` for its G probes (:mod:`structure_search`).
"""

from __future__ import annotations

import copy
import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core.blas_threads import one_blas_thread
from ..core.exceptions import IdentifiabilityError, InputError
from ..core.notebook import NotebookResult
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
    "column_span",
    "multiple_correlations",
    "UNDETERMINED_GAIN_RATIO",
    "parameter_determination",
    "undetermined_parameters",
    "acceptance_rule",
    "acceptance_threshold",
    "FIT_TEST_ALPHA",
    "Candidate",
    "Diagnosis",
    "SET_BEAM_WIDTH",
    "SET_MAX_SIZE",
    "SET_POOL_SIZE",
    "SET_TIE",
    "SetComparison",
    "Step",
    "compare_effects",
    "diagnose",
]

FIT_TEST_ALPHA = 1e-3
"""A model fails the chi2 goodness-of-fit test when its p-value is below this."""

ALTERNATIVE_LEVEL = 0.99
"""Quantile of chi2(added_rank) within which another effect's fit counts as equally good."""

DETERMINED_SIGMAS = 3.0
"""An effect is significant in its values when a parameter reaches this many standard errors."""

UNDETERMINED_GAIN_RATIO = 2.0
"""A significant undetermined effect still ranks first when it lowers the misfit (rss) by more
than this many times what the best determined one does."""

MAX_CORRELATION = 0.95
"""A parameter is traded off against the base errors above this multiple correlation."""

MAX_CORRELATION_ALL = 0.995
"""... and against all the model's other parameters (its own effect's too) above this one."""

SET_MAX_SIZE = 3
"""Largest set of simpler effects :func:`_simpler_set` compares with a many-parameter effect."""

SET_BEAM_WIDTH = 3
"""Sets kept at each size of :func:`_simpler_set`'s beam search."""

SET_POOL_SIZE = 8
"""The simpler candidates (best delta_bic first) :func:`_simpler_set` draws its sets from."""

SET_TIE = 1e-9
"""Relative difference of delta_bic within which a set and an effect fit equally (rounding)."""


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
    implausible: str | None = None
    """What one would have to believe to accept its fitted amplitude (beyond the physical scale
    of its kind on the machine), or None: plausible, or not judged."""

    @property
    def acceptable(self) -> bool:
        """Whether it may be named: significant and its amplitude plausible."""
        return self.significant and self.implausible is None

    @property
    def significant(self) -> bool:
        """Whether the effect lowers BIC by at least its round's threshold."""
        return self.delta_bic is not None and self.delta_bic <= self.threshold

    @property
    def determined(self) -> bool:
        """Whether the data determine the effect (:func:`undetermined_parameters` is empty;
        true when its parameters were not examined)."""
        return not self.parameters or not undetermined_parameters(self.parameters)

    @property
    def undetermined_parameters(self) -> list[str]:
        """The added parameters that make it undetermined (:func:`undetermined_parameters`)."""
        return undetermined_parameters(self.parameters)


def undetermined_parameters(entries: Sequence[dict]) -> list[str]:
    """The names among :func:`parameter_determination` ``entries`` that make an effect
    undetermined; empty: determined.

    Determined: the data see at least one parameter on its own, every such one is determined (not
    traded off) and one is significant (``|value| >= DETERMINED_SIGMAS std``). Parameters moving
    only along combinations the data cannot see count neither way; a coefficient determined to be
    near zero (the 2/rev term of a 1/rev eccentricity) is determined, not a flaw.
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

    Each entry: ``name``, ``value``, ``std`` (None when not determined on its own), ``unit``,
    ``sigmas`` (``|value| / std``), ``correlation``, ``correlation_all`` and ``determined``.
    ``correlation`` is the multiple correlation ``|P_base J_i| / |J_i|`` of the parameter's
    weighted Jacobian column with the span of the base parameters', cut to ``base_rank``
    directions (directions a large error makes barely visible at second order do not count);
    ``correlation_all`` the same with all the other parameters (span cut to the fit's rank - 1).
    Both are 1 when the parameter is not determined alone. ``determined``: ``correlation <=
    MAX_CORRELATION`` and ``correlation_all <= MAX_CORRELATION_ALL`` (pointing-model practice).
    """
    table = result.parameter_table()
    index = {n: i for i, n in enumerate(result.parameter_names)}
    # Angles between columns are those of R (J = Q R): every projection is done on the small R.
    jac = tall_r_factor(result.jacobian_weighted)
    base = column_span(jac, [index[n] for n in base_names], base_rank)
    out = []
    for name in names:
        i = index[name]
        entry = table[name]
        std = entry["std"]
        correlation = correlation_all = 1.0
        if std is not None and std > 0 and np.linalg.norm(jac[:, i]) > 0:
            correlation, correlation_all = multiple_correlations(jac, i, base, result.rank)
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


def column_span(matrix: np.ndarray, columns: Sequence[int], rank: int) -> np.ndarray:
    """An orthonormal basis of the span of ``matrix[:, columns]`` cut to ``rank`` directions."""
    u, _, _ = np.linalg.svd(matrix[:, list(columns)], full_matrices=False)
    return u[:, : max(int(rank), 0)]


def multiple_correlations(matrix, i: int, base: np.ndarray, rank: int) -> tuple[float, float]:
    """The multiple correlations (at most 1) of column ``i`` of ``matrix`` with the orthonormal
    ``base`` and with the span of its other columns cut to ``rank - 1`` directions."""
    column = matrix[:, i]
    norm = float(np.linalg.norm(column))
    others = column_span(matrix, [k for k in range(matrix.shape[1]) if k != i], rank - 1)
    return (
        min(float(np.linalg.norm(base.T @ column)) / norm, 1.0),
        min(float(np.linalg.norm(others.T @ column)) / norm, 1.0),
    )


def acceptance_rule() -> str:
    """The decision rule in words, the one text every output states it with (help, text, JSON,
    HTML): ``delta_bic <= -6 - 2 ln K (K testable candidates)``, from :data:`BIC_THRESHOLD`."""
    return f"delta_bic <= {BIC_THRESHOLD:g} - 2 ln K (K testable candidates)"


def acceptance_threshold(n_testable: int) -> float:
    """The delta_bic an effect must reach when ``n_testable`` candidates are tried at once:
    ``-6 - 2 ln K`` (K chances of a false alarm)."""
    return BIC_THRESHOLD - 2.0 * math.log(max(n_testable, 1))


def _chi2(result: FitResult, noise_variance: float, group_variance=None) -> float:
    """chi2 of ``result`` at the unit-weight ``noise_variance``; with noise groups and the best
    model's ``group_variance``, the groups' unweighted rss over it (one noise for every model)."""
    if group_variance is not None and result.noise_groups is not None:
        return float(np.sum(result.group_rss / group_variance))
    return result.rss / noise_variance


def _group_variance(best: FitResult) -> np.ndarray | None:
    """The best model's noise variance per group (its dof shared out by the groups' sizes), or
    None without noise groups (or with sigma given)."""
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


def _scored(family, current, base: FitResult, effect) -> Candidate:
    """``effect`` fitted on top of ``current`` and scored against ``base`` (delta_bic)."""
    reason = family.untestable_reason(effect)
    if reason:
        return Candidate(effect.name, False, reason)
    try:
        fit = family.fit([*current, effect])
    except (IdentifiabilityError, InputError) as exc:  # InputError: not defined here
        return Candidate(effect.name, False, f"cannot be fitted on these data: {exc}")
    added = fit.result.rank - base.rank
    if added <= 0:
        names = [c for c in fit.result.undetermined_combinations() if effect.name in c]
        reason = "indistinguishable from the model already fitted on these data: its parameters "
        reason += "only move along " + "; ".join(names[:4])
        return Candidate(effect.name, False, reason, fit=fit)
    return Candidate(effect.name, True, None, fit, added, _delta_bic(fit.result, base))


def _delta_bic(result: FitResult, previous: FitResult) -> float:
    """delta_bic of ``result`` against the smaller model ``previous`` (its added rank)."""
    known = 1.0 if previous.sigma_known else None
    added = result.rank - previous.rank
    dbic = delta_bic(_rss(result), _rss(previous), added, result.n_obs, known, result.rank)
    return float(dbic)


def compare_effects(family, current: Sequence[Any], current_fit, candidates):
    """Fit each candidate effect on top of ``current`` and score it (delta_bic vs current),
    best first."""
    base = current_fit.result
    out = [_scored(family, current, base, effect) for effect in candidates]
    threshold = acceptance_threshold(sum(c.testable for c in out))
    known_names = set(base.parameter_names)
    for c, effect in zip(out, candidates, strict=True):
        c.threshold = threshold
        if c.testable:
            c.implausible = _implausibility(family, effect, c.fit)
        if c.significant:
            added_names = [n for n in c.fit.result.parameter_names if n not in known_names]
            c.parameters = parameter_determination(
                c.fit.result, added_names, base.parameter_names, base.rank
            )
    # Best first: the significant determined effects, then the others by delta_bic (a richer
    # effect whose extra parameters are undetermined is not preferred to the simpler one) --
    # unless the undetermined one explains more than UNDETERMINED_GAIN_RATIO times as much.
    base_rss = _rss(base)

    def gain(c: Candidate) -> float:
        return base_rss - _rss(c.fit.result)

    lead = max((gain(c) for c in out if c.acceptable and c.determined), default=0.0)

    def preferred(c: Candidate) -> bool:
        return c.acceptable and (c.determined or gain(c) > UNDETERMINED_GAIN_RATIO * lead)

    out.sort(
        key=lambda c: (
            not c.testable,
            not preferred(c),
            c.delta_bic if c.delta_bic is not None else 0.0,
        )
    )
    return out


def _implausibility(family, effect, fit) -> str | None:
    """The family's :meth:`~.diagnosis_engine.DataFamily.implausibility` of ``effect`` in
    ``fit`` (None for a family that judges none)."""
    judge = getattr(family, "implausibility", None)
    return judge(effect, fit) if judge is not None else None


def _rss(result: FitResult) -> float:
    """The rss a score compares: weighted with sigma given, else :attr:`FitResult.profiled_rss`."""
    return result.rss if result.sigma_known else result.profiled_rss


def _described_rss(result: FitResult, structure, probes) -> float | None:
    """:func:`_rss` of ``result`` with the found structure's probe columns added, or None when
    not comparable (a noise level per group and structure found)."""
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


@dataclass(frozen=True)
class SetComparison:
    """A many-parameter effect a round of the forward selection chose, against the best set of
    simpler effects :func:`_simpler_set` found (with no more added rank in all).

    Attributes:
        step: the step (1 = the first) whose choice was compared.
        effect: the many-parameter effect; added_rank, delta_bic: its own, against the model
            before the step.
        simpler: the set's effects (empty: no simpler candidates to compare); set_added_rank,
            set_delta_bic: the set's, against the same model (None when empty).
        chosen: whether the set was named instead (its BIC at least as good).
    """

    step: int
    effect: str
    added_rank: int
    delta_bic: float
    simpler: tuple[str, ...]
    set_added_rank: int | None
    set_delta_bic: float | None
    chosen: bool

    def to_dict(self) -> dict:
        """The comparison in the diagnosis JSON."""
        return {
            "step": self.step,
            "effect": self.effect,
            "added_rank": self.added_rank,
            "delta_bic": self.delta_bic,
            "simpler_set": list(self.simpler),
            "set_added_rank": self.set_added_rank,
            "set_delta_bic": self.set_delta_bic,
            "set_named": self.chosen,
        }


@dataclass
class Step:
    """One step of the forward selection (``until_explained``)."""

    added: str
    delta_bic: float
    fit: Any = field(repr=False)
    candidates: list[Candidate] = field(repr=False, default_factory=list)


@dataclass
class Diagnosis(NotebookResult):
    """The outcome of :func:`diagnose`.

    Attributes:
        candidates: every catalogued effect tested against the base, best first.
        steps: accepted effects in order (forward selection, always run: remaining structure
            is judged on the model with every significant effect); best_fit: with them all.
        noise_variance: unit-weight variance chi2 is reported with (1 when sigma is given).
        structure: terms the structure search finds in the best model's residuals.
        separations: advice per alternative of the first effect; separation_commands: the
            caller's command settling each (in the JSON only when there are some).
        until_explained: whether the verdict names every accepted effect or the first one.
        after_first: delta_bic of each other effect on top of the first accepted one.
        outliers: the records left out (the caller's dicts); outlier_rule: the rule in words.
        unneeded_given_structure: accepted effects the best description does not need, with
            the BIC cost of removing each (:func:`_least_needed`): not named.
        set_comparisons: each many-parameter choice compared with a set of simpler effects
            (:class:`SetComparison`); named_together: the set named at the first step instead
            of one many-parameter effect (empty: none), the verdict's headline.
        implausible_in_best: accepted effects left out at the end because their amplitude in
            the final fit was implausible (``{name: what one would have to believe}``).
        doubt: the caller's doubt about the model family itself, said before the verdict.
        group_variance: with a noise level per group, the best model's (every chi2 is at it).
        family_verdict, family_results: the family's own entries of the verdict and result,
            after the generic ones.
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
    set_comparisons: list[SetComparison] = field(default_factory=list)
    named_together: list[str] = field(default_factory=list)
    implausible_in_best: dict[str, str] = field(default_factory=dict)
    doubt: str | None = None
    group_variance: np.ndarray | None = field(default=None, repr=False)
    separation_commands: dict[str, Any] = field(default_factory=dict)
    family_verdict: dict[str, Any] = field(default_factory=dict)
    family_results: dict[str, Any] = field(default_factory=dict)

    @property
    def missing_effect(self) -> str | None:
        """The first accepted effect (the headline of the verdict), or None."""
        return self.steps[0].added if self.steps else None

    @property
    def missing_effects(self) -> list[str]:
        """Every accepted effect with ``until_explained``, else the first one (every one, when a
        set of simpler effects was named at the first step)."""
        names = [s.added for s in self.steps]
        return names if self.until_explained else names[: self._first_named()]

    @property
    def also_significant(self) -> list[str]:
        """Effects still significant on top of the first one (plain diagnosis only)."""
        names = [s.added for s in self.steps]
        return [] if self.until_explained else names[self._first_named() :]

    def _first_named(self) -> int:
        """How many steps the plain verdict names: every step when a set of simpler effects was
        named at the first step (several simple causes at once), else one."""
        return len(self.steps) if self.named_together else 1

    @property
    def implausible(self) -> list[dict]:
        """Significant candidates not named because their fitted amplitude is implausible (on
        the base model, or in the final fit): ``{effect, delta_bic, belief}``."""
        named = {s.added for s in self.steps}
        out = {
            c.effect: {"effect": c.effect, "delta_bic": c.delta_bic, "belief": c.implausible}
            for c in self.candidates
            if c.significant and c.implausible and c.effect not in named
        }
        scores = {c.effect: c.delta_bic for c in self.candidates}
        for name, belief in self.implausible_in_best.items():
            out.setdefault(name, {"effect": name, "delta_bic": scores.get(name),
                                  "belief": belief})  # fmt: skip
        return list(out.values())

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
        """The verdict's noise in user units (with a noise level per group, their rms)."""
        if self.group_variance is None:
            return float(math.sqrt(self.noise_variance) * self.family.sigma_scale)
        best = self.best_fit.result
        _, counts = np.unique(best.noise_groups, return_counts=True)
        pooled = float(np.sum(counts * self.group_variance) / best.n_obs)
        return math.sqrt(pooled) * best.user_unit_scale

    def named_parameters(self) -> dict[str, list[dict]]:
        """``{effect: parameter_determination entries}`` of every named effect in the best fit."""
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
            "implausible": c.implausible,
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
        """The ``verdict`` of :meth:`to_dict`: the generic entries, then ``family_verdict``; the
        ``separation_commands`` after the rivals they settle."""
        named = {s.added for s in self.steps}
        commands = {name: str(c) for name, c in self.separation_commands.items()}
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
            "simpler_sets": [comparison.to_dict() for comparison in self.set_comparisons],
            "implausible": [dict(entry) for entry in self.implausible],
        }
        if commands and not self.family_verdict:
            verdict["separation_commands"] = commands
        verdict.update(self._parameter_entries(named))
        if self.missing_effect:
            verdict["effect_story"] = self.family.describe(self.missing_effect)
        verdict.update(copy.deepcopy(self.family_verdict))
        if commands and self.family_verdict:
            verdict["separation_commands"] = commands
        return verdict

    def _parameter_entries(self, named: set[str]) -> dict:
        """The verdict's ``named_parameters``, ``named_undetermined`` and the significant
        candidates not named because undetermined (an implausible one is set aside as such)."""
        named_parameters = self.named_parameters()
        loose = {name: undetermined_parameters(e) for name, e in named_parameters.items() if e}
        return {
            "named_parameters": named_parameters,
            "named_undetermined": {name: names for name, names in loose.items() if names},
            "not_named_undetermined": [
                {
                    "effect": c.effect,
                    "delta_bic": c.delta_bic,
                    "undetermined": c.undetermined_parameters,
                    "parameters": [dict(p) for p in c.parameters],
                }
                for c in self.candidates
                if c.significant
                and not c.determined
                and c.effect not in named
                and not c.implausible
            ],
        }

    def to_dict(self) -> dict:
        """The diagnosis JSON (plus steps, structure and per-effect explanations), the family's
        own results last: the one structured result the text and HTML reports render."""
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
                "accept_effect": acceptance_rule(),
                "threshold": self._first_threshold(),
                "alternative": f"|chi2 difference| within the {ALTERNATIVE_LEVEL:g} quantile "
                "of chi2(larger added_rank)",
                "fit_test_alpha": FIT_TEST_ALPHA if self.sigma_known else None,
            },
            **copy.deepcopy(self.family_results),
        }


def diagnose(family, *, until_explained: bool = False) -> Diagnosis:
    """Test every catalogued effect against the base model and decide (module docstring).

    Runs with one BLAS thread (``core.blas_threads``): its products of tall, thin matrices were
    many times slower split over the threads of busy cores."""
    with one_blas_thread():
        return _diagnose(family, until_explained=until_explained)


def _effect(family, name: str):
    return next(e for e in family.catalogue if e.name == name)


def _forward(family, candidates, base_fit):
    """The forward selection from the base: ``(steps, effects, best fit, after_first,
    set comparisons, the set named at the first step)``. A round's choice of a many-parameter
    effect is compared with sets of simpler ones (:func:`_simpler_set`); a set at least as good is
    added instead, its effects as steps in the order of their own delta_bic."""
    steps: list[Step] = []
    current: list[Any] = []
    current_fit = base_fit
    round_candidates = candidates
    after_first: dict[str, float | None] = {}
    comparisons: list[SetComparison] = []
    together: list[str] = []
    while True:
        accepted = [c for c in round_candidates if c.acceptable]
        if not accepted:
            break
        chosen = accepted[0]
        found = _simpler_set(family, current, current_fit, chosen, round_candidates)
        if found is not None:
            comparison, members = found
            comparisons.append(dataclasses.replace(comparison, step=len(steps) + 1))
        if found is not None and comparison.chosen:
            if not steps:
                together = list(comparison.simpler)
            for c in members:
                previous = current_fit
                current.append(_effect(family, c.effect))
                current_fit = family.fit(current)
                steps.append(
                    Step(c.effect, _delta_bic(current_fit.result, previous.result), current_fit,
                         round_candidates)
                )  # fmt: skip
        else:
            current.append(_effect(family, chosen.effect))
            current_fit = chosen.fit
            steps.append(Step(chosen.effect, float(chosen.delta_bic), chosen.fit, round_candidates))
        rest = [e for e in family.catalogue if e not in current]
        if not rest:
            break
        first_round = round_candidates is candidates
        round_candidates = compare_effects(family, current, current_fit, rest)
        if first_round:
            after_first = {c.effect: c.delta_bic for c in round_candidates}
    return steps, current, current_fit, after_first, comparisons, together


def _set_pool(chosen: Candidate, round_candidates) -> list[Candidate]:
    """The pool of :func:`_simpler_set`: the round's testable, plausible candidates with a smaller
    added rank than ``chosen``'s, best delta_bic first, one of each confounded group (the same
    score and rank), at most :data:`SET_POOL_SIZE`."""
    simpler = sorted(
        (c for c in round_candidates
         if c.testable and c.effect != chosen.effect and c.implausible is None
         and c.delta_bic is not None and c.added_rank < chosen.added_rank),
        key=lambda c: c.delta_bic,
    )  # fmt: skip
    pool: list[Candidate] = []
    for c in simpler:
        if not any(_same_score(c, p) for p in pool):
            pool.append(c)
    return pool[:SET_POOL_SIZE]


class _SetScores:
    """The delta_bic of each set of pool effects fitted on top of ``current`` against
    ``current_fit`` (inf: not fitted, or a member adding no rank of its own), cached with its
    fit in ``scored``."""

    def __init__(self, family, current, current_fit, pool: Sequence[Candidate]) -> None:
        self.family, self.current, self.base = family, current, current_fit.result
        self.order = {e.name: i for i, e in enumerate(family.catalogue)}
        self.rank = {c.effect: c.added_rank for c in pool}
        self.scored: dict[frozenset, tuple[float, Any]] = {}

    def rank_of(self, members: frozenset) -> int:
        return sum(self.rank[n] for n in members)

    def order_of(self, members: frozenset) -> list[int]:
        """The members' places in the catalogue (the tie-break)."""
        return sorted(self.order[n] for n in members)

    def __call__(self, members: frozenset) -> float:
        if members not in self.scored:
            names = sorted(members, key=self.order.__getitem__)
            try:
                fit = self.family.fit([*self.current, *(_effect(self.family, n) for n in names)])
            except (IdentifiabilityError, InputError):
                fit = None
            if fit is None or fit.result.rank - self.base.rank != self.rank_of(members):
                self.scored[members] = (math.inf, None)
            else:
                self.scored[members] = (_delta_bic(fit.result, self.base), fit)
        return self.scored[members][0]


def _grow_beam(scores: _SetScores, pool: Sequence[Candidate], limit: int) -> None:
    """Grow sets from the :data:`SET_BEAM_WIDTH` best singles one effect at a time up to
    :data:`SET_MAX_SIZE`, keeping the best at each size, their added rank at most ``limit``
    (every set tried is left in ``scores``)."""
    beam = [frozenset([c.effect]) for c in pool[:SET_BEAM_WIDTH]]
    for _ in range(SET_MAX_SIZE - 1):
        grown = {
            members | {c.effect}
            for members in beam
            for c in pool
            if c.effect not in members and scores.rank_of(members) + c.added_rank <= limit
        }
        finite = [m for m in grown if math.isfinite(scores(m))]
        if not finite:
            return
        beam = sorted(finite, key=lambda m: (scores(m), scores.order_of(m)))[:SET_BEAM_WIDTH]


def _simpler_set(family, current, current_fit, chosen: Candidate, round_candidates):
    """The best set of simpler candidates against the many-parameter ``chosen`` (added rank at
    least 2): ``(SetComparison, its candidates best first)``, or None when ``chosen`` adds one
    parameter or no two simpler candidates exist.

    Bounded beam search: the :data:`SET_POOL_SIZE` testable, plausible candidates of the round
    with a smaller added rank than ``chosen``'s (best delta_bic first, one of each confounded
    group: the same delta_bic and rank) are the pool; sets grow
    from its :data:`SET_BEAM_WIDTH` best singles one effect at a time up to :data:`SET_MAX_SIZE`,
    keeping the ``SET_BEAM_WIDTH`` best (lowest BIC) at each size, each set's added rank at most
    ``chosen``'s and every member adding rank of its own (confounded effects stay one group: a
    set of two of them is no set). At most ``SET_BEAM_WIDTH * SET_POOL_SIZE * (SET_MAX_SIZE - 1)``
    fits, shared through the family's cache. The set is chosen when its delta_bic is below
    ``chosen``'s (beyond rounding, :data:`SET_TIE`: a set exactly as good, confounded with
    ``chosen``, leaves the one effect named and the set among its alternatives) and every member's
    fitted amplitude in it is plausible.
    """
    limit = chosen.added_rank
    if limit < 2:
        return None
    pool = _set_pool(chosen, round_candidates)
    if len(pool) < 2:
        return None
    scores = _SetScores(family, current, current_fit, pool)
    _grow_beam(scores, pool, limit)
    sets = [m for m in scores.scored if math.isfinite(scores(m))]
    if not sets:
        return None
    best = min(sets, key=lambda m: (scores(m), len(m), scores.order_of(m)))
    dbic, fit = scores.scored[best]
    members = sorted((c for c in pool if c.effect in best), key=lambda c: c.delta_bic)
    plausible = all(_implausibility(family, _effect(family, c.effect), fit) is None
                    for c in members)  # fmt: skip
    comparison = SetComparison(
        step=0,
        effect=chosen.effect,
        added_rank=int(chosen.added_rank),
        delta_bic=float(chosen.delta_bic),
        simpler=tuple(c.effect for c in members),
        set_added_rank=int(sum(c.added_rank for c in members)),
        set_delta_bic=float(dbic),
        chosen=bool(plausible and dbic < chosen.delta_bic - SET_TIE * max(1.0, abs(dbic))),
    )
    return comparison, members


def _pruned(family, candidates, current, current_fit, known, replaced=frozenset()):
    """The accepted effects an effect of which earns its place judged against the best
    description of the data -- the other accepted effects *and* the structure found -- not
    against a model whose chi2 the unexplained structure inflates (a 3/rev term makes any 1/rev
    effect look good): ``(effects, fit, structure, probes, unneeded {name: BIC cost})``. An
    effect in ``replaced`` (a many-parameter effect a set of simpler ones beat) is not put back.
    """
    structure, probes = _search(family, current_fit, known)
    unneeded: dict[str, float] = {}
    threshold = candidates[0].threshold
    while current:
        worst = _least_needed(family, current, current_fit, structure, probes, known, threshold)
        if worst is None:
            break
        name, dbic = worst
        unneeded[name] = dbic
        current = [e for e in current if e.name != name]
        current_fit = family.fit(current)
        structure, probes = _search(family, current_fit, known)
    if unneeded:
        # The final description never fits worse than a determined candidate it passed over: one
        # that alone leaves less misfit is put back first.
        kept = {e.name for e in current}
        described = _described_rss(current_fit.result, structure, probes)
        better = [
            c
            for c in candidates
            if c.acceptable
            and c.determined
            and c.effect not in kept
            and c.effect not in replaced
            and described is not None
            and _rss(c.fit.result) < described
        ]
        if better:
            unneeded.pop(better[0].effect, None)
            current = [_effect(family, better[0].effect), *current]
            current_fit = family.fit(current)
            structure, probes = _search(family, current_fit, known)
    return current, current_fit, structure, probes, unneeded


def _same_score(a: Candidate, b: Candidate) -> bool:
    """Whether two candidates add the same rank with the same delta_bic (to rounding,
    :data:`SET_TIE`): confounded on these data."""
    return a.added_rank == b.added_rank and abs(a.delta_bic - b.delta_bic) <= SET_TIE * max(
        1.0, abs(a.delta_bic)
    )


def _plausible(family, current, current_fit):
    """The accepted effects without those whose amplitude in the final fit is implausible (one
    plausible when it was added can grow once the effects beside it are set aside), refitted one
    at a time, worst first: ``(effects, fit, {name: what one would have to believe})``."""
    dropped: dict[str, str] = {}
    while current:
        judged = [(e, _implausibility(family, e, current_fit)) for e in current]
        worst = next(((e, b) for e, b in judged if b), None)
        if worst is None:
            break
        dropped[worst[0].name] = worst[1]
        current = [e for e in current if e is not worst[0]]
        current_fit = family.fit(current)
    return current, current_fit, dropped


def _separations(family, candidates, steps) -> dict[str, str]:
    """The family's separation advice for the first effect's equally good alternatives and the
    significant candidates not named because undetermined (the same signal, another name?); none
    for an implausible candidate (the verdict sets it aside with what one would have to believe)."""
    if not steps:
        return {}
    first = next(c for c in candidates if c.effect == steps[0].added)
    named = {s.added for s in steps}
    passed_over = [
        c.effect for c in candidates if c.significant and not c.determined and c.effect not in named
    ]
    implausible = {c.effect for c in candidates if c.implausible}  # no plan for what cannot be
    return {
        name: family.separation(first.fit, _effect(family, name))
        for name in dict.fromkeys([*first.alternatives, *passed_over])
        if name not in implausible
    }


def _diagnose(family, *, until_explained: bool) -> Diagnosis:
    base_fit = family.fit([])
    candidates = compare_effects(family, [], base_fit, family.catalogue)
    steps, current, current_fit, after_first, comparisons, together = _forward(
        family, candidates, base_fit
    )
    known = 1.0 if current_fit.result.sigma_known else None
    replaced = frozenset(c.effect for c in comparisons if c.chosen)
    current, current_fit, structure, _, unneeded = _pruned(
        family, candidates, current, current_fit, known, replaced
    )
    current, current_fit, dropped = _plausible(family, current, current_fit)
    if dropped:
        structure, _ = _search(family, current_fit, known)
    if unneeded or dropped:
        steps = _steps_of(family, current, base_fit)
    best = current_fit.result
    noise_variance = _noise_variance(best)
    group_variance = _group_variance(best)
    _mark_alternatives(candidates, noise_variance, group_variance)
    return Diagnosis(
        family=family,
        base_fit=base_fit,
        candidates=candidates,
        steps=steps,
        best_fit=current_fit,
        noise_variance=noise_variance,
        structure=structure,
        fails_fit_test=bool(best.sigma_known and best.dof > 0 and best.p_value < FIT_TEST_ALPHA),
        separations=_separations(family, candidates, steps),
        until_explained=until_explained,
        after_first=after_first,
        warnings=list(family.design_warnings(base_fit)),
        unneeded_given_structure=unneeded,
        set_comparisons=comparisons,
        named_together=together,
        implausible_in_best=dropped,
        group_variance=group_variance,
    )


def _search(
    family, fit, known, max_terms: int = 5, suspects_only: bool = False, skip_inputs=frozenset()
) -> tuple[list[FoundTerm], list[Probe]]:
    """The structure search in the residuals of ``fit``, with the probes it used (with
    ``suspects_only``, the family's ``suspect_probes`` except those in ``skip_inputs``)."""
    if suspects_only:
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

    From the small Gram matrix of the unit-normalised columns (no tall matrix copied or
    decomposed): ``rss = r.r - b^T G^+ b``, ``b`` the columns' products with ``r``; eigenvalues
    below 1e-12 of the largest are not in the span.
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
    # Unit-normalised columns (zero columns left out), scaled on the small matrices.
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


class _Description:
    """The BIC of fits with structure terms' probe columns added, all judged in the weights of
    the best description (``best``: its fit, the structure found and its probes). Linearised at
    the fits (the models are nearly linear); each term pays the search's ``2 ln G``."""

    def __init__(self, best, structure, probes, known) -> None:
        result = best.result
        self.structure_and_probes = (structure, probes)
        self.m = result.n_obs
        self.penalty = 2.0 * math.log(max(len(probes), 1))
        # With a noise level per group estimated with each model the fits' weights differ: all
        # are judged in the best description's (unit variance there), as with sigma given.
        self.reference, self.known = None, known
        if known is None and result.noise_groups is not None:
            self.reference, self.known = result.weights, 1.0
        rss, rank = self.projected(best, structure, probes)
        # ln(rss) weighs as in delta_bic, with the best description's residual dof.
        self.weight = profiled_weight(self.m, rank, 2)
        self.full, self.full_fit = self.bic(rss, rank, len(structure))

    def projected(self, fit, terms, term_probes, own_probes=False) -> tuple[float, int]:
        """(rss, rank) of ``fit`` with the probe columns of ``terms`` added (``own_probes``: the
        probes were weighted like ``fit``, not like the best description)."""
        result = fit.result
        columns = [result.determined_jacobian_weighted, *_term_columns(terms, term_probes)]
        if self.reference is None:
            return _projected_rss(result.residuals * result.weights, columns)
        scale = (self.reference / result.weights)[:, None]
        columns = [c * scale if k == 0 or own_probes else c for k, c in enumerate(columns)]
        return _projected_rss(result.residuals * self.reference, columns)

    def bic(self, rss: float, rank: int, n_terms: int) -> tuple[float, float]:
        """(BIC, its fit part)."""
        if self.known is not None:
            fit_term = rss / self.known
        else:
            fit_term = self.weight * math.log(max(rss, 1e-300))
        return fit_term + rank * math.log(self.m) + self.penalty * n_terms, fit_term

    def score(self, fit, terms, term_probes, own_probes=False) -> tuple[float, float]:
        """(BIC, its fit part) of ``fit`` with the probe columns of ``terms`` added."""
        return self.bic(*self.projected(fit, terms, term_probes, own_probes), len(terms))


def _least_needed(family, current, current_fit, structure, probes, known, threshold):
    """The accepted effect least needed in the best description of the data (the accepted
    effects plus the structure found), with the BIC cost of removing it, or ``None`` when each
    costs at least ``-threshold``, judged with the same structure (an effect that soaked up part
    of a structure it does not explain costs little) and with the suspect shapes found without
    it, when not its own and fitting as well (it mimics them: a wobble following a slow
    temperature change through the measurement order); else it, the physical hypothesis, stays.
    """
    description = _Description(current_fit, structure, probes, known)
    worst = None
    for effect in current:
        try:
            without = family.fit([e for e in current if e is not effect])
        except IdentifiabilityError:
            continue
        costs = _removal_costs(family, effect, without, current_fit, description, known)
        if not costs:
            continue
        cost = float(min(costs))
        if cost < -threshold and (worst is None or cost < worst[1]):
            worst = (effect.name, cost)
    return worst


def _removal_costs(family, effect, without, current_fit, description, known) -> list[float]:
    """The BIC costs of removing ``effect`` (:func:`_least_needed`'s two ways)."""
    structure, probes = description.structure_and_probes
    costs = []
    # Structure spanning E's own signal (a harmonic of the very error E moves): E is its
    # physical name and is not judged against it.
    if not _duplicated(current_fit.result, without.result, structure, probes):
        costs.append(description.score(without, structure, probes)[0] - description.full)
    # What E stood for, in at most two shapes, in inputs E does not depend on itself (a drift in
    # time is a thermal drift's own kind) and in no more parameters than E adds.
    own, own_probes = _search(
        family, without, known, max_terms=2, suspects_only=True, skip_inputs=family.inputs(effect)
    )
    if (
        own
        and sum(len(t.coefficients) for t in own) <= current_fit.result.rank - without.result.rank
        and not _within(own, own_probes, current_fit.result.determined_jacobian_weighted)
    ):
        bic_own, fit_own = description.score(without, own, own_probes, own_probes=True)
        if fit_own <= description.full_fit:
            costs.append(bic_own - description.full)
    return costs


OWN_SHAPE_FRACTION = 0.05
"""A found shape is an effect's own when less than this fraction of its columns (Frobenius norm)
lies outside the span of the model with the effect."""


def _inside(columns: np.ndarray, blocks: Sequence[np.ndarray]) -> bool:
    """Whether ``columns`` lie (to :data:`OWN_SHAPE_FRACTION`) in the span of ``blocks``."""
    outside = _projected_rss(columns, blocks)[0]
    return bool(outside <= OWN_SHAPE_FRACTION**2 * float(np.sum(columns**2)))


def _term_columns(terms, term_probes) -> list[np.ndarray]:
    """The probe columns of the structure ``terms``, one block per term."""
    by_name = {p.name: p for p in term_probes}
    return [by_name[t.name].matrix() for t in terms]


def _duplicated(full: FitResult, without: FitResult, terms, term_probes) -> bool:
    """Whether the columns of the effect ``full`` has and ``without`` lacks lie in the span of
    ``without``'s Jacobian and the structure's probe columns: the structure is its own signal."""
    if not terms:
        return False
    known = set(without.parameter_names)
    own = [i for i, n in enumerate(full.parameter_names) if n not in known]
    if not own:
        return False
    blocks = [without.determined_jacobian_weighted, *_term_columns(terms, term_probes)]
    return _inside(full.jacobian_weighted[:, own], blocks)


def _within(terms, term_probes, jacobian_weighted: np.ndarray) -> bool:
    """Whether the probe columns of ``terms`` lie in the span of ``jacobian_weighted``."""
    return _inside(np.concatenate(_term_columns(terms, term_probes), axis=1), [jacobian_weighted])


def _steps_of(family, effects, base_fit) -> list[Step]:
    """The forward-selection steps of ``effects`` in their order, each with its delta_bic
    against the previous model."""
    steps = []
    previous = base_fit
    for k in range(len(effects)):
        fit = family.fit(effects[: k + 1])
        steps.append(Step(effects[k].name, _delta_bic(fit.result, previous.result), fit, []))
        previous = fit
    return steps

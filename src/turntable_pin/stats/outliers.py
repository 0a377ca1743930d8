"""Gross outliers in a least-squares fit: a stated robust rule.

One pass: for weighted residuals ``r`` of a fit with weighted Jacobian ``J``, the studentized
residual is ``t_i = r_i / (s sqrt(1 - h_i))``, ``h_i`` the leverage and ``s = 1.4826
median(|r_j| / sqrt(1 - h_j))`` a robust scale (a few gross errors cannot inflate it; a real
unmodelled effect does, so its points are not taken for outliers). Observation i is an outlier
when ``|t_i| > z``, the two-sided normal quantile at ``alpha / m`` (Bonferroni: on clean data the
chance of flagging any is about ``alpha``). A group's ``s`` is the larger of its own and the
pooled one. Iterated (:func:`screen_cells`): left out, refitted, tested again; never more than
``MAX_OUTLIER_FRACTION`` of the data (then the model or the noise is wrong).
"""
# scipy.special is imported inside functions: the package's import stays light

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.exceptions import IdentifiabilityError
from .structure_search import orthonormal_columns

__all__ = [
    "MAX_OUTLIER_FRACTION",
    "OUTLIER_ALPHA",
    "OutlierTest",
    "leverages",
    "outlier_rule_words",
    "outlier_threshold",
    "column_variances",
    "screen_cells",
    "screened_diagnosis",
    "variances_differ",
    "screen_outliers",
]

OUTLIER_ALPHA = 0.01
"""Chance, on clean data, that the rule flags any observation of a data set."""

MAX_OUTLIER_FRACTION = 0.05
"""Largest fraction of the observations the rule may call outliers."""

_MAD_TO_SIGMA = 1.4826  # 1 / Phi^-1(3/4): the MAD of a normal sample estimates 0.6745 sigma


@dataclass(frozen=True)
class OutlierTest:
    """One pass of the rule: ``|t_i|`` of every observation (``studentized``, (m,)), the robust
    ``scale`` s, the ``threshold`` z and the indices ``flagged`` (``|t_i| > z``, worst first)."""

    studentized: np.ndarray
    scale: float
    threshold: float
    flagged: np.ndarray


def outlier_threshold(m: int, alpha: float = OUTLIER_ALPHA) -> float:
    """The Bonferroni threshold ``z`` for m observations: ``P(|N(0,1)| > z) = alpha / m``."""
    from scipy import special  # not scipy.stats: half a second to import

    return float(-special.ndtri(alpha / (2.0 * max(m, 1))))


def leverages(jacobian_weighted: np.ndarray) -> np.ndarray:
    """Diagonal of the hat matrix ``J (J^T J)^+ J^T`` (each in [0, 1]), (m,)."""
    j = np.asarray(jacobian_weighted, dtype=float)
    if j.size == 0:
        return np.zeros(j.shape[0])
    norms = np.linalg.norm(j, axis=0)
    u = orthonormal_columns(j[:, norms > 0] / norms[norms > 0])
    return np.clip(np.sum(u * u, axis=1), 0.0, 1.0)


def screen_outliers(
    weighted_residuals: np.ndarray,
    jacobian_weighted: np.ndarray,
    alpha: float = OUTLIER_ALPHA,
    groups: np.ndarray | None = None,
) -> OutlierTest:
    """One pass of the rule (module docstring). ``groups`` (m,) labels observations sharing a
    noise level: a group's scale is the larger of its own and the pooled one (a widened group's
    points are not outliers; a quiet group is not made more sensitive than the pool), and
    ``OutlierTest.scale`` the median of the scales."""
    r = np.asarray(weighted_residuals, dtype=float)
    h = leverages(jacobian_weighted)
    scaled = np.abs(r) / np.sqrt(np.clip(1.0 - h, 1e-12, None))
    labels = np.zeros(r.size, int) if groups is None else np.asarray(groups)
    pooled = _MAD_TO_SIGMA * float(np.median(scaled)) if r.size else 0.0
    scales = np.zeros(r.size)
    for label in np.unique(labels):
        pick = labels == label
        scales[pick] = max(_MAD_TO_SIGMA * float(np.median(scaled[pick])), pooled)
    t = np.divide(scaled, scales, out=np.zeros_like(scaled), where=scales > 0)
    z = outlier_threshold(r.size, alpha)
    flagged = np.flatnonzero(t > z)
    scale = float(np.median(scales)) if r.size else 0.0
    return OutlierTest(t, scale, z, flagged[np.argsort(-t[flagged])])


def outlier_rule_words(observations: str, group: str, pool: str, share: str) -> str:
    """The iterated rule in words, from its constants, for a family's ``observations``, noise
    ``group``, ``pool`` of all groups and the observations a ``share`` of which may go."""
    return (
        "studentized residual |t| = |r| / (s sqrt(1 - h)) above the two-sided normal quantile at "
        f"{OUTLIER_ALPHA:g} / m (m {observations}; h the leverage; s the robust scale "
        f"{_MAD_TO_SIGMA:g} median |r| / sqrt(1 - h), the larger of that of {group} and that of "
        f"{pool}), iterated: the worst (|t| at least half the largest) left out, refitted, tested "
        "again; first on the base model, then on the model with the accepted effects; at most "
        f"{MAX_OUTLIER_FRACTION * 100:g} % of the {share}"
    )


MAX_SCREEN_ROUNDS = 20
"""Most refits of the iterated rule (:func:`screen_cells`)."""


def screen_cells(fit_without, observed: np.ndarray, what: str) -> tuple[np.ndarray, str | None]:
    """The iterated rule over a table of observations: the cells left out as gross outliers, and
    a note (``what`` naming the observations) when it would leave out more than
    :data:`MAX_OUTLIER_FRACTION` (then none is).

    Args:
        fit_without: ``flagged (R, K) bool -> FitResult`` without the cells ``flagged`` (record-
            major); an ``IdentifiabilityError`` there ends the rule with no outlier.
        observed: (R, K) the cells that hold an observation; a column is a noise group.
        what: the observations in words (``measured angles``, ``outputs``).

    Each round leaves out only the clearly worst (at least half the largest ``|t|``) before
    refitting: a gross outlier makes its neighbours look bad too (swamping).
    """

    observed = np.asarray(observed, bool)
    flagged = np.zeros(observed.shape, bool)
    total = int(observed.sum())
    for _ in range(MAX_SCREEN_ROUNDS):
        try:
            result = fit_without(flagged)
        except IdentifiabilityError:
            return np.zeros_like(flagged), None
        live = observed & ~flagged
        groups = np.broadcast_to(np.arange(observed.shape[1]), observed.shape)[live]
        # The leverages need the span only: the determined part is enough.
        span = result.jacobian_weighted @ result.identifiability.basis
        test = screen_outliers(result.residuals * result.weights, span, groups=groups)
        if not test.flagged.size:
            break
        worst = test.flagged[test.studentized[test.flagged] >= 0.5 * test.studentized.max()]
        flagged.reshape(-1)[np.flatnonzero(live.reshape(-1))[worst]] = True
        if flagged.sum() > MAX_OUTLIER_FRACTION * total:
            return np.zeros_like(flagged), (
                f"the outlier rule would leave out more than {MAX_OUTLIER_FRACTION:.0%} of the "
                f"{what}: these are not a handful of bad points but a model or a noise "
                "level that does not fit, so none is left out"
            )
    return flagged, None


def screened_diagnosis(diagnose_without, screen, records, rule: str):
    """A diagnosis with gross outliers left out in two passes: screened under the base model and
    diagnosed, then screened under the accepted effects (a real effect's points are no outliers;
    an outlier their fit shows up is) and diagnosed again if the cells changed.

    Args:
        diagnose_without: ``cells -> Diagnosis`` without the cells ``cells`` (a bool table).
        screen: ``(effects, first) -> (cells, note)``, :func:`screen_cells` under base +
            ``effects``; ``first``: that model's fit on all the data when at hand, else None.
        records: ``(diagnosis, cells) -> list`` of the outliers as the caller reports them.
        rule: the rule in words (``Diagnosis.outlier_rule``).
    """
    cells, note = screen((), None)
    diagnosis = diagnose_without(cells)
    effects = list(diagnosis.best_fit.model.effects)
    if effects:
        first = diagnosis.best_fit if not cells.any() else None  # the same fit, already made
        again, note_again = screen(effects, first)
        note = note_again or note
        if not np.array_equal(again, cells):
            cells = again
            diagnosis = None  # free the first one's fits before the second
            diagnosis = diagnose_without(cells)
    diagnosis.outliers = records(diagnosis, cells)
    diagnosis.outlier_rule = rule
    if note:
        diagnosis.warnings.append(note)
    return diagnosis


def column_variances(residuals: np.ndarray, dof: float, n_obs: int):
    """``(variance, counts, dof)`` of each column of a residual table (R, K) (NaN: no
    observation): its sum of squares over its share of the fit's ``dof`` by its count."""
    counts = np.sum(np.isfinite(residuals), axis=0)
    column_dof = counts * (dof / max(n_obs, 1))
    return np.nansum(residuals**2, axis=0) / np.maximum(column_dof, 1.0), counts, column_dof


MIN_NOISE_COUNT = 10
"""Fewest observations of a column for :func:`variances_differ` to compare its noise."""


def variances_differ(variance, counts, dof, alpha: float) -> tuple[bool, list[int]]:
    """Whether the columns' noise differ (two-sided F test of every pair of columns with at least
    :data:`MIN_NOISE_COUNT` observations, Bonferroni ``alpha``), and those columns."""
    from scipy import special

    present = [a for a in range(len(counts)) if counts[a] >= MIN_NOISE_COUNT]
    if len(present) < 2:
        return False, present
    pairs = [(a, b) for i, a in enumerate(present) for b in present[i + 1 :]]
    level = alpha / len(pairs)
    differ = False
    for a, b in pairs:
        hi, lo = (a, b) if variance[a] >= variance[b] else (b, a)
        p = 2.0 * float(special.fdtrc(dof[hi], dof[lo], variance[hi] / max(variance[lo], 1e-300)))
        differ |= p < level
    return differ, present

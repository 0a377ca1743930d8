"""Gross outliers in a least-squares fit: a stated robust rule.

Rule (one pass): for weighted residuals ``r`` (divided by sigma, or unit-weighted) of a fit with
weighted Jacobian ``J``, the studentized residual of observation i is
``t_i = r_i / (s sqrt(1 - h_i))``, with ``h_i`` the leverage (the diagonal of the hat matrix of
``J``) and ``s = 1.4826 median(|r_j| / sqrt(1 - h_j))`` a robust scale (the median absolute value,
which a few gross errors cannot inflate, and which a real unmodelled effect does inflate, so that
its points are not taken for outliers). Observation i is an outlier when ``|t_i| > z``, with
``z`` the two-sided normal quantile at ``alpha / m`` for m observations (Bonferroni: on clean data
the chance of flagging any observation is about ``alpha``). With groups of observations (kinds of
measurement), ``s`` of a group is the larger of its own and the pooled one. The caller iterates:
leaves the outliers out, refits, and applies the rule again until nothing new is flagged, and
refuses to call more than ``MAX_OUTLIER_FRACTION`` of the data outliers (then the model or the
noise is wrong).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

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
    """One pass of the rule.

    Attributes:
        studentized: ``|t_i|`` of every observation (robust scale), (m,).
        scale: the robust scale ``s`` (in units of the weighted residuals).
        threshold: ``z``.
        flagged: indices with ``|t_i| > z``, worst first.
    """

    studentized: np.ndarray
    scale: float
    threshold: float
    flagged: np.ndarray


def outlier_threshold(m: int, alpha: float = OUTLIER_ALPHA) -> float:
    """The Bonferroni threshold ``z`` for m observations: ``P(|N(0,1)| > z) = alpha / m``."""
    from scipy import special  # not scipy.stats: its import alone takes about half a second

    return float(-special.ndtri(alpha / (2.0 * max(m, 1))))


def leverages(jacobian_weighted: np.ndarray) -> np.ndarray:
    """Diagonal of the hat matrix ``J (J^T J)^+ J^T`` (each in [0, 1]), (m,)."""
    j = np.asarray(jacobian_weighted, dtype=float)
    if j.size == 0:
        return np.zeros(j.shape[0])
    from .structure_search import orthonormal_columns

    norms = np.linalg.norm(j, axis=0)
    u = orthonormal_columns(j[:, norms > 0] / norms[norms > 0])
    return np.clip(np.sum(u * u, axis=1), 0.0, 1.0)


def screen_outliers(
    weighted_residuals: np.ndarray,
    jacobian_weighted: np.ndarray,
    alpha: float = OUTLIER_ALPHA,
    groups: np.ndarray | None = None,
) -> OutlierTest:
    """One pass of the rule of the module docstring on the observations given.

    ``groups`` (m,) labels observations that share a noise level (e.g. the same kind of
    measurement): a group's scale is then the larger of its own and the pooled one, so that a
    group whose residuals an unmodelled effect or a larger noise widens does not have its points
    taken for outliers, while a quiet group is not made more sensitive than the pool.
    ``OutlierTest.scale`` is then the median of the scales.
    """
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
    """The iterated rule (:func:`screen_cells`, :func:`screened_diagnosis`) in words, from its
    constants, for a family that names its ``observations`` (``m <observations>``), a noise
    ``group`` and the ``pool`` of all groups (the robust scale of a group is the larger of
    theirs) and the observations a ``share`` of which may be left out."""
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
    a note (in words, ``what`` naming the observations) when the rule would leave out more than
    :data:`MAX_OUTLIER_FRACTION` of them (then none is left out).

    Args:
        fit_without: ``flagged (R, K) bool -> FitResult`` of the model fitted without the cells
            ``flagged`` (its observations the cells ``observed & ~flagged``, record-major); an
            ``IdentifiabilityError`` there ends the rule with no outlier.
        observed: (R, K) the cells that hold an observation; a column is a noise group.
        what: the observations in words (``measured angles``, ``outputs``).

    Each round fits, tests every observation (:func:`screen_outliers`, the columns as noise
    groups) and leaves out the clearly worst ones only (at least half the largest ``|t|``)
    before refitting: a gross outlier pulls the fit and makes its neighbours look bad too
    (swamping), which the refit undoes.
    """
    from ..core.exceptions import IdentifiabilityError

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
        # The leverages need the span of the Jacobian only: its determined part is enough.
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
    """A diagnosis with gross outliers left out, in two passes: screened under the base model,
    diagnosed without those cells, then screened again under the model with the accepted
    effects (points of a real effect the base could not follow are not outliers, and an outlier
    the effects' fit shows up is) and diagnosed again when the cells changed.

    Args:
        diagnose_without: ``cells -> Diagnosis`` without the cells ``cells`` (a bool table).
        screen: ``(effects, first) -> (cells, note)``: the iterated rule under base +
            ``effects`` (:func:`screen_cells`); ``first`` is the fit of that model on all the
            data when it is at hand, else ``None``.
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
    """``(variance, counts, degrees of freedom)`` of each column of a residual table (R, K), NaN
    where a cell holds no observation: each column's sum of squares over its share of the fit's
    ``dof`` (shared out by the columns' counts of the ``n_obs`` observations)."""
    counts = np.sum(np.isfinite(residuals), axis=0)
    column_dof = counts * (dof / max(n_obs, 1))
    return np.nansum(residuals**2, axis=0) / np.maximum(column_dof, 1.0), counts, column_dof


MIN_NOISE_COUNT = 10
"""Fewest observations of a column for :func:`variances_differ` to compare its noise."""


def variances_differ(variance, counts, dof, alpha: float) -> tuple[bool, list[int]]:
    """Whether the columns' noise differ: a two-sided F test of every pair of the columns with at
    least :data:`MIN_NOISE_COUNT` observations, at ``alpha`` over the pairs (Bonferroni); and
    those columns (fewer than two: never)."""
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

"""A generic search for structure left in fit residuals: which shape is still missing.

Telescope pointing analysts, when their physical terms do not suffice, search harmonic terms in
either axis angle to name the *shape* of what is missing. This module does that for any fit: the
model family supplies *probes* (groups of columns, each a candidate shape such as "a 3/rev
harmonic of one model parameter in one input variable"), and a greedy forward search adds the
probe that removes most of the weighted residual sum of squares, *after* projecting out what the
fitted model can already absorb, while it lowers BIC by at least ``-BIC_THRESHOLD + 2 ln G`` for
G probes: searching G shapes at once is G chances of a false alarm, and ``2 ln G`` is the
likelihood-scale form of a Bonferroni correction (on clean data of 432 observations with about
130 probes, the chance of any false term falls from about 1.5 % to about 0.01 %, while a term of
3 sigma amplitude lowers chi2 by several hundred).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

__all__ = [
    "BIC_THRESHOLD",
    "NEW_FRACTION",
    "FoundTerm",
    "Probe",
    "delta_bic",
    "search_structure",
]

BIC_THRESHOLD = -6.0
"""A term is accepted when it lowers BIC by at least 6 (strong evidence on the Kass-Raftery
scale; the acceptance rule of telescope-pointing practice)."""

NEW_FRACTION = 1e-2
"""A probe direction counts as new only if more than this fraction of it (relative to the probe's
own largest singular value) survives projecting out the model and the terms already found. Shapes
the model spans to first order leave only second-order remainders (of the relative size of the
fitted parameters, 1e-5..1e-3); fitting one of those to the residuals gave absurd amplitudes
(1e5 times the noise)."""


@dataclass(frozen=True)
class Probe:
    """One candidate shape: weighted columns (m, g) and how to describe them.

    Attributes:
        name: short id (``a 3/rev in x``).
        description: for people.
        columns: (m, g) weighted like the residuals (divided by sigma), or a function without
            arguments that returns them: the search then holds one probe's columns at a time,
            so its memory stays that of a few columns however many probes there are.
        unit_scale: user units per internal unit of the probe's coefficients (for amplitudes).
        unit: the user unit of the coefficients.
        effect_spec: how the model family's users add this shape to their model (a text the
            family defines), or ``None``.
    """

    name: str
    description: str
    columns: np.ndarray | Callable[[], np.ndarray]
    unit_scale: float = 1.0
    unit: str = ""
    effect_spec: str | None = None

    def matrix(self) -> np.ndarray:
        """The (m, g) columns (computed now when they were given as a function)."""
        return np.asarray(self.columns() if callable(self.columns) else self.columns, dtype=float)


@dataclass(frozen=True)
class FoundTerm:
    """A probe accepted by the search, with its fitted size."""

    name: str
    description: str
    delta_bic: float
    amplitude: float
    unit: str
    coefficients: tuple[float, ...]
    effect_spec: str | None = None

    def to_dict(self) -> dict:
        """The term as a JSON-ready dictionary."""
        return {
            "term": self.name,
            "description": self.description,
            "delta_bic": self.delta_bic,
            "amplitude": self.amplitude,
            "unit": self.unit,
            "coefficients": list(self.coefficients),
            "effect_spec": self.effect_spec,
        }


def delta_bic(rss_new: float, rss_old: float, added: int, m: int, noise_variance: float | None):
    """BIC change of a model that lowers the weighted rss by adding ``added`` parameters.

    With a known noise variance (sigmas given): ``(rss_new - rss_old) / var + added ln m``.
    Unknown: the Gaussian likelihood with the variance profiled out, ``m ln(rss_new / rss_old)
    + added ln m``.
    """
    if noise_variance is not None:
        return (rss_new - rss_old) / noise_variance + added * math.log(m)
    return m * math.log(max(rss_new, 1e-300) / max(rss_old, 1e-300)) + added * math.log(m)


def _orthonormal_columns(matrix: np.ndarray) -> np.ndarray:
    if matrix.size == 0:
        return np.zeros((matrix.shape[0], 0))
    u, s, _ = np.linalg.svd(matrix, full_matrices=False)
    keep = s > 1e-9 * (s[0] if s.size else 1.0)
    return u[:, keep]


def search_structure(
    weighted_residuals: np.ndarray,
    model_jacobian_weighted: np.ndarray,
    probes: Sequence[Probe],
    *,
    noise_variance: float | None,
    max_terms: int = 5,
) -> list[FoundTerm]:
    """Greedy forward search of probes that explain residual structure.

    Args:
        weighted_residuals: (m,) residuals divided by sigma (unit weights if sigma unknown).
        model_jacobian_weighted: (m, n) the fitted model's weighted Jacobian (its span is
            projected out of every probe: what the model absorbs is not structure).
        probes: candidate shapes.
        noise_variance: 1 when sigmas are known; ``None`` to profile the variance out.
        max_terms: most terms to add.
    """
    r = np.asarray(weighted_residuals, dtype=float).copy()
    m = r.size
    q = _orthonormal_columns(model_jacobian_weighted)
    found: list[FoundTerm] = []
    remaining = list(probes)
    threshold = BIC_THRESHOLD - 2.0 * math.log(max(len(remaining), 1))
    for _ in range(max_terms):
        rss = float(r @ r)
        best = None
        for probe in remaining:
            columns = probe.matrix()
            scale = np.linalg.norm(columns, 2) if columns.size else 0.0
            t = columns - q @ (q.T @ columns)
            u, s, vt = np.linalg.svd(t, full_matrices=False)
            keep = s > NEW_FRACTION * scale
            if not keep.any():
                continue
            basis = u[:, keep]
            reduction = float(np.sum((basis.T @ r) ** 2))
            if best is None or reduction > best[0]:
                best = (reduction, probe, basis, vt[keep].T / s[keep])
        if best is None:
            break
        reduction, probe, basis, pseudo_inverse = best
        dbic = delta_bic(rss - reduction, rss, basis.shape[1], m, noise_variance)
        if dbic > threshold:
            break
        coef = pseudo_inverse @ (basis.T @ r) * probe.unit_scale
        found.append(
            FoundTerm(
                name=probe.name,
                description=probe.description,
                delta_bic=float(dbic),
                amplitude=float(np.linalg.norm(coef)),
                unit=probe.unit,
                coefficients=tuple(float(c) for c in coef),
                effect_spec=probe.effect_spec,
            )
        )
        r = r - basis @ (basis.T @ r)
        q = np.concatenate([q, basis], axis=1)
        remaining.remove(probe)
    return found

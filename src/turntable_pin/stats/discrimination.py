"""Telling two rival linear models apart: their misfit on a design, the design that maximises
it (T-optimal), and the chance that the model choice names the right one.

Two models share columns ``S`` and add their own, ``X1`` and ``X2``, all *whitened* (over the
noise sigma: a squared norm is a chi2). When model 1 is true (signal ``mu = X1 a``), fitting model
2 to it leaves ``lambda_12 = || (I - P_2) mu ||^2`` (``P_2`` the projector onto ``[S X2]``), the
non-centrality of the test of model 2 (Atkinson and Fedorov 1975). A *T-optimal* design
maximises the smaller of ``lambda_12`` and ``lambda_21`` (:func:`t_optimal_exchange`).

The choice. BIC (sigma known; ``k`` the ranks each model adds to ``S``) names model 1 when ``D =
rss_2 - rss_1 > (k_1 - k_2) ln m``. With ``y = mu + e``, ``D = y^T (P_1 - P_2) y``, eigenvalues
in ``[-1, 1]``: a generalised chi-square (:func:`rss_difference`), its tail by Imhof's formula
(:func:`generalized_chi2_sf`). Nested (model 2 contains 1) and model 2 true: ``D =
-chi2'(k_2 - k_1, lambda_21)``; model 1 true: ``-chi2(k_2 - k_1)``.

Nothing here knows what the columns are: the caller whitens its Jacobians and names the models.
"""
# scipy (integrate, special) is imported inside functions: the package's import stays light

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .design import information
from .least_squares import RANK_RTOL
from .model_selection import (
    MAX_CORRELATION,
    MAX_CORRELATION_ALL,
    column_span,
    multiple_correlations,
)

__all__ = [
    "RIDGE",
    "SAME_RTOL",
    "TAIL_SIGMAS",
    "Direction",
    "Exchange",
    "choice_margin",
    "detection_power",
    "generalized_chi2_sf",
    "misfit",
    "noncentral_chi2_sf",
    "orthonormal_span",
    "quadratic_form",
    "residual",
    "rss_difference",
    "t_optimal_exchange",
    "traded_off",
]

RIDGE = 1e-9
"""Ridge of the exchange's Gram matrices (of one candidate's mean diagonal): invertible before
the design determines every column (the reported misfits are exact, :func:`misfit`)."""

SAME_RTOL = 1e-8
"""A rival reproduces a signal when its misfit is below this fraction of the signal's (squared)
norm."""


def orthonormal_span(columns: np.ndarray, rtol: float = RANK_RTOL) -> np.ndarray:
    """An orthonormal basis (m, r) of the span of the unit-normalised ``columns`` (m, p) (singular
    values above ``rtol`` of the largest)."""
    columns = np.asarray(columns, dtype=float)
    if columns.size == 0:
        return np.zeros((columns.shape[0], 0))
    norms = np.linalg.norm(columns, axis=0)
    live = norms > 0
    if not live.any():
        return np.zeros((columns.shape[0], 0))
    u, s, _ = np.linalg.svd(columns[:, live] / norms[live], full_matrices=False)
    return u[:, s > rtol * s[0]]


def residual(fitted: np.ndarray, signal: np.ndarray) -> np.ndarray:
    """``(I - P) signal``: what fitting the columns ``fitted`` (m, q) leaves of ``signal``."""
    signal = np.asarray(signal, dtype=float).reshape(-1)
    basis = orthonormal_span(fitted)
    return signal - basis @ (basis.T @ signal)


def misfit(fitted: np.ndarray, signal: np.ndarray) -> float:
    """``|| (I - P) signal ||^2`` (:func:`residual`) of the noise-free ``signal`` (m,), both
    whitened (a chi2)."""
    rest = residual(fitted, signal)
    return float(rest @ rest)


def quadratic_form(
    terms: Sequence[tuple[np.ndarray, float]], signal: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``(weights, nc)`` of ``Q = y^T (sum_j c_j P_j) y = sum_i weights_i chi2'_1(nc_i)`` for
    ``y = signal + e`` (unit noise), ``P_j`` the projector on the whitened columns of term ``j``
    = ``(columns (m, p_j), c_j)``: the non-zero eigenvalues and the squared projections of
    ``signal`` on their eigenvectors (e.g. ``rss_2 - rss_1 = y^T (P_1 - P_2) y``)."""
    signal = np.asarray(signal, dtype=float).reshape(-1)
    spans = [(orthonormal_span(columns), float(c)) for columns, c in terms]
    both = orthonormal_span(np.hstack([u for u, _ in spans]))
    matrix = np.zeros((both.shape[1], both.shape[1]))
    for u, c in spans:
        inside = both.T @ u
        matrix += c * (inside @ inside.T)
    values, vectors = np.linalg.eigh(matrix)
    keep = np.abs(values) > 1e-9
    along = vectors[:, keep].T @ (both.T @ signal)
    return values[keep], along**2


def rss_difference(
    shared: np.ndarray, own_1: np.ndarray, own_2: np.ndarray, signal: np.ndarray
) -> tuple[np.ndarray, np.ndarray, int, int]:
    """``(weights, noncentralities, k_1, k_2)`` of ``D = rss_2 - rss_1`` (:func:`quadratic_form`
    of ``P_1 - P_2``) when ``signal`` (m,) plus unit noise is fitted by ``[shared, own_1]`` and
    by ``[shared, own_2]`` (whitened), and the ranks each model adds to ``shared``."""
    one, two = np.hstack([shared, own_1]), np.hstack([shared, own_2])
    weights, nc = quadratic_form([(one, 1.0), (two, -1.0)], signal)
    rank_0 = orthonormal_span(shared).shape[1]
    k_1 = orthonormal_span(one).shape[1] - rank_0
    k_2 = orthonormal_span(two).shape[1] - rank_0
    return weights, nc, k_1, k_2


def traded_off(shared: np.ndarray, own: np.ndarray) -> bool:
    """Whether the data leave a model's own parameters undetermined by the correlation rule of
    :func:`~.model_selection.parameter_determination`: an own column seen on its own correlates
    above ``MAX_CORRELATION`` with the shared columns or above ``MAX_CORRELATION_ALL`` with all
    the others; or none is seen on its own (significance depends on the noise: not asked)."""

    columns = np.hstack([shared, own])
    norms = np.linalg.norm(columns, axis=0)
    scaled = columns / np.where(norms > 0, norms, 1.0)
    _, s, vt = np.linalg.svd(scaled, full_matrices=True)
    rank = int(np.sum(s > RANK_RTOL * s[0])) if s.size and s[0] > 0 else 0
    flat = vt[rank:]  # directions the columns do not see
    n_shared = shared.shape[1]
    base = column_span(scaled, range(n_shared), orthonormal_span(shared).shape[1])
    seen = 0
    for i in range(n_shared, columns.shape[1]):
        if norms[i] <= 0 or np.linalg.norm(flat[:, i]) > 1e-8:
            continue  # not seen on its own: counts neither way
        seen += 1
        correlation, correlation_all = multiple_correlations(scaled, i, base, rank)
        if correlation > MAX_CORRELATION or correlation_all > MAX_CORRELATION_ALL:
            return True
    return seen == 0


def generalized_chi2_sf(
    x: float, weights: Sequence[float], noncentralities: Sequence[float]
) -> float:
    """``P(sum_i w_i (z_i + delta_i)^2 > x)``, ``z_i ~ N(0, 1)``, ``delta_i^2`` the
    ``noncentralities``, any signs of the weights: Imhof's (1961) inversion,

        P(Q > x) = 1/2 + (1/pi) int_0^inf sin(theta(u)) / (u rho(u)) du,
        theta(u) = 1/2 sum_i [atan(w_i u) + delta_i^2 w_i u / (1 + w_i^2 u^2)] - x u / 2,
        rho(u) = prod_i (1 + w_i^2 u^2)^(1/4) exp(1/2 sum_i (delta_i w_i u)^2 / (1 + w_i^2 u^2)),

    in units of Q's standard deviation (features at u of order 1); 0 or 1 beyond
    :data:`TAIL_SIGMAS` standard deviations from the mean.
    """
    from scipy import integrate

    w = np.asarray(weights, dtype=float).reshape(-1)
    nc = np.asarray(noncentralities, dtype=float).reshape(-1)
    if w.size == 0:
        return 1.0 if x < 0 else 0.0
    mean = float(np.sum(w * (1.0 + nc)))
    std = math.sqrt(float(np.sum(2.0 * w * w * (1.0 + 2.0 * nc))))
    if x <= mean - TAIL_SIGMAS * std:
        return 1.0
    if x >= mean + TAIL_SIGMAS * std:
        return 0.0
    w, x = w / std, float(x) / std

    def phase_and_envelope(u: float) -> tuple[float, float]:
        """``theta(u) + x u / 2`` and ``1 / (u rho(u))``."""
        wu = w * u
        one = 1.0 + wu * wu
        phase = 0.5 * float(np.sum(np.arctan(wu) + nc * wu / one))
        log_rho = 0.25 * float(np.sum(np.log(one))) + 0.5 * float(np.sum(nc * wu * wu / one))
        return phase, math.exp(-log_rho) / u

    def integrand(u: float) -> float:
        phase, envelope = phase_and_envelope(u)
        return math.sin(phase - 0.5 * x * u) * envelope

    # Smooth at 0; beyond the knot the oscillation is x u / 2's: a Fourier integral (QAWF) of
    # the slow parts, sin(theta) = sin(phase) cos(x u / 2) - cos(phase) sin(x u / 2).
    knot = 20.0
    head, _ = integrate.quad(integrand, 0.0, knot, limit=500)
    omega = 0.5 * abs(x)
    if omega * knot < 1e-3:
        tail, _ = integrate.quad(integrand, knot, np.inf, limit=500)
    else:

        def part(u: float, function) -> float:
            phase, envelope = phase_and_envelope(u)
            return function(phase) * envelope

        cos_part, _ = integrate.quad(part, knot, np.inf, args=(math.sin,), weight="cos",
                                     wvar=omega, limlst=100)  # fmt: skip
        sin_part, _ = integrate.quad(part, knot, np.inf, args=(math.cos,), weight="sin",
                                     wvar=omega, limlst=100)  # fmt: skip
        tail = cos_part - (sin_part if x > 0 else -sin_part)
    return float(min(max(0.5 + (head + tail) / math.pi, 0.0), 1.0))


TAIL_SIGMAS = 40.0
"""A generalised chi-square's tail beyond this many standard deviations is 0 (chi2_1, the
heaviest, has 1e-13 there)."""


def noncentral_chi2_sf(x: float, dof: float, noncentrality: float) -> float:
    """``P(chi2'(dof, noncentrality) > x)`` (``x <= 0``: 1)."""
    from scipy import special

    if x <= 0:
        return 1.0
    if dof <= 0:
        return 0.0
    return float(1.0 - special.chndtr(x, dof, max(noncentrality, 0.0)))


def choice_margin(k_true: int, k_rival: int, m: int) -> float:
    """The ``D = rss_rival - rss_true`` above which a BIC choice (sigma known) names the true
    model: ``(k_true - k_rival) ln m`` (a tie names either)."""
    return (k_true - k_rival) * math.log(max(m, 2))


def detection_power(noncentrality: float, added: int, m: int, threshold: float) -> float:
    """The chance that a model adding ``added`` ranks is accepted (``delta_bic <= threshold``)
    when the misfit without it is ``noncentrality``: ``P(chi2'(added, nc) > added ln m -
    threshold)``."""
    return noncentral_chi2_sf(added * math.log(max(m, 2)) - threshold, added, noncentrality)


@dataclass(frozen=True)
class Direction:
    """One direction of a discrimination (whitened): the rival's columns ``fitted`` (C, k, q)
    and the true model's noise-free ``signal`` (C, k) at each candidate group of k
    observations, and the same at observations already made, ``fixed_fitted`` (m0, q) and
    ``fixed_signal`` (m0,) (or ``None``)."""

    fitted: np.ndarray
    signal: np.ndarray
    fixed_fitted: np.ndarray | None = None
    fixed_signal: np.ndarray | None = None

    def misfit(self, chosen: np.ndarray) -> float:
        """The exact misfit of the candidates ``chosen`` (indices) plus the fixed ones."""
        q = self.fitted.shape[-1]
        fitted = [self.fitted[chosen].reshape(-1, q)]
        signal = [self.signal[chosen].reshape(-1)]
        if self.fixed_fitted is not None:
            fitted.append(self.fixed_fitted)
            signal.append(self.fixed_signal)
        return misfit(np.concatenate(fitted), np.concatenate(signal))


@dataclass(frozen=True)
class Exchange:
    """A T-optimal design (:func:`t_optimal_exchange`): the ``chosen`` indices (n,), the exact
    misfit of each direction on it (``noncentralities``, fixed observations included), the
    ``swaps`` accepted and the ``passes`` made."""

    chosen: np.ndarray
    noncentralities: tuple[float, ...]
    swaps: int
    passes: int

    @property
    def criterion(self) -> float:
        """The smallest misfit over the directions (the T-criterion)."""
        return min(self.noncentralities)


class _Gram:
    """The Gram matrix of one direction's ``[fitted, signal]`` over a design, its inverse, and
    the misfit any candidate's addition would give (Sherman-Morrison-Woodbury on the inverse)."""

    def __init__(self, direction: Direction, chosen: np.ndarray) -> None:
        z = np.concatenate([direction.fitted, direction.signal[..., None]], axis=-1)
        # unit mean diagonal per candidate: the ridge and the conditioning do not depend on units
        scale = np.sqrt(np.mean(np.sum(z * z, axis=1), axis=0))
        scale = np.where(scale > 0, scale, 1.0)
        self.signal_scale = float(scale[-1])
        self.z = z / scale
        self.base = RIDGE * np.eye(z.shape[-1])
        if direction.fixed_fitted is not None:
            fixed = np.concatenate([direction.fixed_fitted, direction.fixed_signal[:, None]], 1)
            fixed = fixed / scale
            self.base = self.base + fixed.T @ fixed
        self.reset(chosen)

    def reset(self, chosen: np.ndarray) -> None:
        self.inverse = np.linalg.inv(information(self.z, chosen, self.base))

    def value(self) -> float:
        """The (ridged) misfit of the current design, in the signal's units."""
        return self.signal_scale**2 / self.inverse[-1, -1]

    def added(self, inverse: np.ndarray | None = None) -> np.ndarray:
        """The misfit with each candidate added to the design of ``inverse`` (default: the
        current one), (C,)."""
        h = self.inverse if inverse is None else inverse
        zh = self.z @ h  # (C, k, q + 1)
        k = self.z.shape[1]
        small = np.eye(k) + zh @ np.swapaxes(self.z, 1, 2)
        u = zh[:, :, -1]
        solved = np.linalg.solve(small, u[..., None])[..., 0]
        corner = h[-1, -1] - np.sum(u * solved, axis=1)
        return self.signal_scale**2 / np.maximum(corner, 1e-300)

    def without(self, index: int) -> np.ndarray:
        """The inverse with candidate ``index`` taken out of the design (a downdate)."""
        z = self.z[index]
        zh = z @ self.inverse
        small = np.eye(z.shape[0]) - zh @ z.T
        return self.inverse + zh.T @ np.linalg.solve(small, zh)


def t_optimal_exchange(
    directions: Sequence[Direction],
    n: int,
    *,
    seed: int = 0,
    max_passes: int = 20,
    rtol: float = 1e-6,
) -> Exchange:
    """The ``n`` distinct candidates that maximise the smallest misfit over ``directions``: a
    seeded random start, then Fedorov's exchange (each chosen candidate swapped for the one
    raising the criterion most, by more than ``rtol``; passes until none changes, at most
    ``max_passes``), every swap scored at once by rank-k updates of the inverse Gram matrices."""
    count = directions[0].fitted.shape[0]
    if not 1 <= n <= count:
        raise ValueError(f"n must be within 1 .. {count} candidates, got {n}")
    rng = np.random.default_rng(seed)
    chosen = np.sort(rng.choice(count, n, replace=False))
    grams = [_Gram(d, chosen) for d in directions]

    def criterion() -> float:
        return min(g.value() for g in grams)

    current = criterion()
    taken = np.zeros(count, bool)
    taken[chosen] = True
    swaps = passes = 0
    while passes < max_passes:
        passes += 1
        changed = False
        for slot in range(n):
            out = chosen[slot]
            scores = np.min([g.added(g.without(out)) for g in grams], axis=0)
            scores[taken] = -np.inf
            best = int(np.argmax(scores))
            if scores[best] > current * (1.0 + rtol) + 1e-12:
                taken[out], taken[best] = False, True
                chosen[slot] = best
                for g in grams:
                    g.reset(chosen)
                current = criterion()
                swaps += 1
                changed = True
        if not changed:
            break
    exact = tuple(d.misfit(chosen) for d in directions)
    return Exchange(chosen.copy(), exact, swaps, passes)

"""D-optimal exact designs of a linear model: choose n of C candidates to maximise log det.

Each candidate adds ``k`` rows ``X_c`` (k, p) to the (weighted) design matrix: ``M = M0 + sum_c
X_c^T X_c`` (``M0`` already known). Maximising ``log det M`` gives the smallest joint confidence
region, whatever the parameters' scale.

A greedy start, then Fedorov's (1972) exchange point by point (Cook and Nachtsheim 1980): each
design point's best replacement, taken when it raises ``log det``; sweeps until none does. Every
gain is read from ``M^-1`` for every candidate at once (matrix determinant lemma), ``M^-1``
follows by Sherman-Morrison-Woodbury and is formed afresh after every sweep (no rounding
accumulates). The criterion never decreases.

Generic: the candidates are rows of numbers; what they mean is the caller's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "ExchangeResult",
    "d_optimal_design",
    "fedorov_exchange",
    "greedy_design",
    "information",
    "information_rows",
    "log_det",
]

RIDGE_RTOL = 1e-9
"""Ridge of the greedy start (of n candidates' mean information): ``M`` is singular until p rows
are in."""

EXCHANGE_TOL = 1e-10
"""An exchange is taken when it raises ``log det`` by more than this."""

MAX_SWEEPS = 100
"""Most sweeps of the exchange over the design points."""


SINGULAR_RTOL = 1e-12
"""An information matrix whose smallest eigenvalue is below this fraction of its largest is
singular (a direction no row sees)."""


def log_det(information: np.ndarray) -> float:
    """``log det`` of a symmetric information matrix; ``-inf`` when it is singular (its smallest
    eigenvalue below :data:`SINGULAR_RTOL` of its largest)."""
    m = np.asarray(information, dtype=float)
    values = np.linalg.eigvalsh(0.5 * (m + m.T))
    if values.size == 0:
        return 0.0
    if not values[0] > SINGULAR_RTOL * values[-1]:
        return float("-inf")
    return float(np.sum(np.log(values)))


def information_rows(information: np.ndarray, rtol: float | None = None) -> np.ndarray:
    """Rows R with ``R^T R = information`` (symmetric, positive semi-definite); with ``rtol``,
    without the rows shorter than ``rtol`` times the longest."""
    values, vectors = np.linalg.eigh(information)
    rows = np.sqrt(np.clip(values, 0.0, None))[:, None] * vectors.T
    if rtol is None:
        return rows
    norms = np.linalg.norm(rows, axis=1)
    return rows[norms > rtol * max(float(norms.max(initial=0.0)), 1e-300)]


@dataclass(frozen=True)
class ExchangeResult:
    """A D-optimal design (:func:`d_optimal_design`): the ``chosen`` indices (n,), ``log_det``
    of its information (with the start's), ``greedy_log_det`` after the greedy start,
    ``history`` after it and each exchange (never decreasing), ``n_exchanges`` and
    ``n_sweeps``."""

    chosen: np.ndarray
    log_det: float
    greedy_log_det: float
    history: tuple[float, ...]
    n_exchanges: int
    n_sweeps: int


def _as_rows(rows: np.ndarray) -> np.ndarray:
    rows = np.asarray(rows, dtype=float)
    if rows.ndim == 2:
        rows = rows[:, None, :]
    if rows.ndim != 3:
        raise ValueError(f"candidate rows must be (C, k, p) or (C, p), got shape {rows.shape}")
    return rows


def information(rows: np.ndarray, chosen, start: np.ndarray | None = None) -> np.ndarray:
    """``start + sum_c X_c^T X_c`` over the ``chosen`` candidates of ``rows`` (C, k, p)."""
    x = rows[chosen].reshape(-1, rows.shape[2])
    m = x.T @ x
    return m if start is None else m + start


def _quadratic(rows: np.ndarray, inverse: np.ndarray) -> np.ndarray:
    """``X_c M^-1 X_c^T`` of every candidate, (C, k, k)."""
    c, k, p = rows.shape
    z = (rows.reshape(-1, p) @ inverse).reshape(c, k, p)
    return z @ np.swapaxes(rows, 1, 2)


def _ridge(rows: np.ndarray, n: int) -> float:
    """The greedy start's ridge (:data:`RIDGE_RTOL` of n candidates' mean information)."""
    mean_diag = float(np.mean(np.sum(rows**2, axis=1)))
    return RIDGE_RTOL * max(n, 1) * max(mean_diag, 1e-300)


def _products(left: np.ndarray, middle: np.ndarray, right: np.ndarray) -> np.ndarray:
    """``L_c W R_c^T`` of every candidate (C, a, b) from (C, a, m), (m, m) and (C, b, m)."""
    c, a, m = left.shape
    lw = (left.reshape(-1, m) @ middle).reshape(c, a, m)
    return lw @ np.swapaxes(right, 1, 2)


def _updated(rows, inverse, quad, u, signs) -> tuple[np.ndarray, np.ndarray]:
    """``M^-1`` and every candidate's ``X_c M^-1 X_c^T`` after ``M + U^T S U`` (Woodbury;
    ``u`` = ``U^T`` (r, p), ``S = diag(signs)``): ``M^-1 - (M^-1 U) K (M^-1 U)^T``, ``K = (S^-1
    + U^T M^-1 U)^-1``."""
    c, k, p = rows.shape
    mu = u @ inverse  # (r, p)
    kernel = np.linalg.inv(np.diag(signs) + mu @ u.T)
    h = (rows.reshape(-1, p) @ mu.T).reshape(c, k, len(signs))  # X_c M^-1 U
    inverse = inverse - mu.T @ kernel @ mu
    return 0.5 * (inverse + inverse.T), quad - _products(h, kernel, h)


def _exchange_ratios(quad: np.ndarray, g: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``det(M + X_c^T X_c - X_i^T X_i) / det M`` of every candidate c replacing point i:
    ``det([[I + A_c, G_c], [-G_c^T, I - B]])``, ``A_c = X_c M^-1 X_c^T`` (``quad``), ``G_c =
    X_c M^-1 X_i^T`` (``g``), ``B = X_i M^-1 X_i^T`` (``b``); by the Schur complement when
    ``I - B`` is well conditioned, else the whole (2k x 2k) determinants."""
    c, k, _ = quad.shape
    rest = np.eye(k) - b
    if np.linalg.eigvalsh(rest).min() > 1e-6:
        kept = np.linalg.inv(rest)
        schur = quad + _products(g, 0.5 * (kept + kept.T), g)
        schur += np.eye(k)
        return np.linalg.det(rest) * np.linalg.det(schur)
    block = np.empty((c, 2 * k, 2 * k))
    block[:, :k, :k] = quad
    block[:, :k, k:] = g
    block[:, k:, :k] = -np.swapaxes(g, 1, 2)
    block[:, k:, k:] = -b
    block += np.eye(2 * k)
    return np.linalg.det(block)


def greedy_design(
    rows: np.ndarray, n: int, start: np.ndarray | None = None, exclude=()
) -> np.ndarray:
    """``n`` candidate indices among ``rows`` (C, k, p) (or (C, p)), in the order chosen, each
    the one that raises ``log det(start + ridge + ...)`` most (``start``: information already
    known (p, p), or ``None``), none of ``exclude``."""
    rows = _as_rows(rows)
    c, k, p = rows.shape
    if not 0 < n <= c - len(exclude):
        raise ValueError(f"cannot choose {n} of {c - len(exclude)} candidates")
    m = (np.zeros((p, p)) if start is None else np.array(start, dtype=float)) + _ridge(
        rows, n
    ) * np.eye(p)
    inverse = np.linalg.inv(m)
    quad = _quadratic(rows, inverse)
    taken = np.zeros(c, dtype=bool)
    taken[list(exclude)] = True
    eye = np.eye(k)
    chosen = []
    for _ in range(n):
        sign, gain = np.linalg.slogdet(eye + quad)
        gain = np.where((sign > 0) & ~taken, gain, -np.inf)
        j = int(np.argmax(gain))
        chosen.append(j)
        taken[j] = True
        inverse, quad = _updated(rows, inverse, quad, rows[j], np.ones(k))
    return np.array(chosen, dtype=int)


def fedorov_exchange(
    rows: np.ndarray,
    chosen,
    start: np.ndarray | None = None,
    *,
    tol: float = EXCHANGE_TOL,
    max_sweeps: int = MAX_SWEEPS,
) -> ExchangeResult:
    """Improve the design ``chosen`` (indices into ``rows`` (C, k, p); nonsingular with
    ``start``, else ValueError) by exchanges raising ``log det`` by more than ``tol``, at most
    ``max_sweeps`` sweeps."""
    rows = _as_rows(rows)
    c, k, p = rows.shape
    chosen = np.array(chosen, dtype=int)
    taken = np.zeros(c, dtype=bool)
    taken[chosen] = True
    m = information(rows, chosen, start)
    current = log_det(m)
    if not np.isfinite(current):
        raise ValueError("the starting design's information matrix is singular")
    history = [current]
    greedy = current
    signs = np.concatenate([np.ones(k), -np.ones(k)])  # x_j in, x_i out
    exchanges = sweeps = 0
    for sweeps in range(1, max_sweeps + 1):  # noqa: B007 (the count is reported)
        inverse = np.linalg.inv(m)
        inverse = 0.5 * (inverse + inverse.T)
        quad = _quadratic(rows, inverse)  # (C, k, k)
        improved = False
        for slot in range(chosen.size):
            i = chosen[slot]
            xi = rows[i]
            vi = inverse @ xi.T  # (p, k)
            b = xi @ vi  # (k, k)
            g = (rows.reshape(-1, p) @ vi).reshape(c, k, k)  # X_c M^-1 X_i^T
            ratio = _exchange_ratios(quad, g, b)
            ratio[taken] = 0.0
            j = int(np.argmax(ratio))
            if not ratio[j] > 0 or np.log(ratio[j]) <= tol:
                continue
            inverse, quad = _updated(rows, inverse, quad, np.concatenate([rows[j], xi]), signs)
            m = m + rows[j].T @ rows[j] - xi.T @ xi
            current += float(np.log(ratio[j]))
            history.append(current)
            taken[i], taken[j] = False, True
            chosen[slot] = j
            exchanges += 1
            improved = True
        m = information(rows, chosen, start)  # afresh: no rounding carried into the next sweep
        current = log_det(m)
        if not improved:
            break
    return ExchangeResult(
        chosen=chosen,
        log_det=current,
        greedy_log_det=greedy,
        history=tuple(history),
        n_exchanges=exchanges,
        n_sweeps=sweeps,
    )


def _completed(rows, n, start, seed) -> np.ndarray:
    """The design ``seed`` made ``n`` long greedily (its best ``n``, or completed)."""
    seed = np.unique(np.asarray(seed, dtype=int))
    if seed.size >= n:
        return seed[greedy_design(rows[seed], n, start)]
    known = information(rows, seed, start)
    return np.concatenate([seed, greedy_design(rows, n - seed.size, known, exclude=seed)])


def d_optimal_design(
    rows: np.ndarray,
    n: int,
    start: np.ndarray | None = None,
    *,
    also_from=(),
    tol: float = EXCHANGE_TOL,
    max_sweeps: int = MAX_SWEEPS,
) -> ExchangeResult:
    """The D-optimal choice of ``n`` of the candidates ``rows`` (C, k, p) (or (C, p)), given
    the information ``start`` (p, p) or ``None``: :func:`greedy_design`, then
    :func:`fedorov_exchange`, also from each design of ``also_from`` (e.g. a regular grid, made
    ``n`` long), keeping the best (an exchange can stop in a local optimum). When no start is
    nonsingular, the greedy design with ``log_det`` ``-inf``."""
    rows = _as_rows(rows)
    greedy = greedy_design(rows, n, start)
    best = None
    for first in (greedy, *(_completed(rows, n, start, s) for s in also_from)):
        if not np.isfinite(log_det(information(rows, first, start))):
            continue
        found = fedorov_exchange(rows, first, start, tol=tol, max_sweeps=max_sweeps)
        if best is None or found.log_det > best.log_det:
            best = found
    if best is None:
        value = log_det(information(rows, greedy, start))
        return ExchangeResult(greedy, value, value, (value,), 0, 0)
    return best

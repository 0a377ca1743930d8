"""Weighted nonlinear least squares with identifiability analysis, for any :class:`FitProblem`
(observations, sigmas, parameter names and units, ``predict`` and ``jacobian``): the result knows
its rank, the combinations the data determine and those they cannot, standard errors, goodness of
fit.

Identifiability is read from the SVD of the column-normalised weighted Jacobian at zero (the
models are first-order exact there; second-order terms, ~1e-10 rad, cannot be resolved):
singular values below ``RANK_RTOL`` of the largest are flat directions. The fit runs in the
determined subspace (the minimum-norm representative, in normalised units, of the equivalent
solutions); determined combinations are the row space's reduced row-echelon form (``a + b`` when
only a sum is determined).

Noise: with sigmas, ``chi2 = sum((r / sigma)^2)`` and its p-value test the fit. Without, unit
weights and the variance estimated (``rss / dof``, or the caller's, e.g. a diagnosis' best model):
chi2 is then 1 per degree of freedom by construction, so no p-value is reported.
"""
# scipy (special, optimize) is imported inside functions: the package's import stays light

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Protocol

import numpy as np

from ..core.exceptions import IdentifiabilityError

__all__ = [
    "DEAD_COLUMN_RTOL",
    "RANK_RTOL",
    "ZeroPoint",
    "FitProblem",
    "FitResult",
    "Identifiability",
    "analyse_identifiability",
    "chi2_quantile",
    "chi2_sf",
    "combination_name",
    "fit_least_squares",
    "tall_r_factor",
    "tall_times",
    "zero_point",
]

DEAD_COLUMN_RTOL = 1e-12
"""A Jacobian column whose norm is below this fraction of the largest column's is zero: the
parameter does not change the observations (what is left is rounding)."""

RANK_RTOL = 1e-6
"""Singular values of the normalised Jacobian below this fraction of the largest are flat."""


class FitProblem(Protocol):
    """What :func:`fit_least_squares` needs from a model and its data."""

    parameter_names: tuple[str, ...]
    parameter_units: tuple[str, ...]
    per_user_unit: np.ndarray  # internal value of one user unit, per parameter
    observed: np.ndarray  # (m,)
    sigma: np.ndarray | None  # (m,) or None (unknown: unit weights, variance estimated)
    user_unit_scale: float  # user units per internal unit of an observation
    observation_unit: str  # name of that user unit: the key suffix of ``rms_<unit>``

    def predict(self, params: np.ndarray) -> np.ndarray:
        """Predicted observations (m,) for parameters in internal units."""

    def jacobian(self, params: np.ndarray) -> np.ndarray:
        """Derivative of :meth:`predict` with respect to the parameters, (m, n)."""

    # Optional: ``predict_and_jacobian(params) -> (predicted (m,), jacobian (m, n))`` in one
    # pass, the Jacobian a new array (the fit scales it in place).


def chi2_sf(chi2: float, dof: float) -> float:
    """``P(X > chi2)`` for X chi-squared with ``dof`` degrees of freedom (``scipy.special``: what
    ``scipy.stats.chi2.sf`` evaluates, without a second of importing ``scipy.stats``)."""
    from scipy import special

    return float(special.chdtrc(dof, chi2))


def chi2_quantile(probability: float, dof: float) -> float:
    """The ``probability`` quantile of chi-squared with ``dof`` degrees of freedom
    (``2 gammaincinv(dof / 2, p)``, as ``scipy.stats.chi2.ppf``)."""
    from scipy import special

    return float(2.0 * special.gammaincinv(dof / 2.0, probability))


def _rref(matrix: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    """Reduced row-echelon form (rows normalised so each pivot is 1; tiny entries zeroed)."""
    a = np.array(matrix, dtype=float)
    rows, cols = a.shape
    r = 0
    for c in range(cols):
        if r >= rows:
            break
        pivot = r + int(np.argmax(np.abs(a[r:, c])))
        if abs(a[pivot, c]) <= tol * max(1.0, np.abs(a).max()):
            continue
        a[[r, pivot]] = a[[pivot, r]]
        a[r] /= a[r, c]
        for k in range(rows):
            if k != r:
                a[k] -= a[k, c] * a[r]
        r += 1
    a = a[:r]
    a[np.abs(a) < 1e-9] = 0.0
    return a


def combination_name(coefficients: np.ndarray, names: tuple[str, ...]) -> str:
    """``"a + b"``, ``"a - 0.5 c.d"``, from coefficients per name."""
    out = ""
    for c, name in zip(coefficients, names, strict=True):
        if c == 0:
            continue
        text = name if abs(abs(c) - 1.0) < 1e-6 else f"{abs(c):.4g} {name}"
        sign = "-" if c < 0 else "+"
        out = f"{out} {sign} {text}" if out else ("-" if c < 0 else "") + text
    return out or "0"


@dataclass(frozen=True)
class Identifiability:
    """What the data determine (linearised at zero parameters).

    Attributes:
        rank: number of independent combinations determined.
        singular_values: of the column-normalised weighted Jacobian, largest first.
        basis: (n, rank) map from reduced coordinates to parameters (internal units).
        determined: (rank, n) coefficients of the determined combinations (RREF of the row space).
        undetermined: (n - rank, n) coefficients of the flat directions (RREF of the null space).
        unresponsive: parameters no observation responds to.
    """

    rank: int
    singular_values: np.ndarray
    basis: np.ndarray
    determined: np.ndarray
    undetermined: np.ndarray
    unresponsive: tuple[str, ...]


TALL_ROWS = 256
"""Row blocks of :func:`tall_r_factor` (matrices of at most ``2 * TALL_ROWS`` rows, or not many
times taller than wide, are decomposed directly)."""


def tall_r_factor(matrix: np.ndarray) -> np.ndarray:
    """The triangular factor R (n, n) of a tall matrix (m, n), ``matrix = Q R``, by blocks of
    :data:`TALL_ROWS` rows (a stacked QR that stays in cache) reduced again: R up to its rows'
    signs, several times faster. The SVD of R has ``matrix``'s singular values and vectors."""
    m, n = matrix.shape
    block = max(TALL_ROWS, 4 * n)
    full = (m // block) * block
    parts = []
    if full:
        stacked = matrix[:full].reshape(-1, block, n)
        parts.append(np.linalg.qr(stacked, mode="r").reshape(-1, n))
    if full < m:
        parts.append(matrix[full:])
    return np.linalg.qr(np.concatenate(parts) if len(parts) > 1 else parts[0], mode="r")


def _singular_values_vt(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Singular values and (n, n) right singular vectors of ``matrix`` (m, n)."""
    m, n = matrix.shape
    if m > 2 * TALL_ROWS and m >= 8 * n:
        _, s, vt = np.linalg.svd(tall_r_factor(matrix))
        return s, vt
    # vt square (n x n) holds the null space; U need not be.
    _, s, vt = np.linalg.svd(matrix, full_matrices=m < n)
    return s, vt


def analyse_identifiability(jacobian_weighted: np.ndarray, names) -> Identifiability:
    """Rank, determined combinations and flat directions of a weighted Jacobian (m, n)."""
    norms = np.linalg.norm(jacobian_weighted, axis=0)
    # A column many orders below the largest is rounding of a zero derivative, not a direction.
    dead = norms <= DEAD_COLUMN_RTOL * max(float(norms.max(initial=0.0)), 1e-300)
    scale = np.where(dead, 1.0, norms)
    n = jacobian_weighted.shape[1]
    s, vt = _singular_values_vt(jacobian_weighted / scale)
    rank = int(np.sum(s > RANK_RTOL * s[0])) if s.size and s[0] > 0 else 0
    v_r = vt[:rank].T
    v_null = vt[rank:].T
    basis = v_r / scale[:, None]
    determined = _rref((v_r * scale[:, None]).T) if rank else np.zeros((0, n))
    undetermined = _rref((v_null / scale[:, None]).T) if rank < n else np.zeros((0, n))
    full_s = np.zeros(n)
    full_s[: s.size] = s
    return Identifiability(
        rank=rank,
        singular_values=full_s,
        basis=basis,
        determined=determined,
        undetermined=undetermined,
        unresponsive=tuple(name for name, d in zip(names, dead, strict=True) if d),
    )


@dataclass(frozen=True)
class FitResult:
    """The outcome of one weighted least-squares fit (internal units).

    Attributes:
        parameter_names, parameter_units, per_user_unit: of the model.
        params: the minimum-norm representative of the best-fitting parameters.
        covariance: of ``params``, on the determined subspace (pseudo-inverse).
        residuals: observed - predicted, (m,).
        weights: 1/sigma per observation (unit weights when sigma is unknown).
        rss: sum of squared weighted residuals.
        rank, dof: determined combinations and ``m - rank``.
        noise_variance: unit-weight residual variance for chi2 and covariances (1 with sigmas).
        sigma_known: whether sigmas were given (then chi2 has a p-value).
        noise_groups: with sigma unknown, each observation's group (int) when every group has
            its own noise level, estimated with this model; ``None``: one level.
    """

    parameter_names: tuple[str, ...]
    parameter_units: tuple[str, ...]
    per_user_unit: np.ndarray
    params: np.ndarray
    covariance: np.ndarray
    residuals: np.ndarray
    weights: np.ndarray
    rss: float
    rank: int
    dof: int
    noise_variance: float
    sigma_known: bool
    identifiability: Identifiability
    user_unit_scale: float
    _jacobian: Any = field(repr=False)  # (m, n) array, or a function computing it on first use
    n_function_evaluations: int = 0
    observation_unit: str = ""
    noise_groups: np.ndarray | None = field(default=None, repr=False)

    @property
    def jacobian_weighted(self) -> np.ndarray:
        """The weighted Jacobian (m, n) at ``params`` (computed on each use: a diagnosis holds
        many fits and needs few Jacobians)."""
        return self._jacobian() if callable(self._jacobian) else self._jacobian

    @property
    def determined_jacobian_weighted(self) -> np.ndarray:
        """The weighted Jacobian along the determined directions, (m, rank): the model's real
        span. At ``params`` large fitted errors can make undetermined directions barely visible
        at second order (a roll about a boresight next to a 0.3 deg azimuth offset); projecting
        residuals on those would credit the model with fits it did not make."""
        return self.jacobian_weighted @ self.identifiability.basis

    @property
    def group_rss(self) -> np.ndarray:
        """Unweighted rss of each noise group, in group order (one group when there are none)."""
        if self.noise_groups is None:
            return np.array([float(self.residuals @ self.residuals)])
        _, inverse = np.unique(self.noise_groups, return_inverse=True)
        return np.bincount(inverse, weights=self.residuals**2)

    @property
    def profiled_rss(self) -> float:
        """The rss of the likelihood with the noise profiled out: :attr:`rss`; with a level per
        group, each profiled, ``exp(sum_g (n_g / m) ln S_g)`` of the groups' unweighted rss
        ``S_g`` (``m ln`` of it is -2 log-likelihood up to a constant): its ratios compare two
        models each at its own noise levels."""
        if self.noise_groups is None:
            return self.rss
        _, counts = np.unique(self.noise_groups, return_counts=True)
        logs = np.log(np.maximum(self.group_rss, 1e-300))
        return float(np.exp(np.sum(counts * logs) / self.n_obs))

    @property
    def n_obs(self) -> int:
        """Number of observations m."""
        return int(self.residuals.size)

    @property
    def n_params(self) -> int:
        """Number of parameters n."""
        return len(self.parameter_names)

    @property
    def chi2(self) -> float:
        """Weighted residual sum of squares over the unit-weight noise variance."""
        return self.rss / self.noise_variance

    @property
    def chi2_reduced(self) -> float:
        """chi2 per degree of freedom (nan without a degree of freedom)."""
        return self.chi2 / self.dof if self.dof > 0 else float("nan")

    @property
    def p_value(self) -> float | None:
        """Probability of a chi2 at least this large if the model were right (sigma known)."""
        if not self.sigma_known or self.dof <= 0:
            return None
        return chi2_sf(self.chi2, self.dof)

    @property
    def rms_key(self) -> str:
        """``rms_<observation unit>`` (``rms`` when the unit has no name): the result's key."""
        return f"rms_{self.observation_unit}" if self.observation_unit else "rms"

    @property
    def rms_user(self) -> float:
        """Root mean square of the (unweighted) residuals, in the observations' user unit."""
        return float(np.sqrt(np.mean(self.residuals**2)) * self.user_unit_scale)

    def with_noise_variance(self, noise_variance: float) -> FitResult:
        """The same fit judged with another unit-weight noise variance (sigma unknown case)."""
        ratio = noise_variance / self.noise_variance
        return replace(
            self, noise_variance=float(noise_variance), covariance=self.covariance * ratio
        )

    def combinations(self) -> list[dict]:
        """The determined combinations: name, value and standard error in user units."""
        out = []
        names = self.parameter_names
        for row in self.identifiability.determined:
            pivot = int(np.flatnonzero(row)[0])
            unit_scale = self.per_user_unit[pivot]
            coeffs_user = row * self.per_user_unit / unit_scale
            value = float(row @ self.params) / unit_scale
            std = float(np.sqrt(max(row @ self.covariance @ row, 0.0))) / unit_scale
            out.append(
                {
                    "name": combination_name(coeffs_user, names),
                    "coefficients": {
                        n: float(c) for n, c in zip(names, coeffs_user, strict=True) if c != 0
                    },
                    "value": value,
                    "std": std,
                    "unit": self.parameter_units[pivot],
                }
            )
        return out

    def undetermined_combinations(self) -> list[str]:
        """Names of the flat directions (combinations the data cannot determine)."""
        out = []
        for row in self.identifiability.undetermined:
            pivot = int(np.flatnonzero(row)[0])
            out.append(
                combination_name(
                    row * self.per_user_unit / self.per_user_unit[pivot], self.parameter_names
                )
            )
        return out

    def individually_determined(self) -> np.ndarray:
        """Boolean mask of the parameters the data determine on their own."""
        basis = self.identifiability.basis
        if basis.size == 0:
            return np.zeros(self.n_params, dtype=bool)
        # e_i is determined iff it lies in the row space: its null-space component vanishes.
        und = self.identifiability.undetermined
        return np.all(np.abs(und) < 1e-9, axis=0) if und.size else np.ones(self.n_params, bool)

    def parameter_table(self) -> dict[str, dict]:
        """``{name: {value, std (None when not determined alone), unit}}`` in user units."""
        mask = self.individually_determined()
        std = np.sqrt(np.clip(np.diag(self.covariance), 0, None))
        out = {}
        for i, name in enumerate(self.parameter_names):
            out[name] = {
                "value": float(self.params[i] / self.per_user_unit[i]),
                "std": float(std[i] / self.per_user_unit[i]) if mask[i] else None,
                "unit": self.parameter_units[i],
                "determined_alone": bool(mask[i]),
            }
        return out

    def high_correlations(self, threshold: float = 0.95) -> list[dict]:
        """Pairs of individually determined parameters correlated above ``threshold``."""
        mask = self.individually_determined()
        idx = np.flatnonzero(mask)
        cov = self.covariance[np.ix_(idx, idx)]
        d = np.sqrt(np.clip(np.diag(cov), 1e-300, None))
        corr = cov / np.outer(d, d)
        out = []
        for a in range(idx.size):
            for b in range(a + 1, idx.size):
                if abs(corr[a, b]) > threshold:
                    out.append(
                        {
                            "a": self.parameter_names[idx[a]],
                            "b": self.parameter_names[idx[b]],
                            "correlation": float(corr[a, b]),
                        }
                    )
        return out

    def to_dict(self) -> dict:
        """The fit as a JSON-ready dictionary (user units; ``rms_<observation unit>``)."""
        return {
            "n_observations": self.n_obs,
            self.rms_key: self.rms_user,
            "chi2": self.chi2,
            "chi2_reduced": self.chi2_reduced,
            "dof": self.dof,
            "p_value": self.p_value,
            "sigma_source": "column" if self.sigma_known else "estimated",
            "noise_variance": self.noise_variance,
            "n_params": self.n_params,
            "rank": self.rank,
            "params": self.parameter_table(),
            "identifiable": {
                "rank": self.rank,
                "n_params": self.n_params,
                "combinations": self.combinations(),
                "undetermined": self.undetermined_combinations(),
                "unresponsive": list(self.identifiability.unresponsive),
                "singular_values": self.identifiability.singular_values.tolist(),
                "high_correlations": self.high_correlations(),
            },
        }


GAUSS_NEWTON_RTOL = 1e-8
"""The iteration stops once a step is below this fraction of the solution (whitened)."""

CHORD_MAX_STEPS = 20
"""Steps with one Jacobian before the fit falls back to scipy's Levenberg-Marquardt."""


@dataclass(frozen=True)
class ZeroPoint:
    """A model's weighted Jacobian J at zero, reduced to what a fit of any subset of its
    parameters needs (at zero a smaller model's columns are columns of this one).

    Attributes:
        names: the parameters (n,).
        r_factor: (k, n), ``R^T R = J^T J`` (J itself when it has fewer rows than columns): the
            SVD of ``R[:, S]`` has the singular values and right vectors of ``J[:, S]``.
        gradient: ``J^T r0`` (n,), ``r0`` the weighted residuals at zero; cost: ``r0 . r0``.
        weights: (m,) 1/sigma (a fit with the same weights keeps this array).
    """

    names: tuple[str, ...]
    r_factor: np.ndarray
    gradient: np.ndarray
    cost: float
    weights: np.ndarray

    def indices(self, names) -> np.ndarray | None:
        """The columns of ``names`` (None when one of them is not a parameter here)."""
        where = {name: i for i, name in enumerate(self.names)}
        if any(name not in where for name in names):
            return None
        return np.array([where[name] for name in names], dtype=int)


def zero_point(names, blocks) -> ZeroPoint:
    """The :class:`ZeroPoint` of parameters ``names`` from ``blocks`` of rows ``(weighted
    jacobian (m_b, n), weighted residuals (m_b,), weights (m_b,))`` at zero (a long data set
    never holds its whole Jacobian)."""
    n = len(names)
    factors, gradient, cost, weights = [], np.zeros(n), 0.0, []
    for jac, res, w in blocks:
        weights.append(w)
        gradient += jac.T @ res
        cost += float(res @ res)
        factors.append(tall_r_factor(jac) if jac.shape[0] > n else np.array(jac, dtype=float))
    stacked = np.concatenate(factors) if factors else np.zeros((0, n))
    r = tall_r_factor(stacked) if stacked.shape[0] > n else stacked
    return ZeroPoint(tuple(names), r, gradient, cost, np.concatenate(weights) if weights else None)


def _evaluator(problem: FitProblem):
    """``params -> (predicted (m,), jacobian (m, n))``, in one pass when the problem has
    ``predict_and_jacobian``."""
    both = getattr(problem, "predict_and_jacobian", None)
    if both is not None:
        return both  # its Jacobian is a new array: the fit scales it in place
    return lambda params: (problem.predict(params), np.array(problem.jacobian(params), dtype=float))


def tall_times(tall: np.ndarray, small: np.ndarray) -> np.ndarray:
    """``tall @ small`` (m, n) @ (n, k) as ``(small^T tall^T)^T``: OpenBLAS's threaded kernel
    for the direct product was 10-20 times slower on a busy two-core machine."""
    return (small.T @ tall.T).T


def _point(origin: np.ndarray | None, basis: np.ndarray, z: np.ndarray) -> np.ndarray:
    """The parameters at whitened coordinates ``z``: ``origin + basis @ z`` (origin None: 0)."""
    return basis @ z if origin is None else origin + basis @ z


def _iterate(problem, evaluate, weights, basis, start, origin):
    """Gauss-Newton, then chord steps, from ``z = 0`` in whitened coordinates (parameters
    ``_point(origin, basis, z)``).

    ``start`` is ``(cost, jz^T jz, jz^T r)`` at ``z = 0``. The Jacobian is evaluated once, at
    the first step's point ``z1``; every further step solves with it against fresh residuals.
    The fixed point differs from the solution by ``(J(z) - J(z1))^T r`` (the fitted errors
    squared, ~1e-10 relative): reached to ~1e-10 of its uncertainty, the steps shrinking by that
    factor. A step below :data:`GAUSS_NEWTON_RTOL` of the solution ends it, its residuals
    updated linearly (exact to the step squared times the nonlinearity).

    Returns ``(z, weighted residuals, normal matrix at z1, evaluations)``, or None when a step
    does not lower the rss or the steps do not settle.
    """
    observed = problem.observed
    cost, normal, gradient = start
    z = np.linalg.solve(normal, gradient)
    predicted, jac = evaluate(_point(origin, basis, z))
    jac *= weights[:, None]
    jz = tall_times(jac, basis)  # d(predicted * weights)/dz = -d(res)/dz
    del jac
    normal = jz.T @ jz
    count = 2
    for _ in range(CHORD_MAX_STEPS):
        res = (observed - predicted) * weights
        new_cost = float(res @ res)
        if new_cost > cost * (1.0 + 1e-12) + 1e-300:
            return None
        cost = new_cost
        step = np.linalg.solve(normal, jz.T @ res)
        z = z + step
        size = float(np.linalg.norm(step))
        if size <= GAUSS_NEWTON_RTOL * float(np.linalg.norm(z)) or size <= 1e-15:
            return z, res - jz @ step, normal, count
        predicted = problem.predict(_point(origin, basis, z))
        count += 1
    return None


def fit_least_squares(
    problem: FitProblem,
    *,
    noise_variance: float | None = None,
    zero_point: ZeroPoint | None = None,
    origin: np.ndarray | None = None,
) -> FitResult:
    """Fit ``problem`` by weighted nonlinear least squares.

    The models are nearly linear: in coordinates where the weighted Jacobian at zero is
    orthonormal, one Gauss-Newton step lands within the nonlinearity of the solution, and chord
    steps reach it in two or three evaluations of ``predict`` (:func:`_iterate`); a step that does
    not lower the residuals hands the fit to scipy's Levenberg-Marquardt.

    Args:
        problem: the model and data (``predict_and_jacobian``, when present, is used for one
            pass per step; ``sigma_relative``: the sigmas are relative weights only).
        noise_variance: unit-weight noise variance to judge the fit with when sigmas are unknown
            (default ``rss / dof`` of this fit). Ignored when sigmas are given.
        zero_point: the reduced Jacobian at zero of a model with these parameters and maybe more
            (:func:`zero_point`): identifiability and first step are read from it (fits of many
            models of one data set).
        origin: start from these parameters instead of zero: ``params`` is ``origin`` plus a
            combination of the directions determined at zero, found from the Jacobian at
            ``origin`` (a solution far from zero, e.g. large offsets, started from a nearby one:
            the minimum-norm representative at zero can miss it).

    Raises:
        IdentifiabilityError: no parameter is determined, or no degree of freedom is left.
    """
    relative = bool(getattr(problem, "sigma_relative", False))
    sigma_known = problem.sigma is not None and not relative
    weights = 1.0 / problem.sigma if problem.sigma is not None else np.ones_like(problem.observed)
    names = tuple(problem.parameter_names)
    evaluate = _evaluator(problem)
    weights, j0, gradient0, cost0 = _at_zero(problem, evaluate, weights, zero_point)
    ident = analyse_identifiability(j0, names)
    m = problem.observed.size
    _check_rank(ident.rank, m)
    # Whitened coordinates: the weighted Jacobian at zero times ``basis`` is orthonormal, so the
    # normal equations of every step are as well conditioned as the problem is nonlinear.
    basis = ident.basis / ident.singular_values[: ident.rank]
    jz0 = tall_times(j0, basis)
    del j0
    start = (cost0, jz0.T @ jz0, basis.T @ gradient0)
    del jz0
    if origin is not None:
        origin = np.asarray(origin, dtype=float)
        start = _start_at(problem, evaluate, weights, basis, origin)
    z, weighted_res, normal, nfev = _solve(problem, evaluate, weights, basis, start, origin)
    params = _point(origin, basis, z)
    rss = float(weighted_res @ weighted_res)
    dof = m - ident.rank
    if sigma_known:
        variance = 1.0
    elif noise_variance is not None:
        variance = float(noise_variance)
    else:
        variance = rss / dof
    cov_z = np.linalg.pinv(normal) * variance
    return FitResult(
        parameter_names=names,
        parameter_units=tuple(problem.parameter_units),
        per_user_unit=np.asarray(problem.per_user_unit, dtype=float),
        params=params,
        covariance=basis @ cov_z @ basis.T,
        residuals=weighted_res / weights,
        weights=weights,
        rss=rss,
        rank=ident.rank,
        dof=dof,
        noise_variance=max(variance, 1e-300),
        sigma_known=sigma_known,
        identifiability=ident,
        user_unit_scale=float(problem.user_unit_scale),
        observation_unit=str(getattr(problem, "observation_unit", "")),
        _jacobian=_weighted_jacobian(problem, params, weights),
        n_function_evaluations=int(nfev),
    )


def _check_rank(rank: int, m: int) -> None:
    """Refuse a fit that determines no parameter or leaves no degree of freedom."""
    if rank == 0:
        raise IdentifiabilityError("the data determine no parameter of the model")
    if m - rank <= 0:
        raise IdentifiabilityError(
            f"{m} observations cannot fit {rank} independent parameter combinations with a "
            "degree of freedom left; measure more positions"
        )


def _at_zero(problem, evaluate, weights, zero_point):
    """``(weights, weighted Jacobian at zero or its R factor, gradient, cost)``: read from
    ``zero_point`` when it has these parameters and weights (its weights array is then kept: one
    for all the fits of a data set), else evaluated."""
    names = tuple(problem.parameter_names)
    columns = zero_point.indices(names) if zero_point is not None else None
    if columns is not None and np.array_equal(zero_point.weights, weights):
        r_factor = zero_point.r_factor[:, columns]
        return zero_point.weights, r_factor, zero_point.gradient[columns], zero_point.cost
    predicted0, j0 = evaluate(np.zeros(len(names)))
    j0 *= weights[:, None]
    res0 = (problem.observed - predicted0) * weights
    return weights, j0, j0.T @ res0, float(res0 @ res0)


def _start_at(problem, evaluate, weights, basis, origin):
    """``(cost, normal matrix, gradient)`` of the first step from ``origin`` in the whitened
    coordinates ``basis``, with the Jacobian there."""
    predicted1, j1 = evaluate(origin)
    j1 *= weights[:, None]
    res1 = (problem.observed - predicted1) * weights
    jz1 = tall_times(j1, basis)
    del j1
    return float(res1 @ res1), jz1.T @ jz1, jz1.T @ res1


def _solve(problem, evaluate, weights, basis, start, origin):
    """``(z, weighted residuals, normal matrix, evaluations)``: :func:`_iterate`, else scipy's
    Levenberg-Marquardt."""
    solved = _iterate(problem, evaluate, weights, basis, start, origin)
    if solved is not None:
        return solved
    z, weighted_res, jac_weighted, nfev = _levenberg_marquardt(problem, weights, basis, origin)
    jz = tall_times(jac_weighted, basis)
    return z, weighted_res, jz.T @ jz, nfev


def _weighted_jacobian(problem: FitProblem, params: np.ndarray, weights: np.ndarray):
    """A function of no argument: the weighted Jacobian (m, n) at ``params``."""

    def compute() -> np.ndarray:
        return np.array(problem.jacobian(params), dtype=float) * weights[:, None]

    return compute


def _levenberg_marquardt(
    problem: FitProblem, weights: np.ndarray, basis: np.ndarray, origin: np.ndarray | None
):
    """scipy's Levenberg-Marquardt in the coordinates ``basis`` about ``origin``: ``(z,
    weighted residuals, weighted jacobian (m, n), evaluations)``."""
    from scipy import optimize

    def fun(z):
        return (problem.observed - problem.predict(_point(origin, basis, z))) * weights

    def jac(z):
        return -tall_times(problem.jacobian(_point(origin, basis, z)) * weights[:, None], basis)

    # Nearly linear: one Gauss-Newton step from zero lands close to the optimum.
    rank = basis.shape[1]
    z0 = np.linalg.lstsq(-jac(np.zeros(rank)), -fun(np.zeros(rank)), rcond=None)[0]
    solution = optimize.least_squares(fun, z0, jac=jac, method="lm", xtol=1e-12, ftol=1e-12)
    z = solution.x
    jac_weighted = problem.jacobian(_point(origin, basis, z)) * weights[:, None]
    return z, solution.fun, jac_weighted, solution.nfev

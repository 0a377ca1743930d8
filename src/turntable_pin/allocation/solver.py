"""Error allocation of the turntable (paper section 4.2, eqs. 29-34) and its worst case (Lemma 1).

Three problems, one per orientation angle k (psi, theta, gamma), over the magnitudes ``x_i >= 0``
of the errors that enter the small-angle model of that angle (eq. 26):

    min  J_k = sum_i W_ki^2 / x_i^2
    s.t. max over phi2 in Omega_k of  f_k(phi2, x) <= I_k,      x_i >= LB_i,

with ``f_k(phi2, x) = c(x) + a(x) cos(phi2) + b(x) sin(phi2)`` linear in x and the paper's intervals
``Omega_gamma = [0, pi/2]``, ``Omega_psi = [3pi/2, 2pi]`` (where every term of the model is
non-negative) and, for theta (no phi2 in its model), the whole turn. The maximum over an interval
is exact (:func:`interval_max`: the ends and the interior stationary point ``atan2(b, a)``).

How it is solved exactly: for one fixed phi2 = t the constraint is linear and the problem has the
closed-form solution ``x_i = max(LB_i, k_i u)`` with ``k_i = (2 W_i^2 / g_i(t))^(1/3)`` and one
scalar ``u`` fixed by the constraint (piecewise linear in u, solved through its breakpoints). Its
optimum ``V(t)`` is a lower bound of the true optimum for every t; maximising ``V`` over t gives a
candidate that, if it satisfies the constraint for *all* phi2 of the interval, is optimal (lower
bound reached). That certificate is checked; if it fails (several active angles), SLSQP on the
exact constraint is used instead, and the result says which method was used.

The upper bounds combine as eq. 34: ``UB_i = min_k x*_ki``. :func:`worst_case_full_circle` gives the
largest ``|f_k|`` the box ``|chi_i| <= UB_i`` allows over *every* phi2 and every sign (Lemma 1):
``sum|A_k| UB + hypot(sum|B_k| UB, sum|C_k| UB)`` when no error has both a cos and a sin term.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from scipy.optimize import minimize_scalar

from ..calibration.site import DEFAULT_LATITUDE_DEG
from ..core.exceptions import InputError
from ..core.units import ARCMIN_PER_RAD, ARCSEC_PER_RAD, DEG_PER_RAD, arcmin_by_name
from ..model.errors import ANGULAR_ERROR_NAMES, MAX_ANGULAR_ERROR_DEG, TurntableErrors
from ..model.small_angle import small_angle_matrix
from .capability import ManufacturingCapability
from .common import (
    ORIENTATION_ANGLES,
    AllocationSummary,
    SubproblemOptimum,
    combine_upper_bounds,
    fixed_angle_solution,
    lower_bounds_infeasible,
    minimize_weighted,
    render_allocation_report,
)
from .sensitivity import PAPER_FIGURE8_TRIG, AverageSensitivities, average_sensitivities

__all__ = [
    "DEFAULT_ACCURACY_DPH",
    "DEFAULT_POSITIONS",
    "MIN_LIMIT_ARCSEC",
    "ORIENTATION_ANGLES",
    "PHI2_INTERVALS_RAD",
    "WEIGHT_SCHEMES",
    "Allocation",
    "LinearAngleModel",
    "OrientationLimits",
    "SubproblemResult",
    "allocate_tolerances",
    "allocation_weights",
    "default_orientation_limits",
    "interval_max",
    "linear_angle_models",
    "paper_eq16_limits",
    "solve_subproblem",
    "worst_case_full_circle",
]

PHI2_INTERVALS_RAD: dict[str, tuple[float, float]] = {
    "gamma": (0.0, 0.5 * math.pi),  # eq. 31
    "theta": (0.0, 2.0 * math.pi),  # eq. 32 has no phi2; the whole turn is the same constraint
    "psi": (1.5 * math.pi, 2.0 * math.pi),  # eq. 33
}
"""The phi2 interval ``(lo, hi)`` of each angle's constraint (eqs. 31-33), radians."""
WEIGHT_SCHEMES: tuple[str, ...] = ("model", "paper", "equal")
"""The weight schemes :func:`allocation_weights` knows."""

# Eq. 16: 0.027 deg on each angle keeps the GyroWheel calibration error under 0.01 deg/h.
_EQ16_LIMIT_DEG = 0.027


MIN_LIMIT_ARCSEC = 1e-6
"""Smallest orientation limit accepted, arcsec (a micro-arcsecond; turntables work in arcsec)."""


@dataclass(frozen=True)
class OrientationLimits:
    """Required bounds I_psi, I_theta, I_gamma on |dpsi|, |dtheta|, |dgamma|, radians.

    Each is at least :data:`MIN_LIMIT_ARCSEC` and at most ``MAX_ANGULAR_ERROR_DEG`` (5 deg,
    ``model.errors``): the allocation is one of small errors (eq. 26), and a limit of more than a
    few degrees is not a small one.
    """

    psi_rad: float
    theta_rad: float
    gamma_rad: float

    def __post_init__(self) -> None:
        for name in ORIENTATION_ANGLES:
            value = float(getattr(self, f"{name}_rad"))
            if not math.isfinite(value) or value <= 0.0:
                raise InputError(f"orientation limit for {name} must be a positive number")
            if value < MIN_LIMIT_ARCSEC / ARCSEC_PER_RAD:
                raise InputError(
                    f"orientation limit for {name} is {value * ARCSEC_PER_RAD:.3g} arcsec; it must "
                    f"be at least {MIN_LIMIT_ARCSEC:g} arcsec (below that no turntable is built, "
                    "and the ratios of the allocation overflow: a unit mix-up?)"
                )
            if value > MAX_ANGULAR_ERROR_DEG / DEG_PER_RAD * (1.0 + 1e-12):
                raise InputError(
                    f"orientation limit for {name} is {value * DEG_PER_RAD:g} deg; it must be at "
                    f"most {MAX_ANGULAR_ERROR_DEG:g} deg (a small orientation error)"
                )
            object.__setattr__(self, f"{name}_rad", value)

    @classmethod
    def from_arcmin(cls, psi: float, theta: float, gamma: float) -> OrientationLimits:
        """The limits from values in arc minutes."""
        return cls(psi / ARCMIN_PER_RAD, theta / ARCMIN_PER_RAD, gamma / ARCMIN_PER_RAD)

    @classmethod
    def from_deg(cls, psi: float, theta: float, gamma: float) -> OrientationLimits:
        """The limits from values in degrees."""
        return cls(psi / DEG_PER_RAD, theta / DEG_PER_RAD, gamma / DEG_PER_RAD)

    def as_array(self) -> np.ndarray:
        """(3,) radians in :data:`ORIENTATION_ANGLES` order."""
        return np.array([getattr(self, f"{n}_rad") for n in ORIENTATION_ANGLES])

    def to_dict(self) -> dict[str, float]:
        """``{psi: arcmin, theta: arcmin, gamma: arcmin}``."""
        return {n: getattr(self, f"{n}_rad") * ARCMIN_PER_RAD for n in ORIENTATION_ANGLES}


DEFAULT_ACCURACY_DPH = 0.01
"""Calibration accuracy behind the default limits: the paper's example, 0.01 deg/h."""
DEFAULT_POSITIONS = "grid:30"
"""Position scheme behind the default limits (the calibration layer's reference scheme)."""


def paper_eq16_limits() -> OrientationLimits:
    """The paper's eq. 16: 0.027 deg on each angle (for 0.01 deg/h, positions not stated)."""
    return OrientationLimits.from_deg(_EQ16_LIMIT_DEG, _EQ16_LIMIT_DEG, _EQ16_LIMIT_DEG)


@lru_cache(maxsize=16)
def default_orientation_limits(
    accuracy_dph: float = DEFAULT_ACCURACY_DPH,
    positions: str = DEFAULT_POSITIONS,
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
) -> OrientationLimits:
    """The orientation requirement used when the user gives no limits.

    It is the calibration layer's requirement (eqs. 15-16, :func:`orientation_requirement`) for
    calibration accuracy ``accuracy_dph`` (deg/h) on the position scheme ``positions`` at
    ``latitude_deg`` (degrees), with the paper's Table 1 GyroWheel. The paper's own numbers are
    :func:`paper_eq16_limits`.
    """
    from ..calibration.positions import PositionSet
    from ..calibration.requirement import orientation_requirement

    requirement = orientation_requirement(
        accuracy_dph, PositionSet.parse(positions), math.radians(latitude_deg)
    )
    return OrientationLimits(*requirement.limits_rad)


# ---- the linear model of each angle ----------------------------------------------------------
@dataclass(frozen=True)
class LinearAngleModel:
    """``f(phi2, chi) = const.chi + cos(phi2) cos_coef.chi + sin(phi2) sin_coef.chi`` (eq. 26 row).

    Read off :func:`small_angle_matrix` (the foundation's eq. 26), not retyped.
    """

    angle: str
    const: np.ndarray
    cos_coef: np.ndarray
    sin_coef: np.ndarray

    @property
    def members(self) -> np.ndarray:
        """Indices (into :data:`ANGULAR_ERROR_NAMES`) of the errors that enter this angle."""
        coef = np.abs(self.const) + np.abs(self.cos_coef) + np.abs(self.sin_coef)
        return np.flatnonzero(coef > 0.0)

    def basis_values(self, phi2_rad) -> np.ndarray:
        """``g_i(phi2) = d f / d chi_i``, shape phi2.shape + (8,)."""
        phi2 = np.asarray(phi2_rad, dtype=float)[..., None]
        return self.const + self.cos_coef * np.cos(phi2) + self.sin_coef * np.sin(phi2)

    def coefficients(self, chi) -> tuple[float, float, float]:
        """``(a, b, c)`` of ``c + a cos + b sin`` for the error values ``chi`` (8,)."""
        chi = np.asarray(chi, dtype=float)
        return float(self.cos_coef @ chi), float(self.sin_coef @ chi), float(self.const @ chi)


def linear_angle_models() -> dict[str, LinearAngleModel]:
    """The eq. 26 model of psi, theta and gamma, each as constant, cos and sin coefficients."""
    s0, s90, s180 = (small_angle_matrix(a) for a in (0.0, 0.5 * math.pi, math.pi))
    const = 0.5 * (s0 + s180)
    cos_coef = 0.5 * (s0 - s180)
    sin_coef = s90 - const
    return {
        name: LinearAngleModel(name, const[k], cos_coef[k], sin_coef[k])
        for k, name in enumerate(ORIENTATION_ANGLES)
    }


def interval_max(a: float, b: float, c: float, lo_rad: float, hi_rad: float) -> tuple[float, float]:
    """Exact ``max`` of ``c + a cos(t) + b sin(t)`` over ``t`` in ``[lo, hi]``: (value, t at max).

    The maximum is at an end or at the stationary point ``atan2(b, a)`` when it lies inside.
    """
    r = math.hypot(a, b)
    star = math.atan2(b, a)
    if hi_rad - lo_rad >= 2.0 * math.pi * (1.0 - 1e-15):
        return c + r, star % (2.0 * math.pi)
    candidates = [lo_rad, hi_rad]
    if r > 0.0:
        inside = lo_rad + (star - lo_rad) % (2.0 * math.pi)
        if inside <= hi_rad:
            candidates.append(inside)
    values = [c + a * math.cos(t) + b * math.sin(t) for t in candidates]
    best = int(np.argmax(values))
    return values[best], candidates[best]


def worst_case_full_circle(model: LinearAngleModel, bounds_rad) -> float:
    """Largest ``|f|`` over every phi2 and every chi with ``|chi_i| <= bounds_i`` (Lemma 1), rad.

    ``max_{s, phi2} |c(s) + a(s) cos + b(s) sin| = max_s |c(s)| + hypot(a(s), b(s))``; when each
    error has at most one of a cos and a sin term all three magnitudes peak at the same signs, so
    it is ``sum |A| x + hypot(sum |B| x, sum |C| x)``. Otherwise every sign corner is tried.
    """
    x = np.abs(np.asarray(bounds_rad, dtype=float))
    if not np.any((model.cos_coef != 0.0) & (model.sin_coef != 0.0)):
        return float(
            np.abs(model.const) @ x
            + math.hypot(np.abs(model.cos_coef) @ x, np.abs(model.sin_coef) @ x)
        )
    members = model.members
    best = 0.0
    for corner in range(2**members.size):
        signs = np.ones(x.size)
        signs[members] = [1.0 if corner >> j & 1 else -1.0 for j in range(members.size)]
        a, b, c = model.coefficients(signs * x)
        best = max(best, abs(c) + math.hypot(a, b))
    return best


# ---- weights -------------------------------------------------------------------------------
def allocation_weights(
    scheme: str, sensitivities: AverageSensitivities | None = None
) -> np.ndarray:
    """Weights W (3, 8), rows :data:`ORIENTATION_ANGLES` (only each angle's own errors matter).

    ``model``: the inverse of the exact model's average sensitivities (Figure 8, computed);
    ``paper``: the inverse of the paper's Figure 8 value 0.6481 for every sin/cos term and 1 for
    every constant term; ``equal``: 1 everywhere (the "traditional" allocation).
    """
    models = linear_angle_models()
    weights = np.ones((3, len(ANGULAR_ERROR_NAMES)))
    if scheme == "equal":
        return weights
    if scheme == "paper":
        for k, name in enumerate(ORIENTATION_ANGLES):
            m = models[name]
            trig = (m.cos_coef != 0.0) | (m.sin_coef != 0.0)
            weights[k, trig] = 1.0 / PAPER_FIGURE8_TRIG
        return weights
    if scheme == "model":
        sens = sensitivities or average_sensitivities(phi1_grid_deg=[0.0])
        # Order of sens rows is dpsi, dtheta, dgamma = ORIENTATION_ANGLES.
        with np.errstate(divide="ignore"):
            weights = np.where(sens.values > 0.0, 1.0 / sens.values, np.inf)
        return weights
    raise InputError(f"unknown weights '{scheme}'; choose one of {', '.join(WEIGHT_SCHEMES)}")


# ---- one sub-problem -----------------------------------------------------------------------
@dataclass(frozen=True)
class SubproblemResult(SubproblemOptimum):
    """Optimum of one of eqs. 31-33 (the common fields: :class:`.common.SubproblemOptimum`;
    ``error_names`` is the vector chi_k of this angle's model, ``method`` "exact" or "slsqp").

    Attributes:
        interval_rad: the phi2 interval of the constraint.
        constraint_rad: max of f_k over the interval at the optimum;  phi2_at_max_rad: where.
        multiplier: Lagrange multiplier of the semi-infinite constraint (x in arcmin).
        bound_multipliers: of the lower bounds (0 for free errors).
        kkt_residual: largest relative stationarity error over the free errors.
    """

    interval_rad: tuple[float, float]
    constraint_rad: float
    phi2_at_max_rad: float
    multiplier: float
    bound_multipliers: np.ndarray
    kkt_residual: float

    def details(self) -> dict:
        """phi2 interval and maximum (degrees), constraint (arcmin), multiplier, KKT residual."""
        return {
            "phi2_interval_deg": [v * DEG_PER_RAD for v in self.interval_rad],
            "constraint_arcmin": self.constraint_rad * ARCMIN_PER_RAD,
            "phi2_at_max_deg": self.phi2_at_max_rad * DEG_PER_RAD,
            "multiplier": self.multiplier,
            "kkt_residual": self.kkt_residual,
        }


def solve_subproblem(
    model: LinearAngleModel,
    limit_rad: float,
    weights: np.ndarray,
    lower_bounds_rad: np.ndarray,
    interval_rad: tuple[float, float],
) -> SubproblemResult:
    """Solve one of eqs. 31-33 exactly (see the module docstring). Radians in and out.

    Raises:
        InfeasibleError: the lower bounds alone already exceed the limit somewhere in the interval.
    """
    idx = model.members
    names = tuple(ANGULAR_ERROR_NAMES[i] for i in idx)
    w = np.asarray(weights, dtype=float)[idx]
    lower = np.asarray(lower_bounds_rad, dtype=float)[idx]
    lo, hi = interval_rad
    # Work in units of the limit: x = z * limit.
    lower_z = lower / limit_rad

    def constraint(z):
        full = np.zeros(len(ANGULAR_ERROR_NAMES))
        full[idx] = z
        return interval_max(*model.coefficients(full), lo, hi)

    def basis(t):
        return model.basis_values(t)[idx]

    at_lower, _ = constraint(lower_z)
    if at_lower > 1.0 + 1e-12:
        raise lower_bounds_infeasible(model.angle, at_lower * limit_rad, limit_rad, names)

    def dual(t):
        return fixed_angle_solution(basis(t), w, lower_z, 1.0)

    grid = np.linspace(lo, hi, 181)
    values = np.array([dual(t)[1] for t in grid])
    j = int(np.argmax(values))
    a, b = grid[max(j - 1, 0)], grid[min(j + 1, grid.size - 1)]
    res = minimize_scalar(
        lambda t: -dual(t)[1], bounds=(a, b), method="bounded", options={"xatol": 1e-13}
    )
    t_star = float(res.x) if -res.fun >= values[j] else float(grid[j])
    # Polish: at the optimum t* is where the constraint of x(t*) peaks (a fixed point); the
    # scalar search leaves t* ~1e-8 off, which this removes.
    for _ in range(20):
        t_next = constraint(dual(t_star)[0])[1] if np.all(np.isfinite(dual(t_star)[0])) else t_star
        t_next = lo + (t_next - lo) % (2.0 * math.pi) if hi - lo < 2.0 * math.pi else t_star
        if not lo <= t_next <= hi or dual(t_next)[1] < dual(t_star)[1] * (1.0 - 1e-15):
            break
        if abs(t_next - t_star) < 1e-15:
            break
        t_star = t_next
    z, _ = dual(t_star)
    method = "exact"
    feasible = np.all(np.isfinite(z)) and constraint(z)[0] <= 1.0 + 1e-10
    if not feasible:
        z = _slsqp(constraint, basis, w, lower_z)
        method = "slsqp"
    # Remove the last rounding-level excess so the bounds are strictly admissible.
    value, _ = constraint(z)
    if value > 1.0:
        z = np.maximum(lower_z, z / value)
    return _kkt_report(model, names, w, lower, z * limit_rad, limit_rad, interval_rad, method)


def _slsqp(constraint, basis, w, lower_z):
    """Fallback: SLSQP on the exact semi-infinite constraint (Danskin gradient)."""
    ones_value, _ = constraint(np.ones(lower_z.size))
    at_lower, _ = constraint(lower_z)
    start = lower_z + (1.0 - at_lower) / (2.0 * ones_value)
    return minimize_weighted(
        w,
        start,
        lower_z,
        lambda z: 1.0 - constraint(z)[0],
        lambda z: -basis(constraint(z)[1]),
    )


def _kkt_report(model, names, w, lower, x_rad, limit_rad, interval_rad, method):
    """Multipliers and KKT residual at ``x_rad``, everything in arc minutes."""
    lo, hi = interval_rad
    full = np.zeros(len(ANGULAR_ERROR_NAMES))
    idx = model.members
    full[idx] = x_rad
    value, t_max = interval_max(*model.coefficients(full), lo, hi)
    x = x_rad * ARCMIN_PER_RAD
    g = model.basis_values(t_max)[idx]  # gradient of the active constraint (Danskin)
    grad_j = -2.0 * w**2 / x**3
    at_lb = x_rad <= lower * (1.0 + 1e-9)
    free = ~at_lb
    constraint_active = value >= limit_rad * (1.0 - 1e-9)
    if constraint_active and np.any(free):
        multiplier = float(np.sum(-grad_j[free] * g[free]) / np.sum(g[free] ** 2))
    else:
        multiplier = 0.0
    bound_multipliers = np.where(at_lb, grad_j + multiplier * g, 0.0)
    stationarity = grad_j + multiplier * g - bound_multipliers
    scale = np.maximum(np.abs(grad_j), 1e-300)
    residual = float(np.max(np.abs(stationarity) / scale))
    active = []
    if constraint_active:
        active.append(
            f"max d{model.angle} over phi2 in [{lo * DEG_PER_RAD:g}, {hi * DEG_PER_RAD:g}] deg "
            f"= limit (at phi2 = {t_max * DEG_PER_RAD:.4f} deg)"
        )
    active += [f"{n} = lower bound" for n, flag in zip(names, at_lb, strict=True) if flag]
    return SubproblemResult(
        angle=model.angle,
        error_names=names,
        weights=w,
        lower_bounds_rad=lower,
        solution_rad=np.asarray(x_rad, dtype=float),
        limit_rad=limit_rad,
        interval_rad=(lo, hi),
        constraint_rad=value,
        phi2_at_max_rad=t_max,
        multiplier=multiplier,
        bound_multipliers=bound_multipliers,
        kkt_residual=residual,
        active=tuple(active),
        method=method,
    )


# ---- the whole allocation ------------------------------------------------------------------
@dataclass(frozen=True)
class Allocation(AllocationSummary):
    """Upper bounds UB of the eight angular errors (eq. 34) and how they were obtained (the
    fields of :class:`.common.AllocationSummary`: ``upper_bounds_rad`` (8,) in
    :data:`ANGULAR_ERROR_NAMES` order; ``weights_scheme`` model, paper or equal; ``subproblems``
    of :class:`SubproblemResult`; ``worst_case_rad`` over every angle and sign, Lemma 1 closed
    form).

    Attributes:
        capability: the lower bounds used (by keyword).
    """

    capability: ManufacturingCapability = field(kw_only=True)

    def errors(self) -> TurntableErrors:
        """The upper bounds as an error set (every error at its bound, positive sign)."""
        return TurntableErrors.from_array(self.upper_bounds_rad)

    def to_dict(self) -> dict:
        """Bounds, objectives, worst case and every sub-problem as a JSON-ready dict (arcmin)."""
        return {
            "upper_bounds_arcmin": arcmin_by_name(ANGULAR_ERROR_NAMES, self.upper_bounds_rad),
            **self.summary_dict(),
            "lower_bounds": self.capability.to_dict(),
            **self.subproblems_dict(),
        }

    def report(self) -> str:
        """The table of upper bounds with J, worst case and active constraints, as text."""
        return render_allocation_report(
            f"Error allocation (weights: {self.weights_scheme})",
            ANGULAR_ERROR_NAMES,
            self.upper_bounds_rad,
            self.capability.lower_bounds_rad,
            self.limits,
            self.worst_case_rad,
            self.subproblems,
            lambda sub: f"{sub.method}, KKT residual {sub.kkt_residual:.1e}",
        )


def allocate_tolerances(
    limits: OrientationLimits | None = None,
    weights: str = "model",
    capability: ManufacturingCapability | None = None,
    sensitivities: AverageSensitivities | None = None,
) -> Allocation:
    """Allocate the eight angular errors to meet ``limits`` (eqs. 29-34).

    Args:
        limits: orientation limits (default :func:`default_orientation_limits`).
        weights: ``model`` (default), ``paper`` or ``equal``; see :func:`allocation_weights`.
        capability: lower bounds (default: the bundled manufacturing capability).
        sensitivities: averages for ``model`` weights (default: computed from the exact model).

    Raises:
        InfeasibleError: the lower bounds alone violate a limit.
    """
    limits = limits or default_orientation_limits()
    capability = capability or ManufacturingCapability.default()
    w = allocation_weights(weights, sensitivities)
    models = linear_angle_models()
    subproblems = {}
    for k, name in enumerate(ORIENTATION_ANGLES):
        subproblems[name] = solve_subproblem(
            models[name],
            limits.as_array()[k],
            w[k],
            capability.lower_bounds_rad,
            PHI2_INTERVALS_RAD[name],
        )
    upper = combine_upper_bounds(subproblems, ANGULAR_ERROR_NAMES)
    worst = np.array([worst_case_full_circle(models[n], upper) for n in ORIENTATION_ANGLES])
    return Allocation(upper, limits, weights, w, subproblems, worst, capability=capability)

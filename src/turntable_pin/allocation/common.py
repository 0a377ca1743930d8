"""What the paper's allocation (:mod:`.solver`) and the allocation of any table
(:mod:`.table_allocation`) share: the closed-form optimum of one linear constraint, the SLSQP
step on the weighted objective, the eq. 34 combination of the sub-problems, the refusal of lower
bounds that alone break a limit, and the text and dict forms of an allocation.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..core.exceptions import InfeasibleError
from ..core.units import ARCMIN_PER_RAD, arcmin_by_name
from ..model.angles import ANGLE_SYMBOLS

__all__ = [
    "ORIENTATION_ANGLES",
    "AllocationSummary",
    "SubproblemOptimum",
    "combine_upper_bounds",
    "fixed_angle_solution",
    "lower_bounds_infeasible",
    "minimize_weighted",
    "render_allocation_report",
]

ORIENTATION_ANGLES = ANGLE_SYMBOLS  # the limit names: psi_rad, theta_rad, gamma_rad
"""Names of the three orientation angles dpsi, dtheta, dgamma as used in keys and options."""


def fixed_angle_solution(g, weights, lower, limit):
    """Closed-form optimum of ``min sum W^2/x^2 s.t. g.x <= limit, x >= lower`` (g may be <= 0).

    Errors with ``g_i <= 0`` are unconstrained by this relaxation (x_i = inf, no cost).
    Returns ``(x, V)``.
    """
    x = np.full(g.shape, np.inf)
    positive = g > 0.0
    if not np.any(positive):
        return x, 0.0
    gp, wp, lp = g[positive], weights[positive], lower[positive]
    k = np.cbrt(2.0 * wp**2 / gp)  # free optimum: x_i = k_i u with u = lambda^(-1/3)
    breaks = np.sort(lp / k)  # x_i = max(lower_i, k_i u): error i is free once u > lower_i / k_i
    order = np.argsort(lp / k)
    # h(u) = sum g_i max(lower_i, k_i u) rises piecewise linearly from sum g lower; solve
    # h(u) = limit on the piece where the errors with the j smallest breakpoints are free.
    xp = lp.copy()
    if gp @ lp < limit:
        for j in range(1, order.size + 1):
            free, at_lb = order[:j], order[j:]
            u = (limit - gp[at_lb] @ lp[at_lb]) / float(np.sum(gp[free] * k[free]))
            if j == order.size or u <= breaks[j]:
                xp = np.maximum(lp, k * u)
                break
    x[positive] = xp
    return x, float(np.sum(wp**2 / xp**2))


def minimize_weighted(w, start, lower, fun: Callable, jac: Callable) -> np.ndarray:
    """SLSQP on ``min sum w^2/z^2`` s.t. ``fun(z) >= 0`` (gradient ``jac``), ``z >= lower``
    (and ``z >= 1e-12``): the numerical step of both allocations, in units of the limit."""
    from scipy.optimize import minimize

    res = minimize(
        lambda z: float(np.sum(w**2 / z**2)),
        start,
        jac=lambda z: -2.0 * w**2 / z**3,
        bounds=[(max(lb, 1e-12), None) for lb in lower],
        constraints=[{"type": "ineq", "fun": fun, "jac": jac}],
        method="SLSQP",
        options={"ftol": 1e-15, "maxiter": 1000},
    )
    return np.asarray(res.x, dtype=float)


def lower_bounds_infeasible(
    angle: str, reached_rad: float, limit_rad: float, names: Sequence[str]
) -> InfeasibleError:
    """The error for lower bounds that alone give ``|d angle|`` up to ``reached_rad``, above the
    limit: no allocation exists."""
    return InfeasibleError(
        f"the manufacturing lower bounds alone give d{angle} up to "
        f"{reached_rad * ARCMIN_PER_RAD:.4f} arcmin, above the limit "
        f"{limit_rad * ARCMIN_PER_RAD:.4f} arcmin: no allocation exists (lower the bounds of "
        f"{', '.join(names)} or relax the limit)"
    )


def combine_upper_bounds(subproblems, error_names: Sequence[str]) -> np.ndarray:
    """Eq. 34: ``UB_i = min_k x*_ki`` over the sub-problems' solutions, in ``error_names`` order
    (``inf`` for an error no angle constrains)."""
    upper = np.full(len(error_names), np.inf)
    for sub in subproblems.values():
        for n, v in zip(sub.error_names, sub.solution_rad, strict=True):
            i = error_names.index(n)
            upper[i] = min(upper[i], v)  # eq. 34
    return upper


@dataclass(frozen=True)
class SubproblemOptimum:
    """The optimum of one angle's problem, as every solver states it.

    Attributes:
        angle: psi, theta or gamma.  error_names: the errors that move it.
        weights, lower_bounds_rad, solution_rad: per error of ``error_names``.
        limit_rad: I_k.  active: human-readable active constraints.  method: how it was solved.
    """

    angle: str
    error_names: tuple[str, ...]
    weights: np.ndarray
    lower_bounds_rad: np.ndarray
    solution_rad: np.ndarray
    limit_rad: float
    active: tuple[str, ...]
    method: str

    @property
    def J(self) -> float:
        """The objective ``sum W^2 / x^2`` at the optimum, errors in arc minutes (1/arcmin^2)."""
        return float(np.sum(self.weights**2 / (self.solution_rad * ARCMIN_PER_RAD) ** 2))

    def details(self) -> dict:
        """What a solver says beyond the common fields, JSON-ready (none here)."""
        return {}

    def to_dict(self) -> dict:
        """The optimum as a JSON-ready dict: angle, solution (arcmin), weights, J, limit
        (arcmin), the solver's :meth:`details`, active constraints and method."""
        return {
            "angle": self.angle,
            "solution_arcmin": arcmin_by_name(self.error_names, self.solution_rad),
            "weights": dict(zip(self.error_names, map(float, self.weights), strict=True)),
            "J": self.J,
            "limit_arcmin": self.limit_rad * ARCMIN_PER_RAD,
            **self.details(),
            "active_constraints": list(self.active),
            "method": self.method,
        }


def render_allocation_report(
    title: str,
    error_names: Sequence[str],
    upper_rad,
    lower_rad,
    limits,
    worst_case_rad,
    subproblems,
    method_note: Callable = lambda sub: sub.method,
) -> str:
    """The text of an allocation: the tolerance table (upper bound in arc minutes and seconds,
    lower bound in arc seconds), then each angle's limit, worst case, J, ``[method_note(sub)]``
    and active constraints."""
    width = max(12, *(len(n) + 2 for n in error_names))
    lines = [title, "", f"{'error':{width}s}{'upper bound':>24s}{'lower bound':>14s}"]
    for n, ub, lb in zip(error_names, upper_rad, lower_rad, strict=True):
        lines.append(
            f"{n:{width}s}{ub * ARCMIN_PER_RAD:11.4f}' = {ub * ARCMIN_PER_RAD * 60:7.2f}\""
            f'{lb * ARCMIN_PER_RAD * 60:12.2f}"'
        )
    lines.append("")
    limits_arcmin = limits.to_dict()
    lines.append(
        "with every error at its final upper bound (the smallest of the three sub-problems'):"
    )
    for k, name in enumerate(ORIENTATION_ANGLES):
        limit = limits_arcmin[name]
        worst = worst_case_rad[k] * ARCMIN_PER_RAD
        share = worst / limit if limit > 0 else float("nan")
        state = "at the limit" if share >= 1.0 - 1e-6 else f"{share:.0%} of the limit"
        lines.append(f"d{name:6s} limit {limit:.4f}'  worst case {worst:.4f}'  ({state})")
    lines.append("each angle's own sub-problem (its bounds before the minimum over the angles):")
    for name in ORIENTATION_ANGLES:
        sub = subproblems[name]
        lines.append(f"d{name:6s} J = {sub.J:.6g} /arcmin^2  [{method_note(sub)}]")
        for item in sub.active:
            lines.append(f"         active in it: {item}")
    return "\n".join(lines)


@dataclass(frozen=True)
class AllocationSummary:
    """What every allocation result holds and says alike: bounds, weights, sub-problems, worst
    case, their objectives and their JSON form (the subclasses add their own fields, by keyword).

    Attributes:
        upper_bounds_rad: radians, in the allocation's error order.
        limits: the :class:`~.solver.OrientationLimits`.  weights_scheme: the weights' name.
        weights: (3, P).  subproblems: ``{psi|theta|gamma: SubproblemOptimum}``.
        worst_case_rad: (3,) largest |dpsi|, |dtheta|, |dgamma| the box ``|chi| <= UB`` allows.
    """

    upper_bounds_rad: np.ndarray
    limits: object
    weights_scheme: str
    weights: np.ndarray
    subproblems: dict = field(default_factory=dict)
    worst_case_rad: np.ndarray = field(default_factory=lambda: np.zeros(3))

    @property
    def J(self) -> dict[str, float]:
        """Objective of each problem at its optimum (1/arcmin^2) and their sum."""
        out = {name: self.subproblems[name].J for name in ORIENTATION_ANGLES}
        out["total"] = float(sum(out.values()))
        return out

    def summary_dict(self) -> dict:
        """J (and its unit), worst case, limits (arcmin) and the weights scheme, JSON-ready."""
        return {
            "J": self.J,
            "J_unit": "1/arcmin^2 (errors in arc minutes)",
            "worst_case_arcmin": arcmin_by_name(ORIENTATION_ANGLES, self.worst_case_rad),
            "limits_arcmin": self.limits.to_dict(),
            "weights": self.weights_scheme,
        }

    def subproblems_dict(self) -> dict:
        """Each angle's active constraints and sub-problem, JSON-ready."""
        return {
            "active_constraints": {n: list(self.subproblems[n].active) for n in ORIENTATION_ANGLES},
            "subproblems": {n: self.subproblems[n].to_dict() for n in ORIENTATION_ANGLES},
        }

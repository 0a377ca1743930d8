"""Error allocation of a table on its first-order model (paper section 4.2, eqs. 29-34, Lemma 1).

The first-order model is the table's regressor ``C(q) = d(dpsi, dtheta, dgamma)/d(errors)`` at
zero errors, for its angular errors. Angle k's problem over the magnitudes ``x_i >= LB_i`` of the
errors that move it (eqs. 29-33) is

    min  J_k = sum_i W_ki^2 / x_i^2    s.t.  sum_i |C_ki(q)| x_i <= I_k   for every q in Omega_k,

the left side being the largest first-order ``|d angle_k|`` errors of magnitudes x reach at q over
every sign. ``Omega_k`` is every joint's whole turn, except where the table's layout gives the
joint's interval for angle k (``GenericTable.angle_domains_rad``): on the paper's table the phi2
intervals of eqs. 31-33 (:data:`PHI2_INTERVALS_RAD`), where every term of eq. 26 is non-negative,
so that the left side is the paper's ``f_k(phi2, x)`` and the problem is the paper's.

The constraint holds on the continuous domain (semi-infinite). ``C_ki`` is a trigonometric
polynomial of degree one in every joint angle (:class:`AngleRows`), so along one joint the left
side is ``c + a cos + b sin`` between the zeros of the rows, with an exact maximum; the maximum over
the domain (:func:`domain_max`) starts from the best points of a grid and maximises exactly along
one joint at a time until nothing improves. For one point q the problem has a closed form whose
optimum ``V(q)`` bounds the true one from below. :func:`solve_subproblem` starts at the grid point
of largest ``V``, moves its points to the local maxima of the constraint at the current solution
and adds the most violated one (an exchange method; several points: SLSQP) until the constraint
holds everywhere. One point whose closed form meets it is the optimum (``exact``); otherwise
(``cutting planes``) the solution is scaled onto the constraint. The bounds combine as eq. 34,
``UB_i = min_k x*_ki``; the worst case (Lemma 1) is ``max sum_i |C_ki(q)| UB_i`` over whole turns.
"""

from __future__ import annotations

# scipy.optimize is imported inside functions: import turntable_pin stays light
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import cached_property, lru_cache

import numpy as np

from ..calibration.positions import PositionSet
from ..calibration.requirement import orientation_requirement
from ..calibration.site import DEFAULT_LATITUDE_DEG
from ..core.exceptions import InfeasibleError, InputError, ModelError
from ..core.notebook import NotebookResult
from ..core.turn_grid import every_combination
from ..core.units import ARCMIN_PER_RAD, ARCSEC_PER_RAD, DEG_PER_RAD, arcmin_by_name
from ..model.angles import ANGLE_SYMBOLS
from ..model.errors import MAX_ANGULAR_ERROR_DEG
from ..model.paper_table import PHI2_INTERVALS_DEG, resolve_table
from . import sensitivity
from .capability import ManufacturingCapability
from .sensitivity import FULL_TURN_RAD, PAPER_FIGURE8_TRIG, Sensitivities, grid_axes_rad

__all__ = [
    "DEFAULT_ACCURACY_DPH",
    "DEFAULT_POSITIONS",
    "MIN_LIMIT_ARCSEC",
    "PHI2_INTERVALS_RAD",
    "REQUIREMENT_KINDS",
    "WEIGHT_SCHEMES",
    "Allocation",
    "AngleRows",
    "OrientationLimits",
    "SubproblemResult",
    "allocate_tolerances",
    "allocation_weights",
    "angle_rows",
    "default_orientation_limits",
    "domain_max",
    "interval_max",
    "minimize_weighted",
    "paper_eq16_limits",
    "solve_subproblem",
]

PHI2_INTERVALS_RAD: dict[str, tuple[float, float]] = {
    angle: (math.radians(lo), math.radians(hi)) for angle, (lo, hi) in PHI2_INTERVALS_DEG.items()
}
"""The paper's Omega_k: the phi2 interval ``(lo, hi)`` of each angle's constraint, radians (its
layout's data, :data:`~turntable_pin.model.paper_table.PHI2_INTERVALS_DEG`)."""
WEIGHT_SCHEMES: tuple[str, ...] = ("model", "paper", "equal")
"""The weight schemes :func:`allocation_weights` knows."""
MIN_LIMIT_ARCSEC = 1e-6
"""Smallest orientation limit accepted, arcsec (a micro-arcsecond; turntables work in arcsec)."""
DEFAULT_ACCURACY_DPH = 0.01
"""Calibration accuracy behind the default limits: the paper's example, 0.01 deg/h."""
DEFAULT_POSITIONS = "grid:30"
"""Position scheme behind the default limits (the calibration layer's reference scheme)."""

_EQ16_LIMIT_DEG = 0.027  # eq. 16: 0.027 deg on each angle keeps the calibration under 0.01 deg/h
_STARTS = 8  # grid points a domain maximum starts from
_MET = 1e-12  # relative excess of the constraint taken as met
_FAR = 1e3  # an error no point constrains yet, in units of the limit (surely too large)
_NODES_RAD = (0.0, 0.5 * math.pi, math.pi)
_TO_COEFFICIENTS = np.array([[0.5, 0.0, 0.5], [0.5, 0.0, -0.5], [-0.5, 1.0, -0.5]])  # (c, a, b)


# ---- limits --------------------------------------------------------------------------------
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
        for name in ANGLE_SYMBOLS:
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
        """(3,) radians in :data:`ANGLE_SYMBOLS` order."""
        return np.array([getattr(self, f"{n}_rad") for n in ANGLE_SYMBOLS])

    def to_dict(self) -> dict[str, float]:
        """``{psi: arcmin, theta: arcmin, gamma: arcmin}``."""
        return {n: getattr(self, f"{n}_rad") * ARCMIN_PER_RAD for n in ANGLE_SYMBOLS}


def paper_eq16_limits() -> OrientationLimits:
    """The paper's eq. 16: 0.027 deg on each angle (for 0.01 deg/h, positions not stated)."""
    return OrientationLimits.from_deg(_EQ16_LIMIT_DEG, _EQ16_LIMIT_DEG, _EQ16_LIMIT_DEG)


REQUIREMENT_KINDS: tuple[str, ...] = ("box", "planes")
"""Which requirement the default limits are: ``box``, the largest box whose every point meets
the accuracy (the limits hold together: a table within the allocated bounds calibrates to the
accuracy, by Lemma 1); ``planes``, the paper's method (eqs. 15-16: each plane's rectangle,
dtheta shared; with all three angles at their limits at once the rate error exceeds the
accuracy, by 5 and 14 % on grid:30)."""


@lru_cache(maxsize=16)
def default_orientation_limits(
    accuracy_dph: float = DEFAULT_ACCURACY_DPH,
    positions: str = DEFAULT_POSITIONS,
    latitude_deg: float = DEFAULT_LATITUDE_DEG,
    table=None,
    requirement: str = "box",
    progress: bool = False,
) -> OrientationLimits:
    """The orientation requirement used when the user gives no limits.

    It is the calibration layer's requirement (eqs. 15-16, :func:`orientation_requirement`) for
    calibration accuracy ``accuracy_dph`` (deg/h) on the position scheme ``positions`` of
    ``table`` (default the bundled table) at ``latitude_deg`` (degrees), with the paper's Table 1
    GyroWheel: its box that holds (``requirement="box"``) or the paper's planes (``"planes"``,
    :data:`REQUIREMENT_KINDS`). The paper's own numbers are :func:`paper_eq16_limits`.
    ``progress``: report the requirement's progress on stderr when it takes long (a three-axis
    table's grid).

    Raises:
        IdentifiabilityError: the positions cannot calibrate the GyroWheel on this table.
    """
    if requirement not in REQUIREMENT_KINDS:
        raise InputError(
            f"unknown requirement '{requirement}'; expected one of {REQUIREMENT_KINDS}"
        )
    result = orientation_requirement(
        accuracy_dph, PositionSet.parse(positions, resolve_table(table)),
        math.radians(latitude_deg), progress=progress,
    )  # fmt: skip
    return OrientationLimits(*(result.box if requirement == "box" else result).limits_rad)


# ---- the rows of one angle and their maximum over a domain ----------------------------------
def _basis(t) -> np.ndarray:
    """``(1, cos t, sin t)`` along a last axis."""
    return np.stack([np.ones_like(t), np.cos(t), np.sin(t)], axis=-1)


@dataclass(frozen=True, eq=False)
class AngleRows:
    """One angle's first-order rows and the domain its constraint holds on.

    Attributes:
        angle: psi, theta or gamma.  error_names: the errors that move it (the columns).
        coefficients: ``T`` (3,) * joints + (m,): the signed rows are ``C_k(q) = sum T[i, j, ..]
            b_i(q_1) b_j(q_2) ..`` with ``b(t) = (1, cos t, sin t)``.
        domain_rad: Omega_k, one ``(lo, hi)`` per joint.
        axes_rad: the starting grid, one per joint inside the domain (a single value: a joint the
            rows do not depend on, never moved).
        joint_names: the joints.  angle_names: their angles' names in words (the paper's phi1,
            phi2).
        named: the joints the constraint's words name (chain indices): those whose interval the
            table's layout gives for this angle, else every joint.
    """

    angle: str
    error_names: tuple[str, ...]
    coefficients: np.ndarray = field(repr=False)
    domain_rad: tuple[tuple[float, float], ...]
    axes_rad: tuple[np.ndarray, ...] = field(repr=False)
    joint_names: tuple[str, ...] = ()
    angle_names: tuple[str, ...] = ()
    named: tuple[int, ...] = ()

    def values(self, points, keep: int | None = None) -> np.ndarray:
        """The signed rows (K, m) at points (K, joints), radians; with ``keep``, their ``(c, a,
        b)`` of ``c + a cos + b sin`` along that joint through each point (K, 3, m)."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        out = np.broadcast_to(self.coefficients, (len(points), *self.coefficients.shape))
        for j in reversed(range(points.shape[1])):  # the last joint's axis is always at -2
            if j == keep:
                out = np.moveaxis(out, -2, 1)
            else:
                out = np.einsum("k...im,ki->k...m", out, _basis(points[:, j]))
        return out

    @cached_property
    def grid(self) -> tuple[np.ndarray, np.ndarray]:
        """The starting grid: positions (N, joints) and ``|C_k|`` there (N, m)."""
        mesh = every_combination(self.axes_rad)
        return mesh, np.abs(self.values(mesh))


def angle_rows(
    table, grid_step_deg: float | None = None, whole_turns: bool = False
) -> dict[str, AngleRows]:
    """The :class:`AngleRows` of psi, theta, gamma on ``table`` over Omega_k (the joint intervals
    of ``table.angle_domains_rad``, else whole turns; ``whole_turns``: every joint's whole turn),
    starting grid of step ``grid_step_deg`` (default by table). ``T`` is read off the regressor at
    0, 90, 180 degrees of every joint and checked on random positions.

    Raises:
        ModelError: the regressor is not of degree one in every joint angle.
    """
    d = len(table.joint_names)
    columns = [table.parameter_names.index(n) for n in table.angular_names]
    nodes = every_combination([np.array(_NODES_RAD)] * d)
    coefficients = table.regressor(list(nodes.T))[:, :, columns]
    coefficients = coefficients.reshape((3,) * d + coefficients.shape[1:])
    for j in range(d):
        coefficients = np.moveaxis(np.tensordot(_TO_COEFFICIENTS, coefficients, ([1], [j])), 0, j)
    probe = np.random.default_rng(0).uniform(-math.pi, math.pi, (16, d))  # generic positions
    exact = table.regressor(list(probe.T))[:, :, columns]
    out = {}
    for k, name in enumerate(ANGLE_SYMBOLS):
        block = coefficients[..., k, :]
        peak = np.abs(block).reshape(-1, block.shape[-1]).max(axis=0)
        members = np.flatnonzero(peak > 1e-12 * max(float(peak.max()), 1e-300))
        given = {} if whole_turns else table.angle_domains_rad(name)
        domain = tuple(given.get(joint, FULL_TURN_RAD) for joint in table.joint_names)
        named = [j for j, joint in enumerate(table.joint_names) if joint in given]
        out[name] = AngleRows(
            name,
            tuple(table.angular_names[i] for i in members),
            block[..., members],
            domain,
            grid_axes_rad(table, grid_step_deg, domain),
            tuple(table.joint_names),
            tuple(table.angle_names),
            tuple(named or range(d)),
        )
        if np.max(np.abs(out[name].values(probe) - exact[:, k, members]), initial=0) > 1e-12:
            raise ModelError(f"{table.urdf_path}: the first-order model is not of degree one")
    return out


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


def _max_along_joint(rows: np.ndarray, z, lo_rad: float, hi_rad: float) -> tuple[float, float]:
    """Exact maximum of ``h(t) = sum_i z_i |c_i + a_i cos t + b_i sin t|`` over ``[lo, hi]`` (at
    most a turn), ``rows`` (3, m) holding c, a, b: (value, t). Between the zeros of the rows the
    signs are fixed and ``h`` is one ``c + a cos + b sin`` (:func:`interval_max` on each piece)."""
    const, cos, sin = rows
    r = np.hypot(cos, sin)
    crossing = (r > 0.0) & (np.abs(const) <= r)
    phase = np.arctan2(sin[crossing], cos[crossing])
    half = np.arccos(np.clip(-const[crossing] / r[crossing], -1.0, 1.0))
    zeros = lo_rad + (np.concatenate([phase + half, phase - half]) - lo_rad) % (2.0 * math.pi)
    edges = np.unique(np.concatenate([[lo_rad, hi_rad], zeros[zeros < hi_rad]]))
    best = (-math.inf, lo_rad)
    for start, end in zip(edges[:-1], edges[1:], strict=True):
        mid = 0.5 * (start + end)
        signed = np.sign(const + cos * math.cos(mid) + sin * math.sin(mid)) * z
        best = max(best, interval_max(signed @ cos, signed @ sin, signed @ const, start, end))
    return best


def _ascend(rows: AngleRows, points, z, local: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Each point (K, joints) moved to a local maximum of ``|C_k| @ z`` by exact maximisation
    along one joint at a time, over the joint's domain or (``local``) within a grid step of the
    point: (points, values)."""
    points = np.array(points, dtype=float).reshape(-1, len(rows.domain_rad))
    values = np.abs(rows.values(points)) @ z
    moving = [j for j, axis in enumerate(rows.axes_rad) if axis.size > 1]
    for _ in range(50):
        improved = False
        for j in moving:
            along = rows.values(points, keep=j)
            lo, hi = rows.domain_rad[j]
            step = float(rows.axes_rad[j][1] - rows.axes_rad[j][0])
            for p in range(len(points)):
                t = points[p, j]
                full = hi - lo >= 2.0 * math.pi * (1.0 - 1e-12)
                near = (t - step, t + step) if full else (max(lo, t - step), min(hi, t + step))
                value, t = _max_along_joint(along[p], z, *(near if local else (lo, hi)))
                if value > values[p] * (1.0 + 1e-14):
                    points[p, j], values[p], improved = (
                        t % (2.0 * math.pi) if full else t,
                        value,
                        True,
                    )
        if not improved:
            break
    return points, values


def _peaks(rows: AngleRows, z, more=()) -> tuple[np.ndarray, np.ndarray]:
    """Local maxima of ``|C_k| @ z`` from the best points of the starting grid, after those
    reached from the points ``more`` within their neighbourhood."""
    positions, magnitudes = rows.grid
    values = magnitudes @ z
    # Ties up to rounding go to the first grid point (a constant row peaks everywhere).
    ranked = np.round(values / max(float(values.max(initial=0.0)), 1e-300), 12)
    points, values = _ascend(rows, positions[np.argsort(-ranked, kind="stable")[:_STARTS]], z)
    if len(more):
        near, near_values = _ascend(rows, more, z, local=True)
        points, values = np.vstack([near, points]), np.concatenate([near_values, values])
    return points, values


def domain_max(rows: AngleRows, z) -> tuple[float, np.ndarray]:
    """``max over q in Omega_k of sum_i |C_ki(q)| z_i`` and where (radians per joint)."""
    points, values = _peaks(rows, np.asarray(z, dtype=float))
    best = int(np.argmax(values))
    return float(values[best]), points[best]


# ---- one angle's problem ----------------------------------------------------------------------
def _fixed_point_optimum(g, weights, lower, limit):
    """Closed-form optimum of ``min sum W^2/x^2 s.t. g.x <= limit, x >= lower`` for each row of
    ``g`` (..., m) at once (g may be <= 0). Returns ``(x, V)`` of shapes (..., m) and (...).

    Errors with ``g_i <= 0`` are unconstrained by this relaxation (x_i = inf, no cost). The free
    optimum is ``x_i = k_i u`` with ``k_i = (2 W_i^2 / g_i)^(1/3)``; with the lower bounds
    ``x_i = max(lower_i, k_i u)``, and ``sum g_i x_i`` rises piecewise linearly in u: ``u`` is
    found on the piece where the errors of the j smallest breakpoints ``lower_i / k_i`` are free.
    """
    g = np.asarray(g, dtype=float)
    w2, lower = np.asarray(weights, dtype=float) ** 2, np.asarray(lower, dtype=float)
    positive = g > 0.0
    safe = np.where(positive, g, 1.0)
    k = np.where(positive, np.cbrt(2.0 * w2 / safe), 0.0)
    breaks = np.where(positive, lower / np.where(positive, k, 1.0), np.inf)
    order = np.argsort(breaks, axis=-1, kind="stable")

    def sort(a):
        return np.take_along_axis(np.broadcast_to(a, g.shape), order, axis=-1)

    gs, ks, ls, bs = sort(np.where(positive, g, 0.0)), sort(k), sort(lower), sort(breaks)
    free = np.cumsum(gs * ks, axis=-1)
    at_lower = np.sum(gs * ls, axis=-1, keepdims=True) - np.cumsum(gs * ls, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        u = (limit - at_lower) / free
    following = np.concatenate([bs[..., 1:], np.full(g.shape[:-1] + (1,), np.inf)], axis=-1)
    valid = (u <= following) & np.isfinite(bs)
    j = np.argmax(valid, axis=-1)[..., None]
    room = np.sum(gs * ls, axis=-1, keepdims=True) < limit
    u_star = np.where(room & np.any(valid, axis=-1, keepdims=True), np.take_along_axis(u, j, -1), 0)
    x = np.where(positive, np.maximum(lower, k * u_star), np.inf)
    value = np.sum(np.where(positive, w2 / np.where(positive, x, 1.0) ** 2, 0.0), axis=-1)
    return x, value


def minimize_weighted(w, start, lower, fun: Callable, jac: Callable) -> np.ndarray:
    """SLSQP on ``min sum w^2/z^2`` s.t. ``fun(z) >= 0`` (gradient ``jac``), ``z >= lower``
    (and ``z >= 1e-12``), in units of the limit."""
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


def _distinct(rows: AngleRows, points) -> list[int]:
    """Indices of the points whose rows ``|C_k|`` differ from every earlier one's (points with
    the same rows -- a table's symmetric positions -- are one constraint)."""
    g = np.abs(rows.values(points))
    scale = max(float(np.abs(g).max(initial=0.0)), 1e-300)
    return [i for i in range(len(g)) if np.all(np.abs(g[:i] - g[i]).max(axis=1) > 1e-6 * scale)]


def _optimum(rows: AngleRows, w, lower_z) -> tuple[np.ndarray, str, np.ndarray]:
    """``min sum w^2/z^2`` s.t. ``max_q |C_k(q)| @ z <= 1``, ``z >= lower_z`` (see the module):
    the solution, the method and the points it was solved on."""
    positions, magnitudes = rows.grid
    points = positions[[int(np.argmax(_fixed_point_optimum(magnitudes, w, lower_z, 1.0)[1]))]]
    z = np.full(w.shape, np.inf)
    for _ in range(100):
        g = np.abs(rows.values(points))
        if len(points) == 1:
            z = _fixed_point_optimum(g[0], w, lower_z, 1.0)[0]
        else:
            start = np.where(np.isfinite(z), z, _FAR)
            start = np.maximum(start / float(np.max(g @ start)), lower_z)
            z = minimize_weighted(w, start, lower_z, lambda v, g=g: 1.0 - g @ v, lambda v, g=g: -g)
        finite = np.where(np.isfinite(z), z, _FAR)
        moved, _ = _ascend(rows, points, finite, local=True)
        peak, worst = domain_max(rows, finite)
        new = peak > 1.0 + _MET and len(_distinct(rows, [*moved, worst])) > len(moved)
        shift = np.abs(np.abs(rows.values(moved)) - g).max() / max(float(g.max()), 1e-300)
        if not new and shift <= 1e-12:
            break
        points = np.array([*moved, worst] if new else moved)
        points = points[_distinct(rows, points)]
    exact = len(points) == 1 and peak <= 1.0 + _MET and np.all(np.isfinite(z))
    z = finite
    if peak > 1.0 or not exact:  # onto the constraint: admissible, and no cheaper
        z = np.maximum(lower_z, z / peak)
    return z, "exact" if exact else "cutting planes", points


def _multipliers(rows: AngleRows, w, z, x_arcmin, at_lower, points):
    """The constraint's maximum at ``z`` (units of the limit) and where, its multiplier (summed
    over its active points: local maxima from ``points`` and the grid; errors in arc minutes) and
    the KKT residual (largest relative stationarity error of the free errors)."""
    from scipy.optimize import nnls

    points, values = _peaks(rows, z, more=points)
    peak = float(values.max())
    active = points[values >= peak * (1.0 - 1e-7)]  # (SLSQP meets its points to ~1e-9)
    g = np.abs(rows.values(active[_distinct(rows, active)]))  # the active gradients (Danskin)
    grad = -2.0 * w**2 / x_arcmin**3
    free = ~at_lower
    scale = max(float(np.abs(grad).max(initial=0.0)), 1e-300)
    lam = np.zeros(len(g))
    if peak >= 1.0 - 1e-9 and np.any(free):
        lam = nnls(g[:, free].T, -grad[free] / scale)[0] * scale
    closing = np.where(free, grad + lam @ g, 0.0) / np.maximum(np.abs(grad), 1e-300)
    return peak, points[int(np.argmax(values))], float(lam.sum()), float(np.max(np.abs(closing)))


@dataclass(frozen=True)
class SubproblemResult:
    """The optimum of one angle's problem.

    Attributes:
        angle: psi, theta or gamma.  error_names: the errors that move it.
        weights, lower_bounds_rad, solution_rad: per error of ``error_names``.
        limit_rad: I_k.  method: ``exact`` or ``cutting planes``.
        domain_rad: Omega_k, one ``(lo, hi)`` per joint.  joint_names: the joints.
        constraint_rad: ``max over Omega_k of sum |C_k| x`` at the solution (<= limit), reached
            at ``at_angles_rad`` (one angle per joint).
        multiplier: the constraint's (x in arcmin, summed over its active points).
        kkt_residual: largest relative stationarity error.
        angle_names: the joints' angles in words.  named: the joints the words name (chain
            indices; :class:`AngleRows`).
    """

    angle: str
    error_names: tuple[str, ...]
    weights: np.ndarray
    lower_bounds_rad: np.ndarray
    solution_rad: np.ndarray
    limit_rad: float
    method: str
    domain_rad: tuple[tuple[float, float], ...]
    joint_names: tuple[str, ...]
    constraint_rad: float
    at_angles_rad: tuple[float, ...]
    multiplier: float
    kkt_residual: float
    angle_names: tuple[str, ...] = ()
    named: tuple[int, ...] = ()

    @property
    def J(self) -> float:
        """The objective ``sum W^2 / x^2`` at the optimum, errors in arc minutes (1/arcmin^2)."""
        return float(np.sum(self.weights**2 / (self.solution_rad * ARCMIN_PER_RAD) ** 2))

    @property
    def _words(self) -> tuple[str, ...]:
        """The angle names of the named joints (the joint names where none are given)."""
        names = self.angle_names or self.joint_names
        return tuple(names[j] for j in self.named)

    @property
    def domain_deg(self) -> dict[str, list[float]]:
        """``{angle name: [lo, hi]}`` of the named joints' intervals, degrees."""
        return {
            w: [v * DEG_PER_RAD for v in self.domain_rad[j]]
            for w, j in zip(self._words, self.named, strict=True)
        }

    @property
    def at_max_deg(self) -> dict[str, float]:
        """``{angle name: degrees}`` of the named joints where the constraint peaks."""
        return {
            w: self.at_angles_rad[j] * DEG_PER_RAD
            for w, j in zip(self._words, self.named, strict=True)
        }

    @property
    def active(self) -> tuple[str, ...]:
        """The active constraints in words (the domain and the peak over the named joints)."""
        out = []
        if self.constraint_rad >= self.limit_rad * (1.0 - 1e-9):
            over = " and ".join(f"{w} in [{lo:g}, {hi:g}] deg" for w, (lo, hi) in
                                self.domain_deg.items())  # fmt: skip
            at = ", ".join(f"{w} = {a:.4f} deg" for w, a in self.at_max_deg.items())
            out.append(f"max d{self.angle} over {over} = limit (at {at})")
        lower = self.solution_rad <= self.lower_bounds_rad * (1.0 + 1e-9)
        return (
            *out,
            *(f"{n} = lower bound" for n, f in zip(self.error_names, lower, strict=True) if f),
        )

    def to_dict(self) -> dict:
        """The optimum, JSON-ready: angle, solution (arcmin), weights, J, limit (arcmin), the
        domain of the named joints (degrees), the constraint's maximum (arcmin) and where it
        peaks, its multiplier and the KKT residual, active constraints and method."""
        return {
            "angle": self.angle,
            "solution_arcmin": arcmin_by_name(self.error_names, self.solution_rad),
            "weights": dict(zip(self.error_names, map(float, self.weights), strict=True)),
            "J": self.J,
            "limit_arcmin": self.limit_rad * ARCMIN_PER_RAD,
            "domain_deg": self.domain_deg,
            "constraint_arcmin": self.constraint_rad * ARCMIN_PER_RAD,
            "at_max_deg": self.at_max_deg,
            "multiplier": self.multiplier,
            "kkt_residual": self.kkt_residual,
            "active_constraints": list(self.active),
            "method": self.method,
        }


def solve_subproblem(rows: AngleRows, limit_rad: float, weights, lower_bounds_rad):
    """:class:`SubproblemResult` of angle ``rows.angle`` (see the module); ``weights`` and
    ``lower_bounds_rad`` per error of ``rows.error_names``, radians.

    Raises:
        InfeasibleError: the lower bounds alone already exceed the limit somewhere in the domain.
    """
    w, lower = np.asarray(weights, dtype=float), np.asarray(lower_bounds_rad, dtype=float)
    lower_z = lower / limit_rad  # in units of the limit: x = z * limit
    at_lower, _ = domain_max(rows, lower_z)
    if at_lower > 1.0 + _MET:
        raise lower_bounds_infeasible(rows.angle, at_lower * limit_rad, limit_rad, rows.error_names)
    z, method, points = _optimum(rows, w, lower_z) if w.size else (w, "exact", rows.grid[0][:1])
    x = z * limit_rad
    peak, at, multiplier, residual = _multipliers(
        rows, w, z, x * ARCMIN_PER_RAD, x <= lower * (1.0 + 1e-9), points
    )
    return SubproblemResult(
        rows.angle, rows.error_names, w, lower, x, float(limit_rad), method, rows.domain_rad,
        rows.joint_names, peak * limit_rad, tuple(map(float, at)), multiplier, residual,
        rows.angle_names, rows.named,
    )  # fmt: skip


# ---- weights and the whole allocation ------------------------------------------------------
def allocation_weights(scheme: str, sensitivities: Sensitivities | None = None, table=None):
    """Weights W (3, P) of ``table``'s angular errors (default the bundled table), rows
    :data:`ANGLE_SYMBOLS`: ``model``, the inverse of the average sensitivities (Figure 8;
    default on the table's grid); ``paper``, the inverse of the paper's Figure 8 value 0.6481 for
    every term that varies with the angles and 1 for the constant ones (the paper's rule, on any
    table); ``equal``, 1 everywhere (the "traditional" allocation).
    """
    table = resolve_table(table)
    if scheme not in WEIGHT_SCHEMES:
        raise InputError(f"unknown weights '{scheme}'; choose one of {', '.join(WEIGHT_SCHEMES)}")
    if scheme == "equal":
        return np.ones((3, len(table.angular_names)))
    sens = sensitivities or sensitivity.sensitivities(table)
    if scheme == "paper":
        return np.where(np.ptp(sens.matrices, axis=0) > 1e-12, 1.0 / PAPER_FIGURE8_TRIG, 1.0)
    with np.errstate(divide="ignore"):
        return np.where(sens.values > 0.0, 1.0 / sens.values, np.inf)


@dataclass(frozen=True)
class Allocation(NotebookResult):
    """Upper bounds of a table's angular errors (eq. 34) and how they were obtained.

    Attributes:
        upper_bounds_rad: (P,) radians in the table's angular order (``inf``: moves no angle).
        limits: the :class:`OrientationLimits`.  weights_scheme: model, paper or equal.
        weights: (3, P).  subproblems: ``{psi|theta|gamma: SubproblemResult}``.
        worst_case_rad: (3,) the largest first-order |dpsi|, |dtheta|, |dgamma| the box
            ``|chi| <= UB`` allows over every sign and every joint angle (Lemma 1).
        capability: the lower bounds.  table: the table.  sensitivities: behind the weights.
    """

    upper_bounds_rad: np.ndarray
    limits: OrientationLimits
    weights_scheme: str
    weights: np.ndarray
    subproblems: dict
    worst_case_rad: np.ndarray
    capability: ManufacturingCapability = field(kw_only=True)
    table: object = field(kw_only=True, repr=False)
    sensitivities: Sensitivities = field(kw_only=True, repr=False)

    @property
    def error_names(self) -> tuple[str, ...]:
        """The table's angular errors (the order of the bounds)."""
        return self.capability.error_names

    @property
    def lower_bounds_rad(self) -> np.ndarray:
        """The lower bounds used, radians."""
        return self.capability.lower_bounds_rad

    @property
    def J(self) -> dict[str, float]:
        """Objective of each problem at its optimum (1/arcmin^2) and their sum."""
        out = {name: self.subproblems[name].J for name in ANGLE_SYMBOLS}
        return {**out, "total": float(sum(out.values()))}

    def errors(self) -> np.ndarray:
        """The upper bounds as an error vector of the table (its ``parameter_names`` order; rad,
        m): every angular error at its bound, 0 for one that moves no angle (an infinite bound)
        and for the lengths, which never turn the payload. What ``table.orientation_error``,
        ``table.write_urdf`` and ``TurntableErrors.from_array`` (on the paper's table) take."""
        values = np.zeros(len(self.table.parameter_names))
        columns = [self.table.parameter_names.index(n) for n in self.error_names]
        values[columns] = np.where(np.isfinite(self.upper_bounds_rad), self.upper_bounds_rad, 0.0)
        return values

    def to_dict(self) -> dict:
        """The table (URDF, payload frame, joints), the bounds (upper in arcmin; the lower ones
        with their source and reasoning), objectives, worst case, limits, grid step, sub-problems
        and sensitivities, JSON-ready: one schema for every table."""
        return {
            "urdf": str(self.table.urdf_path),
            "payload_frame": self.table.payload_frame,
            "joints": list(self.table.joint_names),
            "upper_bounds_arcmin": arcmin_by_name(self.error_names, self.upper_bounds_rad),
            "J": self.J,
            "J_unit": "1/arcmin^2 (errors in arc minutes)",
            "worst_case_arcmin": arcmin_by_name(ANGLE_SYMBOLS, self.worst_case_rad),
            "limits_arcmin": self.limits.to_dict(),
            "weights": self.weights_scheme,
            "lower_bounds": self.capability.to_dict(),
            "grid_step_deg": self.sensitivities.grid_step_deg,
            "active_constraints": {n: list(self.subproblems[n].active) for n in ANGLE_SYMBOLS},
            "subproblems": {n: self.subproblems[n].to_dict() for n in ANGLE_SYMBOLS},
            "sensitivities": self.sensitivities.by_angle(),
        }

    def report(self) -> str:
        """As text: the bounds (upper in arc minutes and seconds, lower in arc seconds), each
        angle's worst case against its limit, each sub-problem's J, method and active
        constraints."""
        name = self.table.title
        step = self.sensitivities.grid_step_deg
        width = max(12, *(len(n) + 2 for n in self.error_names))
        lines = [
            f"Error allocation of {name} (joints {', '.join(self.table.joint_names)}; weights: "
            f"{self.weights_scheme}" + (f"; grid {step:g} deg)" if step else ")"),
            "",
            f"{'error':{width}s}{'upper bound':>24s}{'lower bound':>14s}",
        ]
        for n, ub, lb in zip(self.error_names, self.upper_bounds_rad * ARCMIN_PER_RAD,
                             self.lower_bounds_rad * ARCSEC_PER_RAD, strict=True):  # fmt: skip
            lines.append(f'{n:{width}s}{ub:11.4f}\' = {ub * 60:7.2f}"{lb:12.2f}"')
        lines += ["", "with every error at its final upper bound (the smallest of the three "
                  "sub-problems'):"]  # fmt: skip
        for k, angle in enumerate(ANGLE_SYMBOLS):
            limit = self.limits.to_dict()[angle]
            worst = self.worst_case_rad[k] * ARCMIN_PER_RAD
            state = (
                "at the limit"
                if worst >= limit * (1 - 1e-6)
                else f"{worst / limit:.0%} of the limit"
            )
            lines.append(f"d{angle:6s} limit {limit:.4f}'  worst case {worst:.4f}'  ({state})")
        lines.append(
            "each angle's own sub-problem (its bounds before the minimum over the angles):"
        )
        for angle in ANGLE_SYMBOLS:
            sub = self.subproblems[angle]
            lines.append(f"d{angle:6s} J = {sub.J:.6g} /arcmin^2  [{sub.method}, KKT residual "
                         f"{sub.kkt_residual:.1e}]")  # fmt: skip
            lines += [f"         active in it: {item}" for item in sub.active]
        return "\n".join(lines)


def allocate_tolerances(
    limits: OrientationLimits | None = None,
    weights: str = "model",
    capability: ManufacturingCapability | None = None,
    sensitivities: Sensitivities | None = None,
    *,
    table=None,
    grid_step_deg: float | None = None,
) -> Allocation:
    """Allocate the angular errors of ``table`` (default the bundled table) to meet ``limits``
    (eqs. 29-34; see the module).

    Args:
        limits: orientation limits (default :func:`default_orientation_limits` of the table).
        weights: ``model`` (default), ``paper`` or ``equal`` (:func:`allocation_weights`).
        capability: lower bounds (default: the table's bundled ones,
            :meth:`ManufacturingCapability.of_table`; none bundled: 0).
        sensitivities: the averages behind ``model`` weights (default on the table's grid).
        grid_step_deg: the grid of the sensitivities and of the maxima's starting points (default
            by table: 1, 5, 15 deg when the model depends on 1, 2, 3 joints).

    Raises:
        InfeasibleError: the lower bounds alone violate a limit.
    """
    table = resolve_table(table)
    names = tuple(table.angular_names)
    limits = limits or default_orientation_limits(table=table)
    if capability is None:
        capability = ManufacturingCapability.of_table(table)
    if capability.error_names != names:
        raise InputError(f"the lower bounds must be of this table's errors: {', '.join(names)}")
    sensitivities = sensitivities or sensitivity.sensitivities(table, grid_step_deg=grid_step_deg)
    w = allocation_weights(weights, sensitivities, table)
    rows = angle_rows(table, grid_step_deg)
    subproblems = {}
    for k, angle in enumerate(ANGLE_SYMBOLS):
        idx = [names.index(n) for n in rows[angle].error_names]
        subproblems[angle] = solve_subproblem(
            rows[angle], limits.as_array()[k], w[k, idx], capability.lower_bounds_rad[idx]
        )
    upper = np.full(len(names), np.inf)
    for sub in subproblems.values():  # eq. 34: the smallest of the sub-problems' solutions
        idx = [names.index(n) for n in sub.error_names]
        upper[idx] = np.minimum(upper[idx], sub.solution_rad)
    bounded = np.where(np.isfinite(upper), upper, 0.0)
    whole = angle_rows(table, grid_step_deg, whole_turns=True)  # Lemma 1: every angle and sign
    worst = [
        domain_max(whole[a], bounded[[names.index(n) for n in whole[a].error_names]])[0]
        for a in ANGLE_SYMBOLS
    ]
    return Allocation(
        upper, limits, weights, w, subproblems, np.array(worst),
        capability=capability, table=table, sensitivities=sensitivities,
    )  # fmt: skip

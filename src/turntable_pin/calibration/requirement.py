"""The orientation requirement of a calibration (paper eqs. 15-16, Figures 4-5).

Given a required calibration accuracy ``w_m`` (deg/h), find limits ``I_psi, I_theta, I_gamma`` such
that ``dwx <= w_m`` and ``dwy <= w_m`` whenever ``|dpsi| <= I_psi``, ``|dtheta| <= I_theta``,
``|dgamma| <= I_gamma``. As in the paper, ``dwx`` is studied over the plane (dpsi, dtheta) with
``dgamma = 0`` (surface Gamma1) and ``dwy`` over (dtheta, dgamma) with ``dpsi = 0`` (Gamma2).

The largest rectangle, precisely: in each plane (u, v) the rectangle is ``[-a, a] x [-b, b]``
centred at the origin that maximises the area ``4ab`` subject to ``dw <= w_m`` at its four
corners. Because ``dw`` is even in each angle and grows with each ``|angle|`` (tested), the corners
bound ``dw`` on the whole rectangle. For each ``a`` the largest admissible ``b(a)`` comes from a
bisection on the contour ``dw = w_m``; ``a b(a)`` is maximised by a dense scan refined by a bounded
scalar search; the rectangle is then pushed to the contour along ``a`` too, so neither side can
grow. ``dtheta`` appears in both planes: ``I_theta`` is the smaller of the two rectangles'
theta half-widths (the binding plane), and the other plane's free side is re-extended to the
contour at that ``I_theta`` (it can only grow). The result is therefore maximal: growing any one
of ``I_psi, I_theta, I_gamma`` makes ``dwx`` or ``dwy`` exceed ``w_m``.

The result also reports ``dwx`` and ``dwy`` at the corners of the three-dimensional box (all three
angles at their limits), which the paper's planar analysis does not look at: with the planes'
limits they exceed ``w_m`` (by 5 and 14 % on ``grid:30``).

The box that holds (:class:`RequirementBox`): the rate errors are linear in the orientation
error to first order (:func:`rate_error_jacobian`, ``J`` of shape (N, 2, 3) per position), so
over the box ``|dpsi| <= I_psi, ...`` the largest ``|dw_j|`` at a position is
``sum_k |J_jk| I_k``, reached at a corner. Of all the boxes with ``sum_k |J_jk(p)| I_k <= w_m``
for both axes j and every position p (a polytope), :func:`largest_box` takes the one of largest
volume ``I_psi I_theta I_gamma`` (the largest geometric mean of the three limits: no angle is
preferred, and any box not inside it can be shrunk into it). The full model (eq. 7's second-order
terms, or the exact rotation) then sets the scale: the box is scaled so that its worst corner
meets ``w_m`` exactly. Every point of it meets the accuracy; scaled up by any factor it does not.
"""

from __future__ import annotations

# scipy.optimize is imported inside functions: import turntable_pin stays light
from dataclasses import dataclass, field

import numpy as np

from ..core.exceptions import InputError
from ..core.progress import Progress
from ..core.turn_grid import every_combination
from ..core.units import rad_to_arcmin, rad_to_arcsec, rad_to_deg
from ..model.angles import ANGLE_SYMBOLS
from .drift_fit import require_identifiable
from .gyrowheel import AXES, GyroWheelModel
from .positions import PositionInputs, PositionSet, position_inputs
from .rate_error import (
    DEFINITIONS,
    orientation_error_rotation,
    rate_error_vectors_dph,
    rate_errors_at_angles_dph,
)

__all__ = [
    "ACCURACY_RANGE_DPH",
    "BOX_CRITERION",
    "JACOBIAN_STEP_RAD",
    "MAX_ANGLE_RAD",
    "PLANES",
    "PROGRESS_DELAY_S",
    "RECTANGLE_ZOOMS",
    "OrientationRequirement",
    "PlaneRateError",
    "PlaneRectangle",
    "RequirementBox",
    "box_corners",
    "check_accuracy_dph",
    "holding_scale",
    "largest_box",
    "largest_rectangle",
    "orientation_requirement",
    "rate_error_jacobian",
    "rectangle_steps",
    "requirement_box",
]

MAX_ANGLE_RAD = np.radians(10.0)
"""Search limit: beyond ten degrees the small-angle model of eq. 7 is meaningless."""

ACCURACY_RANGE_DPH: tuple[float, float] = (1e-6, 1.0)
"""Accepted required calibration accuracy ``w_m``, deg/h (ends included). The requirement scales
with ``w_m`` (about 0.01 deg for the paper's 0.01 deg/h): at 1 deg/h it is already about a degree,
the end of the small-angle model's range; at 1e-6 deg/h it is a few thousandths of an arc second,
below what any turntable or autocollimator resolves."""

PLANES: dict[str, tuple[str, tuple[int, int]]] = {
    "psi_theta": ("x", (0, 1)),
    "theta_gamma": ("y", (1, 2)),
}
"""Each plane of Figure 4: the axis whose error is studied and the two angle indices (u, v)."""

_SIGNS = np.array([[1, 1], [1, -1], [-1, 1], [-1, -1]], dtype=float)
_MARGIN = 1e-9


class PlaneRateError:
    """``dw`` of one axis over one plane of orientation-error angles (the third angle zero).

    Calling it with half-widths ``(u, v)`` (radians, arrays) gives the largest ``dw`` (deg/h) over
    the four corners ``(+-u, +-v)``; :meth:`surface` gives ``dw`` itself at signed points.
    """

    def __init__(
        self,
        plane: str,
        gyrowheel: GyroWheelModel,
        inputs: PositionInputs,
        *,
        exact: bool = False,
        definition: str = "true_coefficients",
    ) -> None:
        if plane not in PLANES:
            raise InputError(f"unknown plane '{plane}'; expected one of {tuple(PLANES)}")
        self.plane = plane
        self.axis, self.indices = PLANES[plane]
        self.gyrowheel, self.inputs = gyrowheel, inputs
        self.exact, self.definition = exact, definition

    def surface(self, u_rad, v_rad) -> np.ndarray:
        """``dw`` (deg/h) of this plane's axis at the signed points ``(u, v)`` (broadcast)."""
        u, v = np.broadcast_arrays(np.asarray(u_rad, float), np.asarray(v_rad, float))
        angles = np.zeros(u.shape + (3,))
        angles[..., self.indices[0]] = u
        angles[..., self.indices[1]] = v
        out = rate_errors_at_angles_dph(
            self.gyrowheel, self.inputs, angles, exact=self.exact, definition=self.definition
        )
        return out[:, 0 if self.axis == "x" else 1].reshape(u.shape)

    def __call__(self, u_rad, v_rad) -> np.ndarray:
        u, v = np.broadcast_arrays(np.asarray(u_rad, float), np.asarray(v_rad, float))
        corners = self.surface(u[..., None] * _SIGNS[:, 0], v[..., None] * _SIGNS[:, 1])  # (..., 4)
        return corners.max(axis=-1)

    # ---- contour ----------------------------------------------------------------------------
    def axis_limit(self, along: int, accuracy_dph: float) -> tuple[float, bool]:
        """Largest half-width along u (``along=0``) or v (1) with the other at zero.

        Returns ``(limit_rad, capped)``; ``capped`` when ``dw`` stays below ``w_m`` up to
        :data:`MAX_ANGLE_RAD`.
        """
        hi = 1e-5
        while True:
            point = (hi, 0.0) if along == 0 else (0.0, hi)
            if float(self(*point)) > accuracy_dph:
                break
            if hi >= MAX_ANGLE_RAD:
                return MAX_ANGLE_RAD, True
            hi = min(2.0 * hi, MAX_ANGLE_RAD)
        fixed = np.zeros(1)
        return float(self.largest(along, fixed, accuracy_dph, hi)[0]), False

    def largest(
        self,
        along: int,
        fixed_rad,
        accuracy_dph: float,
        hi_rad: float,
        *,
        rtol: float = 1e-13,
    ) -> np.ndarray:
        """For each fixed value of the other half-width, the largest half-width along ``along``
        in ``[0, hi_rad]`` with ``dw <= w_m`` at the corners.

        A vectorised Illinois (modified regula falsi) search on ``dw - w_m``, which is nearly
        piecewise linear here, with a bisection step every fourth iteration so that the bracket
        always shrinks. It stops where the bracket is narrower than ``rtol * hi_rad`` or where an
        admissible point is within ``1e-12 w_m`` of the contour; the admissible end is returned.
        """
        fixed = np.atleast_1d(np.asarray(fixed_rad, float)).copy()

        def excess(x, f):
            return (self(x, f) if along == 0 else self(f, x)) - accuracy_dph

        lo = np.zeros_like(fixed)
        hi = np.full_like(fixed, hi_rad)
        g_lo = excess(lo, fixed)
        g_hi = excess(hi, fixed)
        result = np.where(g_hi <= 0, hi, lo)
        active = np.flatnonzero((g_hi > 0) & (g_lo <= 0))
        last_side = np.zeros(fixed.size, dtype=int)
        for iteration in range(200):
            if active.size == 0:
                break
            a, b, ga, gb = lo[active], hi[active], g_lo[active], g_hi[active]
            x = b - gb * (b - a) / (gb - ga)
            bisect = (iteration % 4 == 3) | ~((x > a) & (x < b))
            x = np.where(bisect, 0.5 * (a + b), x)
            g = excess(x, fixed[active])
            ok = g <= 0
            # Illinois: when the same end survives twice, halve its value to unstick the method.
            same = last_side[active] == np.where(ok, 1, -1)
            g_hi[active] = np.where(ok & same, 0.5 * gb, np.where(ok, gb, g))
            g_lo[active] = np.where(~ok & same, 0.5 * ga, np.where(ok, g, ga))
            lo[active] = np.where(ok, x, a)
            hi[active] = np.where(ok, b, x)
            last_side[active] = np.where(ok, -1, 1)
            done = (hi[active] - lo[active] <= rtol * hi_rad) | (ok & (-g <= 1e-12 * accuracy_dph))
            result[active] = lo[active]
            active = active[~done]
        return result


@dataclass(frozen=True)
class PlaneRectangle:
    """The largest-area centred rectangle of one plane.

    Attributes:
        plane: ``"psi_theta"`` or ``"theta_gamma"``.
        axis: the GyroWheel axis whose error bounds it.
        half_widths_rad: ``(a, b)`` along the plane's two angles.
        axis_limits_rad: the contour's intercepts on the two angle axes.
        capped: whether an intercept hit :data:`MAX_ANGLE_RAD`.
    """

    plane: str
    axis: str
    half_widths_rad: tuple[float, float]
    axis_limits_rad: tuple[float, float]
    capped: bool

    def to_dict(self) -> dict:
        """The rectangle as a JSON-ready dict (half-widths and intercepts in degrees)."""
        names = self.plane.split("_")
        return {
            "plane": self.plane,
            "axis": self.axis,
            **{
                f"{n}_half_width_deg": rad_to_deg(w)
                for n, w in zip(names, self.half_widths_rad, strict=True)
            },
            **{
                f"{n}_axis_limit_deg": rad_to_deg(w)
                for n, w in zip(names, self.axis_limits_rad, strict=True)
            },
            "capped": self.capped,
        }


RECTANGLE_ZOOMS = 3
"""How many times :func:`largest_rectangle` zooms its scan in on the best half-width."""
PROGRESS_DELAY_S = 2.0
"""A requirement that takes longer than this reports its progress (stderr)."""


def rectangle_steps(zooms: int = RECTANGLE_ZOOMS) -> int:
    """The steps :func:`largest_rectangle` reports done: two axis limits, ``zooms + 1`` scans
    and the last push to the contour."""
    return zooms + 4


def largest_rectangle(
    function: PlaneRateError,
    accuracy_dph: float,
    *,
    scan_points: int = 48,
    zooms: int = RECTANGLE_ZOOMS,
    step=lambda: None,
) -> PlaneRectangle:
    """The centred rectangle of largest area with ``dw <= w_m`` at its corners (see module).

    ``a b(a)`` is scanned on ``scan_points`` values of ``a``, then ``zooms`` times on as many
    points between the best one's neighbours (the relative resolution of ``a`` ends near
    ``(2 / scan_points)^zooms``; the area is flat at its maximum, so it is far finer).
    ``step()`` is called after each of its :func:`rectangle_steps` steps (a progress report).
    """
    u_limit, u_capped = function.axis_limit(0, accuracy_dph)
    step()
    v_limit, v_capped = function.axis_limit(1, accuracy_dph)
    step()
    u_hi = u_limit * (1 + 1e-9) + 1e-15
    v_hi = v_limit * (1 + 1e-9) + 1e-15
    # Scanning and pushing a hair inside the contour keeps the bisections well defined where the
    # contour has a flat edge (dw constant along one angle, e.g. on a 90-degree grid): there the
    # test dw <= w_m on the edge itself would be decided by rounding.
    lower, upper = 0.0, u_limit * (1 - _MARGIN)
    best_a = u_limit
    for level in range(zooms + 1):
        start = lower + (upper - lower) / scan_points if level == 0 else lower
        us = np.linspace(start, upper, scan_points)
        vs = function.largest(1, us, accuracy_dph, v_hi, rtol=1e-9)
        best = int(np.argmax(us * vs))
        best_a = float(us[best])
        lower = float(us[max(best - 1, 0)])
        upper = float(us[min(best + 1, scan_points - 1)])
        step()
    b = float(function.largest(1, best_a, accuracy_dph, v_hi)[0])
    # Push to the contour along u as well so that neither side can grow, then b to the contour.
    a = float(function.largest(0, b * (1 - _MARGIN), accuracy_dph, u_hi)[0])
    b = float(function.largest(1, a * (1 - _MARGIN), accuracy_dph, v_hi)[0])
    a, b = _settle(function, a, b, accuracy_dph)
    step()
    return PlaneRectangle(
        plane=function.plane,
        axis=function.axis,
        half_widths_rad=(a, b),
        axis_limits_rad=(u_limit, v_limit),
        capped=u_capped or v_capped,
    )


def _settle(function: PlaneRateError, a: float, b: float, accuracy_dph: float):
    """Shrink ``(a, b)`` by a few margins if the corner itself ends a hair outside the contour
    (each side was pushed with the other one a margin inside)."""
    for _ in range(8):
        if float(function(a, b)) <= accuracy_dph:
            break
        a, b = a * (1 - 2 * _MARGIN), b * (1 - 2 * _MARGIN)
    return a, b


# ---- the box that holds ---------------------------------------------------------------------
BOX_CRITERION = "largest volume"
"""How :func:`largest_box` chooses among the boxes that hold: the largest product
``I_psi I_theta I_gamma``."""

JACOBIAN_STEP_RAD = 1e-4
"""Step of the central differences of :func:`rate_error_jacobian`, radians (about 20 arcsec, the
size of the requirement itself): under eq. 7 ``dw`` is a quadratic of the angles, whose central
difference is its exact linear part for any step; a step this large keeps rounding far below the
result (the 90-degree grid's nearly singular ``A'`` solves to about 1e-10)."""

_CORNER_SIGNS = every_combination([np.array([-1, 1])] * 3)


def box_corners(limits_rad) -> np.ndarray:
    """The eight corners ``(+-I_psi, +-I_theta, +-I_gamma)`` of a box, (8, 3) radians."""
    return _CORNER_SIGNS * np.asarray(limits_rad, dtype=float)


def rate_error_jacobian(
    gyrowheel: GyroWheelModel,
    inputs: PositionInputs,
    *,
    exact: bool = False,
    definition: str = "true_coefficients",
) -> np.ndarray:
    """``d dw / d(dpsi, dtheta, dgamma)`` at zero orientation error, per position.

    Returns the (N, 2, 3) array ``J[p, j, k]``: the rate error of axis j (x, y) at position p per
    radian of angle k (psi, theta, gamma), deg/h/rad, by central differences of eqs. 7-14
    (:func:`~turntable_pin.calibration.rate_error.rate_error_vectors_dph`, step
    :data:`JACOBIAN_STEP_RAD`). Under the printed eq. 13 row p depends on position p alone.
    """
    angles = np.concatenate([np.eye(3), -np.eye(3)]) * JACOBIAN_STEP_RAD
    rotations = orientation_error_rotation(*angles.T, exact=exact)
    dw = rate_error_vectors_dph(gyrowheel, inputs, rotations, definition=definition)
    return ((dw[:3] - dw[3:]) / (2 * JACOBIAN_STEP_RAD)).transpose(1, 2, 0)


def _undominated(rows: np.ndarray) -> np.ndarray:
    """The rows no other row bounds componentwise (only they can bind a box; of equal rows
    all are kept)."""
    keep = np.ones(rows.shape[0], dtype=bool)
    for start in range(0, rows.shape[0], 256):
        chunk = rows[start : start + 256, None, :]
        above = np.all(rows[None] >= chunk, axis=-1) & np.any(rows[None] > chunk, axis=-1)
        keep[start : start + 256] = ~above.any(axis=1)
    return rows[keep]


def largest_box(
    jacobian, accuracy_dph: float, *, cap_rad: float = MAX_ANGLE_RAD, start_rad=None
) -> tuple[np.ndarray, np.ndarray]:
    """The box of largest volume whose first-order worst case meets ``w_m`` (see module).

    Args:
        jacobian: rate-error Jacobian rows, any shape ending in 3 (deg/h per rad of dpsi,
            dtheta, dgamma), e.g. :func:`rate_error_jacobian`'s (N, 2, 3).
        accuracy_dph: ``w_m``, deg/h.
        cap_rad: largest limit of any angle (an angle no row depends on stops there).
        start_rad: a box near the answer to start the search from (e.g. that of similar
            rows), radians; default the largest cube.

    Returns:
        ``(limits_rad, capped)``: the (3,) half-widths, radians, and which of them the cap set.
    """
    from scipy.optimize import minimize

    rows = _undominated(np.abs(np.asarray(jacobian, dtype=float)).reshape(-1, 3)) / accuracy_dph
    rows = np.vstack([rows, np.eye(3) / cap_rad])  # the cap, as one more row per angle
    cube = 1.0 / float(np.max(rows.sum(axis=1)))
    first = np.full(3, cube)
    if start_rad is not None:
        first = np.minimum(np.maximum(np.asarray(start_rad, dtype=float), cube), cap_rad)
        first /= max(1.0, float(np.max(rows @ first)))
    # max sum log I subject to rows @ I <= 1: concave in x = log(I / cube), started inside.
    result = minimize(
        lambda x: -np.sum(x),
        np.log(first / cube) + np.log1p(-1e-6),
        jac=lambda x: -np.ones(3),
        method="SLSQP",
        constraints=[
            {
                "type": "ineq",
                "fun": lambda x: 1.0 - rows @ (cube * np.exp(x)),
                "jac": lambda x: -rows * (cube * np.exp(x)),
            }
        ],
        options={"ftol": 1e-15, "maxiter": 500},
    )
    limits = cube * np.exp(result.x if np.all(np.isfinite(result.x)) else np.zeros(3))
    limits /= max(1.0, float(np.max(rows @ limits)))
    return limits, limits >= cap_rad * (1 - 1e-9)


@dataclass(frozen=True)
class RequirementBox:
    """The largest box ``|dpsi| <= I_psi, |dtheta| <= I_theta, |dgamma| <= I_gamma`` whose every
    point meets the required accuracy (see the module docstring).

    Attributes:
        psi_rad, theta_rad, gamma_rad: the half-widths, radians.
        criterion: :data:`BOX_CRITERION`.
        dwx_dph, dwy_dph: the largest ``dwx``, ``dwy`` over the box's corners (the full model);
            the larger one is ``w_m``.
        binding: for each axis (x, y) whose first-order worst case meets ``w_m`` (to 1e-7),
            the index of the position where it does.
        capped: which limits stopped at :data:`MAX_ANGLE_RAD` (no position limits them).
        scale: the full model's correction of the first-order box (1 to about 1e-4).
    """

    psi_rad: float
    theta_rad: float
    gamma_rad: float
    criterion: str
    dwx_dph: float
    dwy_dph: float
    binding: tuple[tuple[str, int], ...]
    capped: tuple[bool, bool, bool]
    scale: float

    @property
    def limits_rad(self) -> np.ndarray:
        """``[I_psi, I_theta, I_gamma]``, radians."""
        return np.array([self.psi_rad, self.theta_rad, self.gamma_rad])

    @property
    def volume_rad3(self) -> float:
        """``I_psi I_theta I_gamma``, rad^3 (the criterion)."""
        return float(np.prod(self.limits_rad))

    def to_dict(self) -> dict:
        """The limits (degrees, arc seconds), the criterion and the worst corner, JSON-ready."""
        out: dict = {}
        for name, value in zip(ANGLE_SYMBOLS, self.limits_rad, strict=True):
            out[f"I_{name}_deg"] = rad_to_deg(value)
            out[f"I_{name}_arcsec"] = rad_to_arcsec(value)
        return {
            **out,
            "criterion": self.criterion,
            "dwx_dph": self.dwx_dph,
            "dwy_dph": self.dwy_dph,
            "binding": [{"axis": a, "position_index": i} for a, i in self.binding],
            "capped": list(self.capped),
        }


def holding_scale(
    accuracy_dph: float,
    gyrowheel: GyroWheelModel,
    inputs: PositionInputs,
    limits_rad,
    *,
    exact: bool = False,
    definition: str = "true_coefficients",
) -> tuple[float, np.ndarray]:
    """The largest ``s`` such that the box ``s * limits_rad`` holds: its worst corner meets
    ``w_m`` (deg/h) exactly, by the full model (eqs. 7-14) at the positions of ``inputs``.

    Returns ``(s, worst)`` with ``worst`` (N, 2) each position's largest ``|dw|`` (x, y) over
    the corners of ``s * limits_rad``, deg/h.
    """
    limits = np.asarray(limits_rad, dtype=float)

    def worst(scale: float) -> np.ndarray:
        rotations = orientation_error_rotation(*box_corners(scale * limits).T, exact=exact)
        dw = np.abs(rate_error_vectors_dph(gyrowheel, inputs, rotations, definition=definition))
        return dw.max(axis=0)

    # dw is first order in the angles up to terms of relative size ~I: a few fixed-point steps
    # s <- s w_m / worst(s) meet the contour, then the last rounding is shed.
    scale = 1.0
    for _ in range(20):
        ratio = float(worst(scale).max()) / accuracy_dph
        if abs(ratio - 1.0) <= 1e-13:
            break
        scale /= ratio
    per_position = worst(scale)
    for attempt in range(50):
        if float(per_position.max()) <= accuracy_dph:
            break
        scale *= 1.0 - 2.0 ** (attempt - 52)
        per_position = worst(scale)
    return float(scale), per_position


def requirement_box(
    accuracy_dph: float,
    gyrowheel: GyroWheelModel,
    inputs: PositionInputs,
    *,
    exact: bool = False,
    definition: str = "true_coefficients",
) -> RequirementBox:
    """The largest box that holds (:class:`RequirementBox`) for accuracy ``w_m`` (deg/h) at the
    positions of ``inputs``, with the rate-error model of ``exact`` and ``definition``."""
    jacobian = rate_error_jacobian(gyrowheel, inputs, exact=exact, definition=definition)
    first_order, capped = largest_box(jacobian, accuracy_dph)
    scale, per_position = holding_scale(
        accuracy_dph, gyrowheel, inputs, first_order, exact=exact, definition=definition
    )
    corner = per_position.max(axis=0)
    first_order_worst = np.abs(jacobian) @ first_order  # (N, 2)
    binding = tuple(
        (axis, int(np.argmax(first_order_worst[:, j])))
        for j, axis in enumerate(AXES)
        if first_order_worst[:, j].max() >= accuracy_dph * (1 - 1e-7)
    )
    limits = scale * first_order
    return RequirementBox(
        psi_rad=float(limits[0]),
        theta_rad=float(limits[1]),
        gamma_rad=float(limits[2]),
        criterion=BOX_CRITERION,
        dwx_dph=float(corner[0]),
        dwy_dph=float(corner[1]),
        binding=binding,
        capped=tuple(bool(c) for c in capped),
        scale=float(scale),
    )


@dataclass(frozen=True)
class OrientationRequirement:
    """The requirement ``|dpsi| <= I_psi, |dtheta| <= I_theta, |dgamma| <= I_gamma`` (eq. 15).

    Attributes:
        accuracy_dph: the required accuracy ``w_m``, deg/h.
        psi_rad, theta_rad, gamma_rad: the limits I_psi, I_theta, I_gamma, radians (the names
            of :class:`~turntable_pin.allocation.solver.OrientationLimits`).
        binding_plane: the plane whose rectangle set ``I_theta``.
        rectangles: the largest-area rectangle of each plane before ``I_theta`` was shared.
        box_dwx_dph, box_dwy_dph: largest ``dwx``, ``dwy`` over the eight corners of the box
            with all three angles at their limits (the paper's planes leave the third angle out).
        box: the largest box whose every point meets ``w_m`` (:class:`RequirementBox`), beside
            the planes' limits above.
        latitude_rad, positions_name, n_positions, definition, exact: the set-up.
    """

    accuracy_dph: float
    psi_rad: float
    theta_rad: float
    gamma_rad: float
    binding_plane: str
    rectangles: tuple[PlaneRectangle, PlaneRectangle]
    box_dwx_dph: float
    box_dwy_dph: float
    box: RequirementBox
    latitude_rad: float
    positions_name: str
    n_positions: int
    definition: str
    exact: bool
    gyrowheel: GyroWheelModel = field(repr=False)
    inputs: PositionInputs = field(repr=False)

    @property
    def limits_rad(self) -> np.ndarray:
        """``[I_psi, I_theta, I_gamma]``, radians."""
        return np.array([self.psi_rad, self.theta_rad, self.gamma_rad])

    def to_dict(self) -> dict:
        """The limits (degrees, arcmin, arcsec), the set-up and both rectangles, JSON-ready."""
        units = {"deg": rad_to_deg, "arcmin": rad_to_arcmin, "arcsec": rad_to_arcsec}
        return {
            **{
                f"I_{n}_{unit}": convert(v)
                for unit, convert in units.items()
                for n, v in zip(ANGLE_SYMBOLS, self.limits_rad, strict=True)
            },
            "accuracy_dph": self.accuracy_dph,
            "positions": self.positions_name,
            "n_positions": self.n_positions,
            "latitude_deg": rad_to_deg(self.latitude_rad),
            "definition": self.definition,
            "exact_rotation": self.exact,
            "binding_plane": self.binding_plane,
            "rectangles": [r.to_dict() for r in self.rectangles],
            "box_dwx_dph": self.box_dwx_dph,
            "box_dwy_dph": self.box_dwy_dph,
            "box": self.box.to_dict(),
        }


def check_accuracy_dph(accuracy_dph: float) -> float:
    """``accuracy_dph`` (the required accuracy ``w_m``, deg/h) as a float, or
    :class:`InputError` unless it is a number in :data:`ACCURACY_RANGE_DPH`."""
    if not (np.isfinite(accuracy_dph) and accuracy_dph > 0):
        raise InputError(f"the required accuracy must be a positive number, got {accuracy_dph!r}")
    low, high = ACCURACY_RANGE_DPH
    if not low <= accuracy_dph <= high:
        raise InputError(
            f"the required accuracy must be between {low:g} and {high:g} deg/h, "
            f"got {accuracy_dph!r}"
        )
    return float(accuracy_dph)


def orientation_requirement(
    accuracy_dph: float,
    positions: PositionSet,
    latitude_rad: float,
    *,
    gyrowheel: GyroWheelModel | None = None,
    exact: bool = False,
    definition: str = "true_coefficients",
    progress: bool = False,
) -> OrientationRequirement:
    """The orientation requirement (eqs. 15-16) for accuracy ``w_m`` on a position set.

    Args:
        accuracy_dph: required calibration accuracy ``w_m``, deg/h (in
            :data:`ACCURACY_RANGE_DPH`).
        positions: the test positions of a table; they must turn gravity through all three
            payload axes, else :class:`IdentifiabilityError` (see
            :func:`~turntable_pin.calibration.drift_fit.require_identifiable`).
        latitude_rad: latitude of the test site, radians.
        gyrowheel: the drift coefficients (default: paper Table 1).
        exact: exact rotation for ``dR`` instead of eq. 7.
        definition: the rate-error definition (see :mod:`turntable_pin.calibration.rate_error`).
        progress: report the progress on stderr when the work lasts longer than
            :data:`PROGRESS_DELAY_S` (a three-axis grid takes seconds).
    """
    check_accuracy_dph(accuracy_dph)
    if definition not in DEFINITIONS:
        raise InputError(f"unknown rate-error definition '{definition}'; expected {DEFINITIONS}")
    gyrowheel = gyrowheel if gyrowheel is not None else GyroWheelModel.nominal()
    inputs = position_inputs(positions, latitude_rad)
    require_identifiable(inputs, every_coefficient=False)
    fx = PlaneRateError("psi_theta", gyrowheel, inputs, exact=exact, definition=definition)
    fy = PlaneRateError("theta_gamma", gyrowheel, inputs, exact=exact, definition=definition)
    steps = 2 * rectangle_steps() + 2  # the planes, the other side re-extended, the box
    with Progress(
        steps, f"requirement ({len(positions)} positions)", enabled=progress,
        delay_s=PROGRESS_DELAY_S,
    ) as bar:  # fmt: skip
        return _requirement(
            accuracy_dph, positions, latitude_rad, gyrowheel, inputs, (fx, fy), bar.update,
            exact=exact, definition=definition,
        )  # fmt: skip


def _requirement(
    accuracy_dph, positions, latitude_rad, gyrowheel, inputs, planes, step, *, exact, definition
) -> OrientationRequirement:
    """:func:`orientation_requirement` once its inputs are checked; ``step()`` after each of
    its steps."""
    fx, fy = planes
    rect_x = largest_rectangle(fx, accuracy_dph, step=step)
    rect_y = largest_rectangle(fy, accuracy_dph, step=step)
    psi, theta_x = rect_x.half_widths_rad
    theta_y, gamma = rect_y.half_widths_rad
    # The other plane's free side re-extended to the contour at the binding plane's I_theta.
    binding = "psi_theta" if theta_x <= theta_y else "theta_gamma"
    other, rect, free = (fy, rect_y, 1) if theta_x <= theta_y else (fx, rect_x, 0)
    theta = min(theta_x, theta_y)
    side = other.largest(
        free, theta * (1 - _MARGIN), accuracy_dph, rect.axis_limits_rad[free] * 1.000001
    )
    pair = _settle(
        other, *((theta, float(side[0])) if free else (float(side[0]), theta)), accuracy_dph
    )
    if free:
        theta, gamma = pair
    else:
        psi, theta = pair
    corners = box_corners([psi, theta, gamma])
    box = rate_errors_at_angles_dph(
        gyrowheel, inputs, corners, exact=exact, definition=definition
    ).max(axis=0)
    step()
    held = requirement_box(accuracy_dph, gyrowheel, inputs, exact=exact, definition=definition)
    step()
    return OrientationRequirement(
        accuracy_dph=float(accuracy_dph),
        psi_rad=float(psi),
        theta_rad=float(theta),
        gamma_rad=float(gamma),
        binding_plane=binding,
        rectangles=(rect_x, rect_y),
        box_dwx_dph=float(box[0]),
        box_dwy_dph=float(box[1]),
        box=held,
        latitude_rad=float(latitude_rad),
        positions_name=positions.name,
        n_positions=len(positions),
        definition=definition,
        exact=exact,
        gyrowheel=gyrowheel,
        inputs=inputs,
    )

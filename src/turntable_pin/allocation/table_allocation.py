"""Error allocation for any table (1 to 3 joints, from its URDF): sensitivities, bounds, worst case.

The paper's allocation (:mod:`.solver`) is built on its table's eq. 26. For any other table the
same problem is posed on the table's exact first-order model, read off
:meth:`GenericTable.regressor <turntable_pin.model.generic_table.GenericTable.regressor>`:
``C(q) = d(dpsi, dtheta, dgamma)/d(errors)`` at zero errors, for the table's *angular* errors
(``<joint>.position``, ``.tilt_a``, ``.tilt_b``, ``<mount>.rot_x/y/z``; the offsets move the
payload, never its orientation).

- The positions ``q`` are a full grid over every joint (step :func:`default_grid_step_deg`:
  1 degree for one joint, 5 for two, 15 for three, unless given).
- Sensitivities (the analogue of the paper's Figure 8): the mean of ``|C_ki(q)|`` over the grid.
- Angle k's problem, over the magnitudes ``x_i >= LB_i`` of the errors that move it::

      min  J_k = sum_i W_ki^2 / x_i^2   s.t.  sum_i |C_ki(q)| x_i <= I_k  at every grid q,

  the left side being the largest first-order ``|d angle_k|`` that errors of those magnitudes
  reach at ``q`` over every sign. Weights ``W = 1 / sensitivity`` (``model``) or 1 (``equal``).
  Solved exactly: each single row ``q`` has the closed-form optimum of
  :func:`.common.fixed_angle_solution`, a lower bound of the true optimum; the best row's
  optimum is the answer when it satisfies every row, otherwise rows are added one at a time
  (the most violated first) and SLSQP solves the problem on the rows so far, until none is
  violated (a cutting-plane method; the last point is scaled onto the constraint).
- The upper bounds combine as eq. 34: ``UB_i = min_k x*_ki``; the worst case is
  ``max_q sum_i |C_ki(q)| UB_i`` (first order, every sign, every grid position).
"""

from __future__ import annotations

import math
from dataclasses import KW_ONLY, dataclass, field
from pathlib import Path

import numpy as np

from ..core.exceptions import InputError
from ..core.units import ARCMIN_PER_RAD, ARCSEC_PER_RAD, DEG_PER_RAD, arcmin_by_name
from ..model.errors import MAX_ANGULAR_ERROR_DEG
from .capability import read_lower_bounds_file
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
from .solver import OrientationLimits

__all__ = [
    "DEFAULT_GRID_STEPS_DEG",
    "MAX_GRID_POINTS",
    "TABLE_WEIGHT_SCHEMES",
    "TableAllocation",
    "TableSensitivities",
    "TableSubproblem",
    "allocate_table_tolerances",
    "angular_names",
    "default_grid_step_deg",
    "grid_angles_rad",
    "table_lower_bounds",
    "table_sensitivities",
]

DEFAULT_GRID_STEPS_DEG: dict[int, float] = {1: 1.0, 2: 5.0, 3: 15.0}
"""Default grid step per number of joints, degrees (360, 5184 and 13824 positions)."""
MAX_GRID_POINTS = 200_000
"""Most positions a grid over every joint may have (memory of the regressor on it)."""
TABLE_WEIGHT_SCHEMES: tuple[str, ...] = ("model", "equal")
"""The weights an allocation of any table knows (the paper's Figure 8 values are its own)."""

_RELATIVE_ZERO = 1e-12  # a sensitivity below this (times the largest) does not count


def angular_names(table) -> tuple[str, ...]:
    """The table's angular errors (every parameter but the offsets), in parameter order."""
    return tuple(n for n in table.parameter_names if n not in table.length_names)


def default_grid_step_deg(table) -> float:
    """The default grid step for ``table`` (see :data:`DEFAULT_GRID_STEPS_DEG`), degrees."""
    return DEFAULT_GRID_STEPS_DEG[len(table.joint_names)]


def grid_angles_rad(table, step_deg: float | None = None) -> list[np.ndarray]:
    """A full grid over every joint, ``0, step, ... < 360`` degrees each: one flat array of
    radians per joint (chain order), every combination."""
    step = default_grid_step_deg(table) if step_deg is None else float(step_deg)
    if not (math.isfinite(step) and 0.0 < step <= 90.0):
        raise InputError(f"the grid step must be in (0, 90] degrees, got {step_deg!r}")
    axis = np.arange(0.0, 360.0 - 1e-9, step) / DEG_PER_RAD
    count = axis.size ** len(table.joint_names)
    if count > MAX_GRID_POINTS:
        raise InputError(
            f"a {step:g}-degree grid over {len(table.joint_names)} joints has {count} positions, "
            f"more than {MAX_GRID_POINTS}; choose a coarser --grid-step-deg"
        )
    mesh = np.meshgrid(*([axis] * len(table.joint_names)), indexing="ij")
    return [m.ravel() for m in mesh]


@dataclass(frozen=True)
class TableSensitivities:
    """``C`` of a table's angular errors on a grid, and its mean magnitude.

    Attributes:
        error_names: the angular errors (columns).
        matrices: (N, 3, P) ``d(dpsi, dtheta, dgamma)/d(error)`` at each grid position (rad/rad).
        values: (3, P) mean of ``|C|`` over the grid (the Figure 8 analogue).
        grid_step_deg: the grid step, degrees.  joint_names: the joints of the grid.
        grid_rad: the grid, one flat array of radians per joint (chain order).
    """

    error_names: tuple[str, ...]
    matrices: np.ndarray = field(repr=False)
    values: np.ndarray
    grid_step_deg: float
    joint_names: tuple[str, ...]
    grid_rad: tuple = field(repr=False, default=())

    def to_dict(self) -> dict:
        """Grid and mean sensitivities by angle and error name, JSON-ready."""
        return {
            "averaging": "mean of |d angle / d error| over a full grid of every joint",
            "grid_step_deg": self.grid_step_deg,
            "joints": list(self.joint_names),
            "sensitivities": {
                angle: dict(zip(self.error_names, map(float, self.values[k]), strict=True))
                for k, angle in enumerate(ORIENTATION_ANGLES)
            },
        }


def table_sensitivities(table, grid_step_deg: float | None = None) -> TableSensitivities:
    """The sensitivities of ``table``'s angular errors on a full grid (see the module)."""
    step = default_grid_step_deg(table) if grid_step_deg is None else float(grid_step_deg)
    names = angular_names(table)
    columns = [table.parameter_names.index(n) for n in names]
    grid = grid_angles_rad(table, step)
    matrices = table.regressor(grid)[:, :, columns]
    return TableSensitivities(
        error_names=names,
        matrices=matrices,
        values=np.abs(matrices).mean(axis=0),
        grid_step_deg=step,
        joint_names=tuple(table.joint_names),
        grid_rad=tuple(grid),
    )


def table_lower_bounds(table, path: str | Path | None = None) -> np.ndarray:
    """Manufacturing lower bounds of the table's angular errors, radians (default all 0).

    ``path``: a YAML file ``lower_bounds: {<error>[_unit]: value}`` in the table's names
    (arc seconds without a suffix), like the paper's ``--lower-bounds`` file.
    """
    names = angular_names(table)
    if path is None:
        return np.zeros(len(names))
    path = Path(path)
    data = read_lower_bounds_file(path)
    try:
        values = table.errors_from_user_units(data["lower_bounds"])
    except InputError as exc:
        raise InputError(f"lower_bounds: {exc.detail}", path=path) from None
    lengths = [n for n in table.length_names if values[table.parameter_names.index(n)] != 0.0]
    if lengths:
        raise InputError(f"lower_bounds: '{lengths[0]}' is not an angular error", path=path)
    out = values[[table.parameter_names.index(n) for n in names]]
    if np.any(out < 0.0):
        bad = names[int(np.flatnonzero(out < 0.0)[0])]
        raise InputError(f"lower_bounds: '{bad}' is negative", path=path)
    return out


@dataclass(frozen=True)
class TableSubproblem(SubproblemOptimum):
    """The optimum of one angle's problem (the common fields: :class:`.common.SubproblemOptimum`;
    ``method`` is ``exact`` or ``cutting planes``).

    Attributes:
        worst_rad: the first-order worst case at the solution (<= limit).
        at_angles_deg: the grid position where it is reached, degrees (chain order).
    """

    worst_rad: float
    at_angles_deg: tuple[float, ...]

    def details(self) -> dict:
        """The first-order worst case (arcmin) and the grid position where it is reached."""
        return {
            "worst_case_arcmin": self.worst_rad * ARCMIN_PER_RAD,
            "at_angles_deg": list(self.at_angles_deg),
        }


def _solve_rows(rows: np.ndarray, w: np.ndarray, lower: np.ndarray) -> tuple[np.ndarray, str]:
    """``min sum w^2/z^2`` s.t. ``rows @ z <= 1``, ``z >= lower`` (rows >= 0): exact or by
    cutting planes (see the module docstring)."""
    values = np.empty(rows.shape[0])
    for r, g in enumerate(rows):
        values[r] = fixed_angle_solution(g, w, lower, 1.0)[1]
    best = int(np.argmax(values))
    z = fixed_angle_solution(rows[best], w, lower, 1.0)[0]
    if np.all(np.isfinite(z)) and float(np.max(rows @ z)) <= 1.0 + 1e-12:
        return z, "exact"
    chosen = [best]
    for _ in range(200):
        sub = rows[chosen]
        start = np.where(np.isfinite(z), z, 1.0 / max(float(sub.sum(axis=1).max()), 1e-300))
        start = np.maximum(start / max(float(np.max(sub @ start)), 1e-300), lower)
        z = minimize_weighted(w, start, lower, lambda v, a=sub: 1.0 - a @ v, lambda v, a=sub: -a)
        excess = rows @ z
        worst = int(np.argmax(excess))
        if excess[worst] <= 1.0 + 1e-9 or worst in chosen:
            break
        chosen.append(worst)
    return z, "cutting planes"


def _subproblem(angle, k, sens: TableSensitivities, weights, lower, limit_rad) -> TableSubproblem:
    """Solve angle ``k``'s problem (radians in and out)."""
    magnitude = np.abs(sens.matrices[:, k, :])  # (N, P)
    peak = magnitude.max(axis=0)
    members = np.flatnonzero(peak > _RELATIVE_ZERO * max(float(peak.max()), 1e-300))
    names = tuple(sens.error_names[i] for i in members)
    rows = magnitude[:, members]
    w, lb = np.asarray(weights, float)[members], np.asarray(lower, float)[members]
    lower_z = lb / limit_rad
    if float(np.max(rows @ lower_z)) > 1.0 + 1e-12:
        raise lower_bounds_infeasible(angle, float(np.max(rows @ lb)), limit_rad, names)
    z, method = _solve_rows(rows, w, lower_z)
    peak_value = float(np.max(rows @ z))
    if peak_value > 0.0:  # onto the constraint: admissible, and no cheaper by shrinking
        z = np.maximum(lower_z, z / peak_value)
    x = z * limit_rad
    excess = rows @ x
    at = int(np.argmax(excess))
    angles = tuple(float(np.degrees(a[at])) for a in sens.grid_rad)
    active = []
    if excess[at] >= limit_rad * (1.0 - 1e-6):
        where = ", ".join(f"{j} = {a:g}" for j, a in zip(sens.joint_names, angles, strict=True))
        active.append(f"first-order max |d{angle}| = limit (at {where} deg)")
    active += [
        f"{n} = lower bound" for n, v, b in zip(names, x, lb, strict=True) if v <= b * (1 + 1e-9)
    ]
    return TableSubproblem(
        angle=angle,
        error_names=names,
        weights=w,
        lower_bounds_rad=lb,
        solution_rad=x,
        limit_rad=float(limit_rad),
        worst_rad=float(excess[at]),
        at_angles_deg=angles,
        active=tuple(active),
        method=method,
    )


@dataclass(frozen=True)
class TableAllocation(AllocationSummary):
    """Upper bounds of a table's angular errors (eq. 34 on the table's own model); the fields of
    :class:`.common.AllocationSummary` (``upper_bounds_rad`` (P,), ``inf``: the error moves no
    angle; ``weights_scheme`` ``model`` or ``equal``; ``subproblems`` of
    :class:`TableSubproblem`; ``worst_case_rad`` first order, over the grid and every sign with
    every error at its upper bound) and, by keyword:

    Attributes:
        error_names: the table's angular errors.  lower_bounds_rad: (P,) radians.
        sensitivities: the :class:`TableSensitivities` used.  urdf, payload_frame: the table.
    """

    _: KW_ONLY
    error_names: tuple[str, ...]
    lower_bounds_rad: np.ndarray
    sensitivities: TableSensitivities = field(repr=False)
    urdf: str = ""
    payload_frame: str = ""

    def to_dict(self) -> dict:
        """Bounds (arcmin, by the table's error names), objectives, worst case, sub-problems."""
        return {
            "urdf": self.urdf,
            "payload_frame": self.payload_frame,
            "joints": list(self.sensitivities.joint_names),
            "upper_bounds_arcmin": arcmin_by_name(self.error_names, self.upper_bounds_rad),
            "lower_bounds_arcsec": {
                n: float(v * ARCSEC_PER_RAD)
                for n, v in zip(self.error_names, self.lower_bounds_rad, strict=True)
            },
            **self.summary_dict(),
            "grid_step_deg": self.sensitivities.grid_step_deg,
            **self.subproblems_dict(),
        }

    def report(self) -> str:
        """The table of upper bounds with J, worst case and active constraints, as text."""
        return render_allocation_report(
            f"Error allocation of {Path(self.urdf).name} (joints "
            f"{', '.join(self.sensitivities.joint_names)}; weights: {self.weights_scheme}; "
            f"grid {self.sensitivities.grid_step_deg:g} deg)",
            self.error_names,
            self.upper_bounds_rad,
            self.lower_bounds_rad,
            self.limits,
            self.worst_case_rad,
            self.subproblems,
        )


def allocate_table_tolerances(
    table,
    limits: OrientationLimits,
    weights: str = "model",
    lower_bounds_rad=None,
    grid_step_deg: float | None = None,
) -> TableAllocation:
    """Allocate ``table``'s angular errors to meet ``limits`` (see the module docstring).

    Args:
        table: a :class:`~turntable_pin.model.generic_table.GenericTable`.
        limits: orientation limits.  weights: ``model`` or ``equal``.
        lower_bounds_rad: (P,) manufacturing lower bounds in :func:`angular_names` order
            (default 0).  grid_step_deg: the grid over every joint (default by joint count).

    Raises:
        InfeasibleError: the lower bounds alone violate a limit.
    """
    if weights not in TABLE_WEIGHT_SCHEMES:
        raise InputError(
            f"weights '{weights}' are the paper table's; for this table choose one of "
            f"{', '.join(TABLE_WEIGHT_SCHEMES)}"
        )
    sens = table_sensitivities(table, grid_step_deg)
    p = len(sens.error_names)
    lower = np.zeros(p) if lower_bounds_rad is None else np.asarray(lower_bounds_rad, float)
    if lower.shape != (p,):
        raise InputError(f"expected {p} lower bounds ({', '.join(sens.error_names)})")
    if np.any(~np.isfinite(lower)) or np.any(lower < 0.0):
        raise InputError("lower bounds must be finite and not negative")
    if float(lower.max(initial=0.0)) > MAX_ANGULAR_ERROR_DEG / DEG_PER_RAD:
        raise InputError(f"a lower bound is beyond {MAX_ANGULAR_ERROR_DEG:g} deg")
    if weights == "equal":
        w = np.ones((3, p))
    else:
        with np.errstate(divide="ignore"):
            w = np.where(sens.values > 0.0, 1.0 / np.where(sens.values > 0, sens.values, 1), np.inf)
    subproblems = {}
    for k, name in enumerate(ORIENTATION_ANGLES):
        subproblems[name] = _subproblem(name, k, sens, w[k], lower, limits.as_array()[k])
    upper = combine_upper_bounds(subproblems, sens.error_names)
    finite = np.where(np.isfinite(upper), upper, 0.0)
    worst = (np.abs(sens.matrices) @ finite).max(axis=0)  # (3,)
    return TableAllocation(
        error_names=sens.error_names,
        upper_bounds_rad=upper,
        lower_bounds_rad=lower,
        limits=limits,
        weights_scheme=weights,
        weights=w,
        sensitivities=sens,
        subproblems=subproblems,
        worst_case_rad=worst,
        urdf=str(table.urdf_path),
        payload_frame=table.payload_frame,
    )

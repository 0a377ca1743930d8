"""Sensitivities of the orientation error to a table's angular errors (paper eq. 28, Figure 8).

``C[k, i] = d f_k / d chi_i`` for ``f = (dpsi, dtheta, dgamma)``, read off the table's regressor
(:meth:`GenericTable.regressor <turntable_pin.model.generic_table.GenericTable.regressor>`): the
first-order model at zero errors, or the exact chain at a given error set. The offsets move the
payload, never its orientation, so only the angular errors have columns.

Because ``C`` depends on the angles, the paper plots averages (Figure 8): :func:`sensitivities`
takes the mean of ``|C|`` over every combination of one grid per joint. By default each joint the
first-order model depends on runs over a full turn at the table's grid step (1 degree when one
joint matters, 5 for two, 15 for three) and a joint it does not depend on -- the paper's phi1, whose
errors turn with it -- is held at 0. On the paper's table that is 360 phi2 values, and the averages
are ``2/pi = 0.6366`` for every sin/cos term and 1 for every constant term. The paper's
``0.6476 / 0.5365`` are the mean of ``|cos|`` and ``|sin|`` over a 45-degree grid that counts both
0 and 360 degrees; its ``0.6481 / 0.5372`` and its small non-zero off-model values (0.0053,
0.0059, ...) match that grid applied to the exact chain at errors of about 0.1-0.2 degrees (see
``docs/allocation.md``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from ..core.exceptions import InputError
from ..core.sizes import MIN_GRID_STEP_DEG, turn_grid_count
from ..core.turn_grid import every_combination, full_turn_grid_deg
from ..core.units import DEG_PER_RAD
from ..core.words import argument
from ..model.angles import ANGLE_NAMES
from ..model.paper_table import resolve_table

__all__ = [
    "DEFAULT_GRID_STEPS_DEG",
    "FULL_TURN_RAD",
    "MAX_GRID_POINTS",
    "PAPER_FIGURE8_TRIG",
    "Sensitivities",
    "average_sensitivities",
    "check_grid_step",
    "default_grid_step_deg",
    "grid_axes_rad",
    "moving_joints",
    "sensitivities",
    "sensitivity_matrix",
]

PAPER_FIGURE8_TRIG = 0.6481
"""The paper's Figure 8 value for every sin/cos term of the ``paper`` weights (docs/model.md)."""
DEFAULT_GRID_STEPS_DEG: dict[int, float] = {1: 1.0, 2: 5.0, 3: 15.0}
"""Default grid step by the number of joints the first-order model depends on, degrees."""
MAX_GRID_POINTS = 200_000
"""Most positions a grid over every joint may have (memory of the regressor on it)."""
FULL_TURN_RAD = (0.0, 2.0 * math.pi)
"""A joint's whole turn, radians."""


@lru_cache(maxsize=32)
def moving_joints(table) -> tuple[bool, ...]:
    """Whether the table's first-order model depends on each joint (chain order): ``False`` for
    a joint all of whose error factors before it turn with it (the paper's phi1)."""
    rng = np.random.default_rng(0)  # generic positions: any random draw is generic
    angles = [rng.uniform(-math.pi, math.pi, 16) for _ in table.joint_names]
    base = table.regressor(angles)
    out = []
    for j in range(len(angles)):
        moved = list(angles)
        moved[j] = angles[j] + 1.0
        out.append(bool(np.max(np.abs(table.regressor(moved) - base)) > 1e-12))
    return tuple(out)


def default_grid_step_deg(table) -> float:
    """The default grid step of ``table`` (:data:`DEFAULT_GRID_STEPS_DEG` by the number of joints
    its first-order model depends on), degrees."""
    return DEFAULT_GRID_STEPS_DEG[max(1, sum(moving_joints(table)))]


def _step(table, step_deg) -> float:
    step = default_grid_step_deg(table) if step_deg is None else float(step_deg)
    if not (math.isfinite(step) and MIN_GRID_STEP_DEG <= step <= 90.0):
        raise InputError(
            f"the grid step must be in [{MIN_GRID_STEP_DEG:g}, 90] degrees, got {step_deg!r}"
        )
    return step


def _check_count(count: int, step: float, joints: int) -> None:
    if count > MAX_GRID_POINTS:
        raise InputError(
            f"a {step:g}-degree grid over {joints} joints has {count} positions, "
            f"more than {MAX_GRID_POINTS}; choose a coarser {argument('grid_step_deg')}"
        )


def check_grid_step(table, step_deg: float | None = None) -> float:
    """The grid step (default by table), degrees, refused when it is outside [MIN, 90] degrees or
    its full-turn grid over every joint has more than :data:`MAX_GRID_POINTS` positions."""
    step = _step(table, step_deg)
    joints = len(table.joint_names)
    _check_count(turn_grid_count(step) ** joints, step, joints)
    return step


def grid_axes_rad(table, step_deg: float | None = None, domain_rad=None) -> tuple[np.ndarray, ...]:
    """One grid per joint (chain order), radians: ``0, step, ... < 360`` degrees over a full turn,
    ``lo .. hi`` with both ends over an interval of ``domain_rad`` (one ``(lo, hi)`` per joint,
    default full turns); a joint the first-order model does not depend on: ``lo`` only."""
    step = _step(table, step_deg)
    domain = domain_rad or (FULL_TURN_RAD,) * len(table.joint_names)
    kinds = []  # (lo, hi, full turn or not, count) of each joint; counted before any is made
    for (lo, hi), moving in zip(domain, moving_joints(table), strict=True):
        if not moving:
            kinds.append((lo, hi, False, 1))
        elif hi - lo >= 2.0 * math.pi * (1.0 - 1e-12):
            kinds.append((lo, hi, True, turn_grid_count(step)))
        else:
            count = max(2, math.ceil((hi - lo) * DEG_PER_RAD / step - 1e-9) + 1)
            kinds.append((lo, hi, False, count))
    _check_count(math.prod(k[3] for k in kinds), step, sum(moving_joints(table)))
    axes = []
    for lo, hi, full, count in kinds:
        if full:
            axes.append(lo + full_turn_grid_deg(step)[:, 0] / DEG_PER_RAD)
        else:
            axes.append(np.array([lo]) if count == 1 else np.linspace(lo, hi, count))
    return tuple(axes)


@dataclass(frozen=True)
class Sensitivities:
    """``C`` of a table's angular errors on a grid, and its mean magnitude (Figure 8).

    Attributes:
        error_names: the angular errors (columns).  joint_names: the joints of the grid.
        axes_rad: one grid per joint (chain order), radians; the positions are every combination.
        matrices: (N, 3, P) ``d(dpsi, dtheta, dgamma)/d(error)`` at each position (rad/rad).
        values: (3, P) mean of ``|C|`` over the grid; rows dpsi, dtheta, dgamma.
        grid_step_deg: the grid step (None: grids given by the caller).
        error_values: the error set the exact chain was differentiated at (None: zero errors,
            the first-order model), in the table's parameter order.
    """

    error_names: tuple[str, ...]
    joint_names: tuple[str, ...]
    axes_rad: tuple[np.ndarray, ...] = field(repr=False)
    matrices: np.ndarray = field(repr=False)
    values: np.ndarray
    grid_step_deg: float | None = None
    error_values: np.ndarray | None = None

    @property
    def phi1_grid_deg(self) -> np.ndarray:
        """The first joint's grid, degrees (the paper's phi1)."""
        return self.axes_rad[0] * DEG_PER_RAD

    @property
    def phi2_grid_deg(self) -> np.ndarray:
        """The last joint's grid, degrees (the paper's phi2)."""
        return self.axes_rad[-1] * DEG_PER_RAD

    @property
    def max_phi1_variation(self) -> float:
        """Largest change of ``C`` along the first joint on the grid (the paper's phi1, which
        drops out: 0 up to rounding)."""
        shaped = self.matrices.reshape(self.axes_rad[0].size, -1)
        return float(np.max(np.abs(shaped - shaped[:1])))

    def value(self, angle: str, error: str) -> float:
        """Average sensitivity of ``angle`` (dpsi/dtheta/dgamma) to ``error``."""
        return float(self.values[ANGLE_NAMES.index(angle), self.error_names.index(error)])

    def by_angle(self, angle_keys=ANGLE_NAMES) -> dict:
        """``{angle: {error: mean |C|}}`` with the rows keyed by ``angle_keys``."""
        return {
            key: dict(zip(self.error_names, map(float, self.values[k]), strict=True))
            for k, key in enumerate(angle_keys)
        }

    def to_dict(self) -> dict:
        """Grids (degrees), error set and sensitivities by angle and error name, JSON-ready."""
        return {
            "averaging": "mean of |d angle / d error| over every combination of the joint grids",
            "grid_deg": {
                j: (a * DEG_PER_RAD).tolist()
                for j, a in zip(self.joint_names, self.axes_rad, strict=True)
            },
            "grid_step_deg": self.grid_step_deg,
            "error_values": None if self.error_values is None else self.error_values.tolist(),
            "max_phi1_variation": self.max_phi1_variation,
            "sensitivities": self.by_angle(),
        }


def sensitivities(
    table, axes_rad=None, *, grid_step_deg: float | None = None, error_values=None
) -> Sensitivities:
    """The mean of ``|C|`` of ``table``'s angular errors over every combination of ``axes_rad``
    (one grid per joint, radians; default :func:`grid_axes_rad` at ``grid_step_deg``), at zero
    errors or of the exact chain at ``error_values`` (the table's parameter order)."""
    step = None
    if axes_rad is None:
        step = _step(table, grid_step_deg)
        axes_rad = grid_axes_rad(table, step)
    axes = tuple(np.atleast_1d(np.asarray(a, dtype=float)) for a in axes_rad)
    columns = [table.parameter_names.index(n) for n in table.angular_names]
    matrices = table.regressor(list(every_combination(axes).T), error_values)[:, :, columns]
    return Sensitivities(
        error_names=tuple(table.angular_names),
        joint_names=tuple(table.joint_names),
        axes_rad=axes,
        matrices=matrices,
        values=np.abs(matrices).mean(axis=0),
        grid_step_deg=step,
        error_values=None if error_values is None else np.asarray(error_values, dtype=float),
    )


def average_sensitivities(
    error_values=None, phi1_grid_deg=None, phi2_grid_deg=None, *, table=None
) -> Sensitivities:
    """:func:`sensitivities` of the paper's table (or ``table``, two joints) over every (phi1,
    phi2) pair of the grids, in degrees (default 4 phi1 and 360 phi2 values per turn), at
    ``error_values`` (the table's order, rad and m; default none)."""
    phi1 = full_turn_grid_deg(90.0)[:, 0] if phi1_grid_deg is None else phi1_grid_deg
    phi2 = full_turn_grid_deg(1.0)[:, 0] if phi2_grid_deg is None else phi2_grid_deg
    angles = (np.asarray(phi1, float) / DEG_PER_RAD, np.asarray(phi2, float) / DEG_PER_RAD)
    return sensitivities(resolve_table(table), angles, error_values=error_values)


def sensitivity_matrix(error_values, phi1_rad: float, phi2_rad: float, table=None) -> np.ndarray:
    """``C`` (3, 8) of the paper's table (or ``table``, two joints) at (phi1, phi2) and
    ``error_values`` (the table's order, rad and m), exact (the table's regressor)."""
    table = resolve_table(table)
    columns = [table.parameter_names.index(n) for n in table.angular_names]
    angles = (np.array([phi1_rad], float), np.array([phi2_rad], float))
    return table.regressor(angles, np.asarray(error_values, float))[0][:, columns]

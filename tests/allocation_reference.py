"""Independent constructions the allocation layer is checked against.

- The paper's eq. 26 per angle (:class:`LinearAngleModel`, read off ``small_angle_matrix``), posed
  as one angle's rows over a phi2 interval for the library's solver (:func:`solve_subproblem`,
  :func:`worst_case_full_circle`), and Lemma 1's closed form (:func:`lemma1_closed_form`).
- SLSQP on the exact semi-infinite constraint of eq. 26 (:func:`_slsqp`: Danskin gradient).
- ``C`` of the exact chain by Pinocchio's kinematic regressor (:func:`pinocchio_sensitivity_matrix`)
  and by central differences (:func:`sensitivity_matrix_fd`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from turntable_pin.allocation import solver
from turntable_pin.model.angles import ANGLE_ENTRIES
from turntable_pin.model.chain import ROTATION
from turntable_pin.model.errors import ANGULAR_ERROR_NAMES
from turntable_pin.model.small_angle import small_angle_matrix

ORIENTATION_ANGLES = ("psi", "theta", "gamma")


@dataclass(frozen=True)
class LinearAngleModel:
    """``f(phi2, chi) = const.chi + cos(phi2) cos_coef.chi + sin(phi2) sin_coef.chi`` (eq. 26)."""

    angle: str
    const: np.ndarray
    cos_coef: np.ndarray
    sin_coef: np.ndarray

    @property
    def members(self) -> np.ndarray:
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

    def rows(self, interval_rad) -> solver.AngleRows:
        """This angle's rows over ``interval_rad`` of phi2, for the library's solver."""
        idx = self.members
        lo, hi = interval_rad
        coefficients = np.stack([self.const, self.cos_coef, self.sin_coef])[:, idx]
        full = hi - lo >= 2 * math.pi * (1 - 1e-12)
        axis = lo + np.arange(0, 2 * math.pi - 1e-9, math.radians(1)) if full else np.linspace(
            lo, hi, int(round(math.degrees(hi - lo))) + 1)  # fmt: skip
        return solver.AngleRows(
            self.angle,
            tuple(ANGULAR_ERROR_NAMES[i] for i in idx),
            coefficients,
            ((lo, hi),),
            (axis,),
            ("phi2",),
            ("phi2",),
            (0,),
        )


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


def solve_subproblem(model: LinearAngleModel, limit_rad, weights, lower_bounds_rad, interval_rad):
    """The library's solver on eq. 26's rows of ``model`` over a phi2 interval (weights and
    lower bounds of all eight errors)."""
    idx = model.members
    return solver.solve_subproblem(
        model.rows(interval_rad),
        limit_rad,
        np.asarray(weights, dtype=float)[idx],
        np.asarray(lower_bounds_rad, dtype=float)[idx],
    )


def worst_case_full_circle(model: LinearAngleModel, bounds_rad) -> float:
    """The library's domain maximum of eq. 26's ``sum |g_i| bounds_i`` over every phi2."""
    rows = model.rows((0.0, 2 * math.pi))
    return solver.domain_max(rows, np.abs(np.asarray(bounds_rad, dtype=float))[model.members])[0]


def lemma1_closed_form(model: LinearAngleModel, bounds_rad) -> float:
    """Lemma 1 when no error has both a cos and a sin term: ``sum|A| x + hypot(sum|B| x,
    sum|C| x)``."""
    x = np.abs(np.asarray(bounds_rad, dtype=float))
    a, b, c = (np.where(np.abs(v) > 1e-12, np.abs(v), 0.0) for v in
               (model.const, model.cos_coef, model.sin_coef))  # fmt: skip
    assert not np.any((b > 0.0) & (c > 0.0))
    return float(a @ x + math.hypot(b @ x, c @ x))


def _slsqp(constraint, basis, w, lower_z):
    """SLSQP on the exact semi-infinite constraint (Danskin gradient), in units of the limit."""
    ones_value, _ = constraint(np.ones(lower_z.size))
    at_lower, _ = constraint(lower_z)
    start = lower_z + (1.0 - at_lower) / (2.0 * ones_value)
    return solver.minimize_weighted(
        w,
        start,
        lower_z,
        lambda z: 1.0 - constraint(z)[0],
        lambda z: -basis(constraint(z)[1]),
    )


# ---- C of the exact chain, two more ways --------------------------------------------------------
def _factor_twist(table, error_values, name: str) -> tuple[str, np.ndarray]:
    """Link holding error ``name`` and the link placement's right-trivialised variation per unit:
    ``tail^-1 xi tail`` with ``tail`` the factors after it and ``xi`` the factor's unit twist."""
    chain = table.chain
    link, index = next(
        (link, i) for link in chain.links for i, f in enumerate(link.factors) if f.error == name
    )
    factor = link.factors[index]
    values = np.array(error_values, dtype=float)
    for earlier in link.factors[: index + 1]:
        values[chain.error_names.index(earlier.error)] = 0.0  # identity factors leave the tail
    tail = chain.error_transforms(values)[link.name]
    tail_se3 = pin.SE3(np.array(tail[:3, :3]), np.array(tail[:3, 3]))
    unit = factor.unit
    twist = (
        pin.Motion(np.zeros(3), unit) if factor.kind == ROTATION else pin.Motion(unit, np.zeros(3))
    )
    return link.name, tail_se3.actInv(twist).vector


def pinocchio_sensitivity_matrix(table, error_values, phi1_rad: float, phi2_rad: float):
    """``C`` (3, 8) of the exact chain of the paper's ``table`` at ``error_values`` from
    Pinocchio's ``computeFrameKinematicRegressor`` (a fixed link's factors are carried to the
    payload frame by the placement between the two)."""
    pin_model = table.pinocchio_model(error_values)
    data = pin_model.createData()
    q = table.chain.joint_vector(phi1_rad, phi2_rad)
    pin.forwardKinematics(pin_model, data, q)
    pin.updateFramePlacements(pin_model, data)
    frame_id = pin_model.getFrameId(table.payload_frame)
    regressor = pin.computeFrameKinematicRegressor(pin_model, data, frame_id, pin.LOCAL)
    ideal = table.payload_pose(None, (phi1_rad, phi2_rad))
    dR = ideal.rotation.T @ data.oMf[frame_id].rotation
    payload = pin_model.frames[frame_id].placement
    out = np.empty((3, len(ANGULAR_ERROR_NAMES)))
    for col, name in enumerate(ANGULAR_ERROR_NAMES):
        link, twist = _factor_twist(table, error_values, name)
        if table.chain.link(link).is_joint:
            block = pin_model.getJointId(link) - 1
            omega = (regressor[:, 6 * block : 6 * block + 6] @ twist)[3:]
        else:
            relative = pin_model.frames[pin_model.getFrameId(link)].placement.actInv(payload)
            omega = relative.actInv(pin.Motion(twist)).angular
        d_dR = dR @ pin.skew(omega)  # Rt -> Rt (I + [omega]x de)
        out[:, col] = [d_dR[i, j] for i, j in ANGLE_ENTRIES]
    return out


def sensitivity_matrix_fd(table, error_values, phi1_rad, phi2_rad, step_rad: float = 1e-6):
    """``C`` (3, 8) by central finite differences of the exact chain's orientation error."""
    base = np.asarray(error_values, dtype=float)
    out = np.empty((3, len(ANGULAR_ERROR_NAMES)))
    for col in range(len(ANGULAR_ERROR_NAMES)):
        sides = []
        for sign in (1.0, -1.0):
            values = base.copy()
            values[col] += sign * step_rad
            e = table.orientation_error(values, (phi1_rad, phi2_rad))
            sides.append(np.array([e.dpsi_rad, e.dtheta_rad, e.dgamma_rad]))
        out[:, col] = (sides[0] - sides[1]) / (2.0 * step_rad)
    return out

"""Sensitivities of the orientation error to the eight angular turntable errors (paper eq. 28).

``C[k, i] = d f_k / d chi_i`` for ``f = (dpsi, dtheta, dgamma)`` of the exact Pinocchio model, at a
pair of rotation angles. Two independent ways to get it:

* :func:`sensitivity_matrix` (analytic): Pinocchio's kinematic regressor
  (``computeFrameKinematicRegressor``) gives the payload frame's variation for a variation of each
  joint placement; an error factor sitting inside a placement (a link of the model's
  :class:`~turntable_pin.model.chain.ErrorChain`) is moved to the placement's end by the adjoint
  of the factors after it. A fixed link (the payload mount) is not a Pinocchio joint, so its
  factors are carried to the payload frame by the placement between the two.
* :func:`sensitivity_matrix_fd`: central finite differences of
  :meth:`TurntableModel.orientation_error`.

Because ``C`` depends on the angles, the paper plots averages (Figure 8).
:func:`average_sensitivities` takes the mean of ``|C|`` over every pair of a grid of (phi1, phi2);
by default uniform grids over the full turn (with this error model ``dR`` does not depend on phi1
at all, so the phi1 grid only documents that). For the first-order model the averages are
``2/pi = 0.6366`` for every sin/cos term and 1 for every constant term. The paper's
``0.6476 / 0.5365`` are the mean of ``|cos|`` and ``|sin|`` over a 45-degree grid that counts both
0 and 360 degrees (:func:`paper_style_grid_deg`); its ``0.6481 / 0.5372`` and its small non-zero
off-model values (0.0053, 0.0059, ...) match that grid applied to the exact chain at errors of
about 0.1-0.2 degrees (see the README).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from ..core.units import DEG_PER_RAD
from ..model.angles import ANGLE_ENTRIES, ANGLE_NAMES
from ..model.chain import ROTATION
from ..model.errors import ANGULAR_ERROR_NAMES, TurntableErrors
from ..model.turntable import TurntableModel

__all__ = [
    "ORIENTATION_ANGLE_NAMES",
    "PAPER_FIGURE8_TRIG",
    "AverageSensitivities",
    "average_sensitivities",
    "paper_style_grid_deg",
    "sensitivities_on_grid",
    "sensitivity_matrix",
    "sensitivity_matrix_fd",
    "uniform_grid_deg",
]

ORIENTATION_ANGLE_NAMES = ANGLE_NAMES
"""Alias of :data:`turntable_pin.model.angles.ANGLE_NAMES` (rows of the sensitivities)."""


def _factor_twist(model: TurntableModel, name: str) -> tuple[str, np.ndarray]:
    """Link holding error ``name`` and the link placement's right-trivialised variation per unit.

    The placement is ``nominal F_1 ... F_k(e) ... F_n``; d/de of it is the placement times
    ``tail^-1 xi tail`` with ``tail = F_{k+1} ... F_n`` and ``xi`` the factor's unit twist.
    """
    chain = model.chain
    link, index = chain.locate(name)
    factor = link.factors[index]
    values = model.errors.as_array().copy()
    for earlier in link.factors[: index + 1]:
        values[chain.error_names.index(earlier.error)] = 0.0  # identity factors leave the tail
    tail = chain.error_transforms(values)[link.name]
    tail_se3 = pin.SE3(np.array(tail[:3, :3]), np.array(tail[:3, 3]))
    unit = factor.unit
    if factor.kind == ROTATION:
        twist = pin.Motion(np.zeros(3), unit)
    else:
        twist = pin.Motion(unit, np.zeros(3))
    return link.name, tail_se3.actInv(twist).vector


def sensitivity_matrix(model: TurntableModel, phi1_rad: float, phi2_rad: float) -> np.ndarray:
    """Analytic ``C`` (3, 8): d(dpsi, dtheta, dgamma)/d chi at (phi1, phi2), from Pinocchio.

    Rows dpsi, dtheta, dgamma; columns :data:`ANGULAR_ERROR_NAMES`. Dimensionless (rad/rad).
    Exact derivative of the exact chain at the model's error set (not the small-angle model).
    """
    pin_model, data = model.pin_model, model.pin_data
    q = model.joint_vector(phi1_rad, phi2_rad)
    pin.forwardKinematics(pin_model, data, q)
    pin.updateFramePlacements(pin_model, data)
    frame_id = model.payload_frame_id
    regressor = pin.computeFrameKinematicRegressor(pin_model, data, frame_id, pin.LOCAL)
    actual = data.oMf[frame_id].rotation
    ideal = model.ideal_pose(phi1_rad, phi2_rad).rotation
    dR = ideal.T @ actual
    payload = pin_model.frames[frame_id].placement
    out = np.empty((3, len(ANGULAR_ERROR_NAMES)))
    for col, name in enumerate(ANGULAR_ERROR_NAMES):
        link, twist = _factor_twist(model, name)
        if model.chain.link(link).is_joint:
            block = pin_model.getJointId(link) - 1
            omega = (regressor[:, 6 * block : 6 * block + 6] @ twist)[3:]
        else:
            # Both frames hang on the last joint: the payload relative to the fixed link's frame.
            relative = pin_model.frames[pin_model.getFrameId(link)].placement.actInv(payload)
            omega = relative.actInv(pin.Motion(twist)).angular
        # Rt -> Rt (I + [omega]x de), so d(dR) = dR [omega]x.
        d_dR = dR @ pin.skew(omega)
        out[:, col] = [d_dR[i, j] for i, j in ANGLE_ENTRIES]
    return out


def sensitivity_matrix_fd(
    model: TurntableModel, phi1_rad: float, phi2_rad: float, step_rad: float = 1e-6
) -> np.ndarray:
    """``C`` (3, 8) by central finite differences of the exact model (independent check)."""
    base = model.errors.as_array()
    out = np.empty((3, len(ANGULAR_ERROR_NAMES)))
    for col in range(len(ANGULAR_ERROR_NAMES)):
        sides = []
        for sign in (1.0, -1.0):
            values = base.copy()
            values[col] += sign * step_rad
            e = model.with_errors(TurntableErrors.from_array(values))
            r = e.orientation_error(phi1_rad, phi2_rad)
            sides.append(np.array([r.dpsi_rad, r.dtheta_rad, r.dgamma_rad]))
        out[:, col] = (sides[0] - sides[1]) / (2.0 * step_rad)
    return out


def uniform_grid_deg(n: int) -> np.ndarray:
    """``n`` equally spaced angles over one turn, 0 included and 360 excluded, degrees."""
    return 360.0 * np.arange(n) / n


def paper_style_grid_deg(step_deg: float = 45.0) -> np.ndarray:
    """``0, step, ..., 360`` degrees, both ends counted (reproduces the paper's 0.6476/0.5365)."""
    return np.arange(0.0, 360.0 + 0.5 * step_deg, step_deg)


@dataclass(frozen=True)
class AverageSensitivities:
    """Mean of ``|C|`` over a grid of rotation angles (Figure 8).

    Attributes:
        values: (3, 8) rows dpsi, dtheta, dgamma; columns :data:`ANGULAR_ERROR_NAMES`.
        phi1_grid_deg, phi2_grid_deg: the grids averaged over (every pair), degrees.
        errors: the error set at which the exact model was differentiated.
        max_phi1_variation: largest change of ``C`` along phi1 on the grid (0 up to rounding:
            with this error model the orientation error does not depend on phi1).
    """

    values: np.ndarray
    phi1_grid_deg: np.ndarray
    phi2_grid_deg: np.ndarray
    errors: TurntableErrors = field(default_factory=TurntableErrors)
    max_phi1_variation: float = 0.0

    def value(self, angle: str, error: str) -> float:
        """Average sensitivity of ``angle`` (dpsi/dtheta/dgamma) to ``error``."""
        return float(
            self.values[ORIENTATION_ANGLE_NAMES.index(angle), ANGULAR_ERROR_NAMES.index(error)]
        )

    def to_dict(self) -> dict:
        """Grids (degrees), error set, phi1 variation and sensitivities by name, JSON-ready."""
        return {
            "averaging": "mean of |dC/dchi| over every (phi1, phi2) pair of the grids",
            "phi1_grid_deg": self.phi1_grid_deg.tolist(),
            "phi2_grid_deg": self.phi2_grid_deg.tolist(),
            "errors": self.errors.to_user_units(),
            "max_phi1_variation": self.max_phi1_variation,
            "sensitivities": {
                angle: {
                    name: float(self.values[k, i]) for i, name in enumerate(ANGULAR_ERROR_NAMES)
                }
                for k, angle in enumerate(ORIENTATION_ANGLE_NAMES)
            },
        }


def sensitivities_on_grid(model: TurntableModel, phi1_grid_rad, phi2_grid_rad) -> np.ndarray:
    """Analytic ``C`` at every pair of the grids: shape (n1, n2, 3, 8)."""
    phi1 = np.atleast_1d(np.asarray(phi1_grid_rad, dtype=float))
    phi2 = np.atleast_1d(np.asarray(phi2_grid_rad, dtype=float))
    out = np.empty((phi1.size, phi2.size, 3, len(ANGULAR_ERROR_NAMES)))
    for a, p1 in enumerate(phi1):
        for b, p2 in enumerate(phi2):
            out[a, b] = sensitivity_matrix(model, float(p1), float(p2))
    return out


def average_sensitivities(
    model: TurntableModel | None = None,
    phi1_grid_deg=None,
    phi2_grid_deg=None,
) -> AverageSensitivities:
    """Mean of ``|C|`` over the grids (default: 4 phi1 values and 360 phi2 values per turn).

    Args:
        model: the turntable whose exact chain is differentiated (default: no errors).
        phi1_grid_deg, phi2_grid_deg: grids in degrees (default :func:`uniform_grid_deg`).
    """
    model = model or TurntableModel()
    phi1 = uniform_grid_deg(4) if phi1_grid_deg is None else np.asarray(phi1_grid_deg, float)
    phi2 = uniform_grid_deg(360) if phi2_grid_deg is None else np.asarray(phi2_grid_deg, float)
    grid = sensitivities_on_grid(model, phi1 / DEG_PER_RAD, phi2 / DEG_PER_RAD)
    variation = float(np.max(np.abs(grid - grid[:1]))) if phi1.size > 1 else 0.0
    return AverageSensitivities(
        values=np.abs(grid).mean(axis=(0, 1)),
        phi1_grid_deg=phi1,
        phi2_grid_deg=phi2,
        errors=model.errors,
        max_phi1_variation=variation,
    )


PAPER_FIGURE8_TRIG = 0.6481
"""The paper's Figure 8 value used for every sin/cos term by ``--weights paper``
(see docs/model.md)."""

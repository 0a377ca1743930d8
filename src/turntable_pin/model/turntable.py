"""The two-axis turntable as a Pinocchio model whose joint placements carry the turntable errors.

Where each error of paper Table 3 lives (each placement is the nominal URDF ``<origin>`` followed by
the listed elementary motions, applied in the moving frame):

========================  ===================================================================
placement                 error factors
========================  ===================================================================
joint ``outer_axis``      ``Ry(dphi_y1)``
joint ``inner_axis``      ``Rz(dalpha_z1) Rx(dalpha_x1) Tx(deta) Ry(deps_y) Rx(deps_x)``
fixed ``payload_mount``   ``Ry(dalpha_y2) Rz(dphi_z2) Rx(dalpha_x2)``
========================  ===================================================================

so that ``Rt = Ry(phi1) Ry(dphi_y1) Rz(dalpha_z1) Rx(dalpha_x1) Ry(deps_y) Rx(deps_x) Rz(phi2)
Ry(dalpha_y2) Rz(dphi_z2) Rx(dalpha_x2)``, the chain of Table 3, and the joint values stay the
*commanded* angles phi1, phi2.

Why the position errors are placement rotations and not joint offsets: ``Ry(dphi_y1)`` commutes with
the outer joint's rotation, so it is exact either way; but ``Rz(dphi_z2)`` sits *between* the two
inner-axis wobble rotations in Table 3 and does not commute with ``Ry(dalpha_y2)``, so an offset of
the inner joint value would not reproduce the chain exactly. Keeping every error in a placement also
keeps q equal to the commanded angles, which is what measurement files record, and lets one
mechanism (placements) carry every error, for the URDF writer and for Jacobians alike.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..core.exceptions import InputError, ModelError
from ..core.resources import default_urdf_path
from .angles import ANGLE_ENTRIES
from .chain import ErrorChain, apply_chain_errors, joint_axis
from .errors import ERROR_NAMES, TurntableErrors
from .paper_table import (
    INNER_JOINT,
    OUTER_JOINT,
    PAYLOAD_FRAME,
    PAYLOAD_MOUNT,
    PLACEMENT_ERROR_FACTORS,
    PLACEMENT_ORDER,
)

__all__ = [
    "INNER_JOINT",
    "OUTER_JOINT",
    "PAYLOAD_FRAME",
    "PAYLOAD_MOUNT",
    "PLACEMENT_ERROR_FACTORS",
    "PLACEMENT_ORDER",
    "OrientationError",
    "TurntableModel",
    "error_placements",
    "joint_axis",
    "paper_chain",
]


@lru_cache(maxsize=8)
def _load_nominal(urdf_path: str) -> tuple[pin.Model, ErrorChain]:
    try:
        model = pin.buildModelFromUrdf(urdf_path)
    except (RuntimeError, ValueError) as exc:
        raise ModelError(f"{urdf_path}: Pinocchio cannot read this URDF: {exc}") from None
    _check_structure(model, urdf_path)
    return model, paper_chain(model)


def paper_chain(model: pin.Model) -> ErrorChain:
    """The :class:`ErrorChain` of the paper's table: ``model``'s chain with the Table 3 factors."""
    return ErrorChain.from_pinocchio(model, PAYLOAD_FRAME, PLACEMENT_ERROR_FACTORS, ERROR_NAMES)


def error_placements(error_values: np.ndarray) -> dict[str, np.ndarray]:
    """Homogeneous 4x4 error transforms of each placement, vectorised over error sets.

    Args:
        error_values: shape (..., 9), the errors in :data:`ERROR_NAMES` order (rad, deta in m).

    Returns:
        ``{placement name: array (..., 4, 4)}``: the factors of :data:`PLACEMENT_ERROR_FACTORS`
        multiplied in order (see :meth:`ErrorChain.error_transforms`).
    """
    return _load_nominal(str(default_urdf_path().resolve()))[1].error_transforms(error_values)


def _check_structure(model: pin.Model, source: str) -> None:
    names = list(model.names)
    for joint in (OUTER_JOINT, INNER_JOINT):
        if joint not in names:
            raise ModelError(f"{source}: no joint '{joint}'; joints are {names[1:]}")
    if model.nq != 2:
        raise ModelError(f"{source}: expected 2 degrees of freedom, found {model.nq}")
    frame_names = [f.name for f in model.frames]
    for frame in (PAYLOAD_MOUNT, PAYLOAD_FRAME):
        if frame not in frame_names:
            raise ModelError(f"{source}: no frame '{frame}'; frames are {frame_names}")
    if model.parents[model.getJointId(INNER_JOINT)] != model.getJointId(OUTER_JOINT):
        raise ModelError(f"{source}: '{INNER_JOINT}' must be a child of '{OUTER_JOINT}'")


@dataclass(frozen=True)
class OrientationError:
    """The orientation error of the payload at one position.

    Attributes:
        dR: ``Rd^T Rt`` (eq. 23), 3x3.
        dpsi_rad, dtheta_rad, dgamma_rad: ``dR[0,2]``, ``dR[1,0]``, ``dR[2,1]`` (eq. 24), radians.
        payload_origin_m: payload origin in the base frame, metres (zero for a perfect table).
    """

    dR: np.ndarray
    dpsi_rad: float
    dtheta_rad: float
    dgamma_rad: float
    payload_origin_m: np.ndarray


class TurntableModel:
    """A two-axis turntable: the Pinocchio model of a URDF with an error set in its placements.

    Args:
        errors: the turntable errors (default: none).
        urdf_path: the nominal URDF (default: the bundled ``models/turntable.urdf``).

    Attributes:
        chain: the :class:`ErrorChain` (nominal placements, error factors, joint axes) that every
            layer reads.
        pin_model, pin_data: the Pinocchio model with the errors in its placements, and its data.
        nominal_pin_model: the Pinocchio model of the URDF as given (the ideal table).

    The nominal model gives the ideal orientation ``Rd``; the error model gives the actual
    ``Rt``; both by Pinocchio forward kinematics.
    """

    def __init__(
        self, errors: TurntableErrors | None = None, urdf_path: str | Path | None = None
    ) -> None:
        self.urdf_path = Path(urdf_path) if urdf_path is not None else default_urdf_path()
        if not self.urdf_path.is_file():
            raise InputError("no such URDF file", path=self.urdf_path)
        self.errors = errors if errors is not None else TurntableErrors.zero()
        self.nominal_pin_model, self.chain = _load_nominal(str(self.urdf_path.resolve()))
        self.pin_model = self.nominal_pin_model.copy()
        self._apply_errors()
        self.pin_data = self.pin_model.createData()
        self._nominal_data = self.nominal_pin_model.createData()
        self.payload_frame_id = self.pin_model.getFrameId(PAYLOAD_FRAME)
        self.outer_joint_id = self.pin_model.getJointId(OUTER_JOINT)
        self.inner_joint_id = self.pin_model.getJointId(INNER_JOINT)

    # Names of earlier versions (the README's changelog lists them).
    @property
    def model(self) -> pin.Model:
        """Alias of :attr:`pin_model`."""
        return self.pin_model

    @property
    def data(self) -> pin.Data:
        """Alias of :attr:`pin_data`."""
        return self.pin_data

    @property
    def nominal_model(self) -> pin.Model:
        """Alias of :attr:`nominal_pin_model`."""
        return self.nominal_pin_model

    def with_errors(self, errors: TurntableErrors) -> TurntableModel:
        """The same URDF with another error set."""
        return TurntableModel(errors, self.urdf_path)

    # ---- building ---------------------------------------------------------------------------
    def _apply_errors(self) -> None:
        apply_chain_errors(
            self.chain, self.nominal_pin_model, self.pin_model, self.errors.as_array()
        )

    def placement_chain(
        self, model: pin.Model | None = None
    ) -> list[tuple[np.ndarray, np.ndarray]]:
        """The kinematic chain from the base to the payload frame as read off ``model``.

        Returns ``[(placement 4x4, joint axis or None), ...]``: for each joint from the root its
        placement and axis, then the payload frame's placement (axis ``None``), as Pinocchio
        holds them (default: :attr:`pin_model`, the model with errors).
        """
        model = self.pin_model if model is None else model
        frame = model.frames[model.getFrameId(PAYLOAD_FRAME)]
        chain = [
            (model.jointPlacements[model.getJointId(link.name)].homogeneous, link.axis)
            for link in self.chain.joints
        ]
        chain.append((frame.placement.homogeneous, None))
        return chain

    # ---- evaluation --------------------------------------------------------------------------
    def joint_vector(self, phi1_rad: float, phi2_rad: float) -> np.ndarray:
        """Pinocchio's configuration vector for commanded angles (phi1, phi2), radians."""
        return self.chain.joint_vector(phi1_rad, phi2_rad)

    def payload_pose(self, phi1_rad: float, phi2_rad: float) -> pin.SE3:
        """Actual payload pose in the base frame (Pinocchio forward kinematics)."""
        q = self.joint_vector(phi1_rad, phi2_rad)
        pin.framesForwardKinematics(self.pin_model, self.pin_data, q)
        return self.pin_data.oMf[self.payload_frame_id].copy()

    def ideal_pose(self, phi1_rad: float, phi2_rad: float) -> pin.SE3:
        """Ideal payload pose in the base frame, from the nominal (error-free) model."""
        q = self.joint_vector(phi1_rad, phi2_rad)
        pin.framesForwardKinematics(self.nominal_pin_model, self._nominal_data, q)
        return self._nominal_data.oMf[self.payload_frame_id].copy()

    def orientation_error(self, phi1_rad: float, phi2_rad: float) -> OrientationError:
        """``dR = Rd^T Rt`` and the three error angles at commanded angles (phi1, phi2), radians."""
        for value in (phi1_rad, phi2_rad):
            if not np.isfinite(value):
                raise InputError(f"rotation angles must be finite numbers, got {value!r}")
        actual = self.payload_pose(phi1_rad, phi2_rad)
        ideal = self.ideal_pose(phi1_rad, phi2_rad)
        dR = ideal.rotation.T @ actual.rotation
        dpsi, dtheta, dgamma = (float(dR[i, j]) for i, j in ANGLE_ENTRIES)
        return OrientationError(
            dR=dR,
            dpsi_rad=dpsi,
            dtheta_rad=dtheta,
            dgamma_rad=dgamma,
            payload_origin_m=np.array(actual.translation),
        )

    # ---- export ------------------------------------------------------------------------------
    def write_urdf(self, path: str | Path) -> Path:
        """Write a URDF whose joint ``<origin>``s carry this model's errors (via yourdfpy)."""
        from .urdf_io import write_error_urdf

        return write_error_urdf(self.urdf_path, self.chain, self.errors.as_array(), path)

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
from ..core.rotations import AXIS_INDEX, axis_rotation
from .errors import ERROR_NAMES, TurntableErrors

OUTER_JOINT = "outer_axis"
INNER_JOINT = "inner_axis"
PAYLOAD_MOUNT = "payload_mount"
PAYLOAD_FRAME = "gyrowheel"

# (kind, axis, error name) factors of each placement, in the order they are applied.
PLACEMENT_ERROR_FACTORS: dict[str, tuple[tuple[str, str, str], ...]] = {
    OUTER_JOINT: (("rot", "y", "dphi_y1"),),
    INNER_JOINT: (
        ("rot", "z", "dalpha_z1"),
        ("rot", "x", "dalpha_x1"),
        ("trans", "x", "deta"),
        ("rot", "y", "deps_y"),
        ("rot", "x", "deps_x"),
    ),
    PAYLOAD_MOUNT: (
        ("rot", "y", "dalpha_y2"),
        ("rot", "z", "dphi_z2"),
        ("rot", "x", "dalpha_x2"),
    ),
}
PLACEMENT_ORDER: tuple[str, ...] = (OUTER_JOINT, INNER_JOINT, PAYLOAD_MOUNT)


def error_placements(error_values: np.ndarray) -> dict[str, np.ndarray]:
    """Homogeneous 4x4 error transforms of each placement, vectorised over error sets.

    Args:
        error_values: shape (..., 9), the errors in :data:`ERROR_NAMES` order (rad, deta in m).

    Returns:
        ``{placement name: array (..., 4, 4)}``: the factors of :data:`PLACEMENT_ERROR_FACTORS`
        multiplied in order. The nominal placement is to be applied before them.
    """
    values = np.asarray(error_values, dtype=float)
    if values.shape[-1] != len(ERROR_NAMES):
        raise ValueError(f"expected {len(ERROR_NAMES)} error values, got shape {values.shape}")
    lead = values.shape[:-1]
    out = {}
    for placement, factors in PLACEMENT_ERROR_FACTORS.items():
        total = np.broadcast_to(np.eye(4), lead + (4, 4)).copy()
        for kind, axis, name in factors:
            value = values[..., ERROR_NAMES.index(name)]
            step = np.broadcast_to(np.eye(4), lead + (4, 4)).copy()
            if kind == "rot":
                step[..., :3, :3] = axis_rotation(axis, value)
            else:
                step[..., AXIS_INDEX[axis], 3] = value
            total = total @ step
        out[placement] = total
    return out


def _se3(homogeneous: np.ndarray) -> pin.SE3:
    return pin.SE3(np.array(homogeneous[:3, :3]), np.array(homogeneous[:3, 3]))


@lru_cache(maxsize=8)
def _load_nominal(urdf_path: str) -> pin.Model:
    try:
        model = pin.buildModelFromUrdf(urdf_path)
    except (RuntimeError, ValueError) as exc:
        raise ModelError(f"{urdf_path}: Pinocchio cannot read this URDF: {exc}") from None
    _check_structure(model, urdf_path)
    return model


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


def joint_axis(model: pin.Model, joint_id: int) -> np.ndarray:
    """Unit rotation axis of a revolute joint of ``model``, in the joint frame."""
    joint = model.joints[joint_id]
    short = joint.shortname()
    if short in ("JointModelRX", "JointModelRY", "JointModelRZ"):
        axis = np.zeros(3)
        axis[AXIS_INDEX[short[-1].lower()]] = 1.0
        return axis
    if short == "JointModelRevoluteUnaligned":
        return np.array(joint.extract().axis, dtype=float)
    raise ModelError(f"joint '{model.names[joint_id]}' is {short}, not a revolute joint")


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

    The nominal model (errors of the URDF as given) gives the ideal orientation ``Rd``; the
    error model gives the actual ``Rt``; both by Pinocchio forward kinematics.
    """

    def __init__(
        self, errors: TurntableErrors | None = None, urdf_path: str | Path | None = None
    ) -> None:
        self.urdf_path = Path(urdf_path) if urdf_path is not None else default_urdf_path()
        if not self.urdf_path.is_file():
            raise InputError("no such URDF file", path=self.urdf_path)
        self.errors = errors if errors is not None else TurntableErrors.zero()
        self.nominal_model = _load_nominal(str(self.urdf_path.resolve()))
        self.model = self.nominal_model.copy()
        self._apply_errors()
        self.data = self.model.createData()
        self._nominal_data = self.nominal_model.createData()
        self.payload_frame_id = self.model.getFrameId(PAYLOAD_FRAME)
        self.outer_joint_id = self.model.getJointId(OUTER_JOINT)
        self.inner_joint_id = self.model.getJointId(INNER_JOINT)
        self._q_index = (
            self.model.joints[self.outer_joint_id].idx_q,
            self.model.joints[self.inner_joint_id].idx_q,
        )

    def with_errors(self, errors: TurntableErrors) -> TurntableModel:
        """The same URDF with another error set."""
        return TurntableModel(errors, self.urdf_path)

    # ---- building ---------------------------------------------------------------------------
    def _apply_errors(self) -> None:
        transforms = error_placements(self.errors.as_array())
        for name in (OUTER_JOINT, INNER_JOINT):
            jid = self.model.getJointId(name)
            nominal = self.nominal_model.jointPlacements[jid]
            self.model.jointPlacements[jid] = nominal * _se3(transforms[name])
        mount = self.model.getFrameId(PAYLOAD_MOUNT)
        nominal_mount = self.nominal_model.frames[mount].placement
        actual_mount = nominal_mount * _se3(transforms[PAYLOAD_MOUNT])
        # Pinocchio folds the fixed joint into frames: the joint frame and the child body frame.
        for frame_name in (PAYLOAD_MOUNT, PAYLOAD_FRAME):
            fid = self.model.getFrameId(frame_name)
            relative = nominal_mount.actInv(self.nominal_model.frames[fid].placement)
            self.model.frames[fid].placement = actual_mount * relative

    def placement_chain(
        self, model: pin.Model | None = None
    ) -> list[tuple[np.ndarray, np.ndarray]]:
        """The kinematic chain from the base to the payload frame as read off ``model``.

        Returns ``[(placement 4x4, joint axis or None), ...]``: for each joint from the root its
        placement and axis, then the payload frame's placement (axis ``None``). Batch evaluation
        composes this list; it is the Pinocchio model's own data, not a second copy of the chain.
        """
        model = self.model if model is None else model
        frame = model.frames[model.getFrameId(PAYLOAD_FRAME)]
        joints = []
        jid = frame.parentJoint
        while jid > 0:
            joints.append(jid)
            jid = model.parents[jid]
        chain = [(model.jointPlacements[j].homogeneous, joint_axis(model, j)) for j in joints[::-1]]
        chain.append((frame.placement.homogeneous, None))
        return chain

    # ---- evaluation --------------------------------------------------------------------------
    def _q(self, phi1_rad: float, phi2_rad: float) -> np.ndarray:
        q = np.zeros(self.model.nq)
        q[self._q_index[0]] = phi1_rad
        q[self._q_index[1]] = phi2_rad
        return q

    def payload_pose(self, phi1_rad: float, phi2_rad: float) -> pin.SE3:
        """Actual payload pose in the base frame (Pinocchio forward kinematics)."""
        pin.framesForwardKinematics(self.model, self.data, self._q(phi1_rad, phi2_rad))
        return self.data.oMf[self.payload_frame_id].copy()

    def ideal_pose(self, phi1_rad: float, phi2_rad: float) -> pin.SE3:
        """Ideal payload pose in the base frame, from the nominal (error-free) model."""
        q = self._q(phi1_rad, phi2_rad)
        pin.framesForwardKinematics(self.nominal_model, self._nominal_data, q)
        return self._nominal_data.oMf[self.payload_frame_id].copy()

    def orientation_error(self, phi1_rad: float, phi2_rad: float) -> OrientationError:
        """``dR = Rd^T Rt`` and the three error angles at commanded angles (phi1, phi2), radians."""
        for value in (phi1_rad, phi2_rad):
            if not np.isfinite(value):
                raise InputError(f"rotation angles must be finite numbers, got {value!r}")
        actual = self.payload_pose(phi1_rad, phi2_rad)
        ideal = self.ideal_pose(phi1_rad, phi2_rad)
        dR = ideal.rotation.T @ actual.rotation
        return OrientationError(
            dR=dR,
            dpsi_rad=float(dR[0, 2]),
            dtheta_rad=float(dR[1, 0]),
            dgamma_rad=float(dR[2, 1]),
            payload_origin_m=np.array(actual.translation),
        )

    # ---- export ------------------------------------------------------------------------------
    def write_urdf(self, path: str | Path) -> Path:
        """Write a URDF whose joint ``<origin>``s carry this model's errors (via yourdfpy)."""
        from .urdf_io import write_error_urdf

        return write_error_urdf(self, path)

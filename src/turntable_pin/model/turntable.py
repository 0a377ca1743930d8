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

from pathlib import Path

import numpy as np

from .chain import joint_axis
from .errors import TurntableErrors
from .generic_table import OrientationError
from .paper_table import (
    INNER_JOINT,
    OUTER_JOINT,
    PAYLOAD_FRAME,
    PAYLOAD_MOUNT,
    PLACEMENT_ERROR_FACTORS,
    PLACEMENT_ORDER,
    paper_table,
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
]


def error_placements(error_values: np.ndarray) -> dict[str, np.ndarray]:
    """Homogeneous 4x4 error transforms of each placement of the bundled table, vectorised over
    error sets (``error_values`` (..., 9) in ``ERROR_NAMES`` order; see
    :meth:`~turntable_pin.model.chain.ErrorChain.error_transforms`)."""
    return paper_table().chain.error_transforms(error_values)


class TurntableModel:
    """The paper's table with an error set: a façade over the one table class.

    It holds :func:`~turntable_pin.model.paper_table.paper_table` (a
    :class:`~turntable_pin.model.generic_table.GenericTable` under the paper's layout) and a
    :class:`TurntableErrors`, and answers in the paper's angles (phi1, phi2); every computation
    is the table's. Scripts of earlier versions keep working with it.

    Args:
        errors: the turntable errors (default: none).
        urdf_path: a URDF with the paper's joints and payload frame (default: the bundled
            ``models/turntable.urdf``).

    Attributes:
        table: the generic table; chain: its :class:`ErrorChain`.
        pin_model, pin_data: the Pinocchio model with the errors in its placements, and its data
            (also ``model``, ``data``).
        nominal_pin_model: the Pinocchio model of the URDF as given (also ``nominal_model``).
    """

    def __init__(
        self, errors: TurntableErrors | None = None, urdf_path: str | Path | None = None
    ) -> None:
        self.table = paper_table(urdf_path)
        self.urdf_path = self.table.urdf_path if urdf_path is None else Path(urdf_path)
        self.errors = errors if errors is not None else TurntableErrors.zero()
        self.chain = self.table.chain
        self.nominal_pin_model = self.nominal_model = self.table.nominal_pin_model
        self.pin_model = self.model = self.table.pinocchio_model(self.errors.as_array())
        self.pin_data = self.data = self.pin_model.createData()
        self.payload_frame_id = self.pin_model.getFrameId(PAYLOAD_FRAME)
        self.outer_joint_id = self.pin_model.getJointId(OUTER_JOINT)
        self.inner_joint_id = self.pin_model.getJointId(INNER_JOINT)

    def with_errors(self, errors: TurntableErrors) -> TurntableModel:
        """The same URDF with another error set."""
        return TurntableModel(errors, self.urdf_path)

    def joint_vector(self, phi1_rad: float, phi2_rad: float) -> np.ndarray:
        """Pinocchio's configuration vector for commanded angles (phi1, phi2), radians."""
        return self.chain.joint_vector(phi1_rad, phi2_rad)

    def payload_pose(self, phi1_rad: float, phi2_rad: float):
        """Actual payload pose in the base frame (Pinocchio forward kinematics)."""
        return self.table.payload_pose(self.errors.as_array(), (phi1_rad, phi2_rad))

    def ideal_pose(self, phi1_rad: float, phi2_rad: float):
        """Ideal payload pose in the base frame, from the nominal (error-free) model."""
        return self.table.payload_pose(None, (phi1_rad, phi2_rad))

    def orientation_error(self, phi1_rad: float, phi2_rad: float) -> OrientationError:
        """``dR = Rd^T Rt`` and the three error angles at commanded angles (phi1, phi2), radians."""
        return self.table.orientation_error(self.errors.as_array(), (phi1_rad, phi2_rad))

    def placement_chain(self, model=None) -> list[tuple[np.ndarray, np.ndarray]]:
        """``[(placement 4x4, joint axis or None), ...]`` from the base to the payload frame as
        read off ``model`` (default: :attr:`pin_model`, the model with errors)."""
        model = self.pin_model if model is None else model
        chain = [
            (model.jointPlacements[model.getJointId(link.name)].homogeneous, link.axis)
            for link in self.chain.joints
        ]
        frame = model.frames[model.getFrameId(PAYLOAD_FRAME)]
        return [*chain, (frame.placement.homogeneous, None)]

    def write_urdf(self, path: str | Path) -> Path:
        """Write a URDF whose joint ``<origin>``s carry this model's errors (via yourdfpy)."""
        return self.table.write_urdf(self.errors.as_array(), path)

"""Test positions of any table (1 to 3 joints, from its URDF) for the GyroWheel calibration layer.

A position is a tuple of commanded joint angles in chain order from the base (the order of
:attr:`~turntable_pin.model.generic_table.GenericTable.joint_names`). A position set comes from:

- ``grid:STEP``: every joint in {0, STEP, ..., < 360} degrees, every combination (a full grid:
  12 positions for one joint at 30 degrees, 144 for two, 1728 for three);
- ``grid:S1xS2[xS3]``: the same with one step per joint, in chain order (as many steps as joints);
- a CSV file with one angle column per joint: ``phi1_deg .. phiN_deg`` (chain order) or
  ``<joint>_deg`` (the joint names); other columns are ignored.

The specific force and the earth rate along the payload axes are ``Rd^T`` times their base-frame
values (as for the paper's table, :func:`~turntable_pin.calibration.positions.position_inputs`),
with ``Rd`` the nominal payload orientation composed from the table's :class:`ErrorChain` (the
placements Pinocchio reads from the URDF).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..core.csv_table import CsvTable, read_csv_table
from ..core.exceptions import InputError
from ..core.sizes import MAX_POSITIONS, check_count
from ..core.units import deg_to_rad, rad_to_deg
from ..model.chain import compose_rotation
from .positions import (
    MAX_COMMANDED_ANGLE_DEG,
    POSITION_BYTES,
    angle_columns,
    check_commanded_angles,
    grid_angles_deg,
    grid_steps,
)

__all__ = ["JointPositions"]


@dataclass(frozen=True)
class JointPositions:
    """Commanded positions of a table with 1 to 3 joints.

    Attributes:
        angles_rad: (N, J) joint angles in chain order, radians.
        table: the :class:`~turntable_pin.model.generic_table.GenericTable` they command.
        name: the scheme name or file the positions came from.
    """

    angles_rad: np.ndarray
    table: object = field(repr=False, compare=False)
    name: str = ""

    def __post_init__(self) -> None:
        n_joints = len(self.table.joint_names)
        angles = np.array(self.angles_rad, dtype=float)
        if angles.ndim == 1 and n_joints == 1:
            angles = angles[:, None]
        if angles.ndim != 2 or angles.shape[1] != n_joints:
            raise InputError(
                f"positions: expected {n_joints} angle(s) per position "
                f"({', '.join(self.table.joint_names)}), got shape {angles.shape}"
            )
        if angles.shape[0] == 0:
            raise InputError("positions: the set is empty")
        check_count(angles.shape[0], MAX_POSITIONS, "positions", POSITION_BYTES)
        if not np.all(np.isfinite(angles)):
            raise InputError("positions: angles must be finite numbers")
        largest = float(np.max(np.abs(angles)))
        if largest > deg_to_rad(MAX_COMMANDED_ANGLE_DEG):
            raise InputError(
                f"positions: an angle of {rad_to_deg(largest):g} deg; commanded angles must be "
                f"within +-{MAX_COMMANDED_ANGLE_DEG:g} deg"
            )
        angles.setflags(write=False)
        object.__setattr__(self, "angles_rad", angles)

    def __len__(self) -> int:
        return int(self.angles_rad.shape[0])

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The joints, in the order of the columns of :attr:`angles_rad`."""
        return tuple(self.table.joint_names)

    @property
    def column_names(self) -> tuple[str, ...]:
        """``<joint>_deg`` per joint: the keys of the angles in reports."""
        return tuple(f"{j}_deg" for j in self.joint_names)

    # ---- construction -------------------------------------------------------------------------
    @classmethod
    def grid(cls, table, *steps_deg: float) -> JointPositions:
        """Every joint in {0, step, ..., < 360} degrees, every combination (one step for all
        joints, or one per joint in chain order)."""
        n_joints = len(table.joint_names)
        if len(steps_deg) not in (1, n_joints):
            raise InputError(
                f"grid: {len(steps_deg)} steps for a table of {n_joints} joint(s) "
                f"({', '.join(table.joint_names)}); give one step, or one per joint"
            )
        steps = list(steps_deg) * n_joints if len(steps_deg) == 1 else list(steps_deg)
        angles, name = grid_angles_deg(steps)
        return cls(deg_to_rad(angles), table, name)

    @classmethod
    def from_table(cls, table, csv: CsvTable, columns: tuple[str, ...], name: str):
        """The positions of the angle ``columns`` (degrees) of a read :class:`CsvTable`."""
        check_commanded_angles(csv, columns)
        angles = np.stack([csv[c] for c in columns], axis=1)
        return cls(deg_to_rad(angles), table, name)

    @classmethod
    def from_csv(cls, table, path: str | Path) -> JointPositions:
        """Read the angle columns (``phi1_deg .. phiN_deg`` or ``<joint>_deg``) of a CSV file."""
        csv = read_csv_table(path, (), cls.candidate_columns(table))
        columns = cls.columns_of(table, csv)
        return cls.from_table(table, csv, columns, str(path))

    @staticmethod
    def candidate_columns(table) -> tuple[str, ...]:
        """Every column name an angle may have for ``table`` (numbered, then by joint name)."""
        n = len(table.joint_names)
        names = [f"phi{i + 1}_deg" for i in range(n)] + [f"{j}_deg" for j in table.joint_names]
        return tuple(dict.fromkeys(names))

    @staticmethod
    def columns_of(table, csv: CsvTable) -> tuple[str, ...]:
        """The angle columns present in ``csv`` for ``table``, or :class:`InputError`."""
        return angle_columns(csv.header, table.joint_names, csv.path, csv.header_row)

    @classmethod
    def parse(cls, table, spec: str) -> JointPositions:
        """A scheme name (``grid:STEP``, ``grid:S1xS2[xS3]``) or the path of a CSV file."""
        text = str(spec).strip()
        steps = grid_steps(text)
        if steps is not None:
            return cls.grid(table, *steps)
        path = Path(text)
        if not path.exists():
            raise InputError(
                f"positions '{text}': neither a scheme (grid:STEP) nor an existing CSV file"
            )
        return cls.from_csv(table, path)

    # ---- what the payload sees ----------------------------------------------------------------
    def nominal_rotations(self) -> np.ndarray:
        """(N, 3, 3) nominal payload orientations ``Rd`` (base <- payload) from the chain."""
        chain = self.table.chain
        return compose_rotation(chain.placements(), list(self.angles_rad.T))

    def distinct_count(self, decimals: int = 9) -> int:
        """Number of distinct commanded positions (angles taken modulo 360 degrees)."""
        wrapped = np.round(np.mod(rad_to_deg(self.angles_rad), 360.0), decimals) % 360.0
        return int(np.unique(wrapped, axis=0).shape[0])

    def to_dict(self) -> dict:
        """Name, count, joint names and the angles in degrees per joint, as a dict."""
        out = {"name": self.name, "n_positions": len(self), "joints": list(self.joint_names)}
        for column, values in zip(self.column_names, rad_to_deg(self.angles_rad).T, strict=True):
            out[column] = values
        return out

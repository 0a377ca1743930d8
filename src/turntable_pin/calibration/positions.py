"""Test positions of a multi-position calibration and the inputs the GyroWheel senses at each.

A position is a pair of commanded turntable angles (phi1 about the outer axis y, phi2 about the
inner axis z). A position set comes from a scheme name or a CSV file:

- ``grid:STEP``: phi1 and phi2 each in {0, STEP, ..., < 360} degrees, all pairs;
- ``grid:STEP1xSTEP2``: the same with separate steps for phi1 and phi2;
- a CSV file with columns ``phi1_deg, phi2_deg``.

The specific force and the earth rate along the payload axes come from the payload orientation
``Rd`` of the Pinocchio model (:class:`TurntableModel`): in the base frame F0 (x north, y west,
z up) the specific force of a resting body is ``+e_z`` (1 g up) and the earth rate is
``we (cos lat, 0, sin lat)``; along the payload axes they are ``Rd^T`` times these, which is the
closed form of paper eq. 3.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..core.csv_table import closest_column_hint, read_csv_table
from ..core.exceptions import InputError
from ..core.sizes import MAX_POSITIONS, check_count, turn_grid_count
from ..core.units import deg_to_rad, rad_to_deg
from ..model.turntable import TurntableModel
from .site import DEFAULT_LATITUDE_DEG, MAX_LATITUDE_DEG  # noqa: F401  (re-exported)

__all__ = [
    "DEFAULT_LATITUDE_DEG",
    "EARTH_RATE_DPH",
    "MAX_COMMANDED_ANGLE_DEG",
    "POSITION_BYTES",
    "PositionInputs",
    "PositionSet",
    "angle_columns",
    "base_frame_inputs",
    "check_commanded_angles",
    "grid_angles_deg",
    "grid_steps",
    "position_inputs",
]

EARTH_RATE_DPH = 15.041067
"""Earth rotation rate used by the paper (eq. 3), deg/h."""

MAX_COMMANDED_ANGLE_DEG = 3600.0
"""Largest ``|phi1|``, ``|phi2|`` a position may command, degrees (ten turns either way): angles
are taken as written (a table may log its turns), but beyond ten turns a value is a unit mix-up
or a typo, and trigonometry of huge angles only returns rounding noise."""

POSITION_BYTES = 4096
"""Memory a position costs in the calibration layer's computations (rough upper bound), bytes."""

_GRID = re.compile(r"^grid:\s*([0-9.eE+-]+(?:\s*x\s*[0-9.eE+-]+)*)$")


def grid_steps(text: str) -> list[float] | None:
    """The steps (degrees: one for every joint, or one per joint) of a ``grid:STEP`` or
    ``grid:S1xS2[xS3]`` spec, or ``None`` when ``text`` is no grid spec (a file name).

    Raises:
        InputError: a spec that starts with ``grid`` but is malformed.
    """
    match = _GRID.match(text)
    if match is None:
        if text.startswith("grid"):
            raise InputError(
                f"positions '{text}': expected grid:STEP or grid:S1xS2[xS3] (degrees, one step "
                "per joint)"
            )
        return None
    try:
        return [float(s) for s in re.split(r"\s*x\s*", match.group(1).strip())]
    except ValueError:
        raise InputError(f"positions '{text}': bad grid step") from None


def grid_angles_deg(steps_deg: Sequence[float]) -> tuple[np.ndarray, str]:
    """Every joint in {0, step, ..., < 360} degrees, every combination: (N, J) angles in degrees
    (the last joint varies fastest) and the grid's name (``grid:30``, ``grid:30x45``).

    Raises:
        InputError: a step outside (0, 360], or more positions than ``MAX_POSITIONS``.
    """
    for step in steps_deg:
        if not (np.isfinite(step) and 0 < step <= 360):
            raise InputError(f"grid step must be in (0, 360] degrees, got {step!r}")
    same = all(s == steps_deg[0] for s in steps_deg)
    name = f"grid:{steps_deg[0]:g}" if same else "grid:" + "x".join(f"{s:g}" for s in steps_deg)
    count = 1.0
    for step in steps_deg:
        count *= float(turn_grid_count(step))
    check_count(count, MAX_POSITIONS, f"positions of {name}", POSITION_BYTES)
    axes = [np.arange(0.0, 360.0 - 1e-9, s) for s in steps_deg]
    mesh = np.meshgrid(*axes, indexing="ij")
    return np.stack([m.ravel() for m in mesh], axis=1), name


@dataclass(frozen=True)
class PositionSet:
    """Commanded turntable positions.

    Attributes:
        phi1_rad, phi2_rad: outer- and inner-axis angles, radians, shape (N,).
        name: the scheme name or file the positions came from.
    """

    phi1_rad: np.ndarray
    phi2_rad: np.ndarray
    name: str = ""

    def __post_init__(self) -> None:
        phi1 = np.array(self.phi1_rad, dtype=float).reshape(-1)
        phi2 = np.array(self.phi2_rad, dtype=float).reshape(-1)
        if phi1.shape != phi2.shape:
            raise InputError(f"positions: {phi1.size} phi1 values but {phi2.size} phi2 values")
        if phi1.size == 0:
            raise InputError("positions: the set is empty")
        check_count(phi1.size, MAX_POSITIONS, "positions", POSITION_BYTES)
        if not (np.all(np.isfinite(phi1)) and np.all(np.isfinite(phi2))):
            raise InputError("positions: angles must be finite numbers")
        largest = float(max(np.max(np.abs(phi1)), np.max(np.abs(phi2))))
        if largest > deg_to_rad(MAX_COMMANDED_ANGLE_DEG):
            raise InputError(
                f"positions: an angle of {rad_to_deg(largest):g} deg; commanded angles must be "
                f"within +-{MAX_COMMANDED_ANGLE_DEG:g} deg"
            )
        phi1.setflags(write=False)
        phi2.setflags(write=False)
        object.__setattr__(self, "phi1_rad", phi1)
        object.__setattr__(self, "phi2_rad", phi2)

    def __len__(self) -> int:
        return int(self.phi1_rad.size)

    @classmethod
    def grid(cls, step1_deg: float, step2_deg: float | None = None) -> PositionSet:
        """phi1 in {0, step1, ... < 360} and phi2 in {0, step2, ... < 360} degrees, all pairs."""
        step2_deg = step1_deg if step2_deg is None else step2_deg
        angles, name = grid_angles_deg([step1_deg, step2_deg])
        return cls(deg_to_rad(angles[:, 0]), deg_to_rad(angles[:, 1]), name)

    @classmethod
    def from_csv(cls, path: str | Path) -> PositionSet:
        """Read columns ``phi1_deg, phi2_deg`` (other columns are ignored)."""
        table = read_csv_table(path, ("phi1_deg", "phi2_deg"))
        check_commanded_angles(table)
        return cls(deg_to_rad(table["phi1_deg"]), deg_to_rad(table["phi2_deg"]), str(path))

    @classmethod
    def parse(cls, spec: str) -> PositionSet:
        """A scheme name (``grid:STEP``, ``grid:STEP1xSTEP2``) or the path of a CSV file."""
        text = str(spec).strip()
        steps = grid_steps(text)
        if steps is not None:
            if len(steps) > 2:
                raise InputError(
                    f"grid: {len(steps)} steps for the paper's table of 2 joints; give one "
                    "step, or one per joint"
                )
            return cls.grid(*steps)
        path = Path(text)
        if not path.exists():
            raise InputError(
                f"positions '{text}': neither a scheme (grid:STEP) nor an existing CSV file"
            )
        return cls.from_csv(path)

    def distinct_count(self, decimals: int = 9) -> int:
        """Number of distinct payload orientations (angles taken modulo 360 degrees)."""
        wrapped = (
            np.round(
                np.mod(rad_to_deg(np.stack([self.phi1_rad, self.phi2_rad], 1)), 360.0), decimals
            )
            % 360.0
        )
        return int(np.unique(wrapped, axis=0).shape[0])

    def to_dict(self) -> dict:
        """Name, count and the angles in degrees, as a dict."""
        return {
            "name": self.name,
            "n_positions": len(self),
            "phi1_deg": rad_to_deg(self.phi1_rad),
            "phi2_deg": rad_to_deg(self.phi2_rad),
        }


@dataclass(frozen=True)
class PositionInputs:
    """What the GyroWheel senses at each position of a set, at the ideal orientation.

    Attributes:
        positions: the :class:`PositionSet`.
        latitude_rad: latitude of the test site, radians.
        specific_force_g: (N, 3) specific force along the payload axes, g (eq. 3 ``a``).
        earth_rate_dph: (N, 3) earth rate along the payload axes, deg/h (eq. 3 ``w``).
        payload_rotation: (N, 3, 3) ideal payload orientation ``Rd`` (base <- payload).
    """

    positions: PositionSet
    latitude_rad: float
    specific_force_g: np.ndarray
    earth_rate_dph: np.ndarray
    payload_rotation: np.ndarray = field(repr=False)

    def __len__(self) -> int:
        return len(self.positions)


def check_commanded_angles(table, columns=("phi1_deg", "phi2_deg")) -> None:
    """Refuse a commanded angle beyond :data:`MAX_COMMANDED_ANGLE_DEG` in a :class:`CsvTable`,
    naming the file, row and column."""
    for column in columns:
        values = table[column]
        bad = np.flatnonzero(np.abs(values) > MAX_COMMANDED_ANGLE_DEG)
        if bad.size:
            raise InputError(
                f"a commanded angle must be within +-{MAX_COMMANDED_ANGLE_DEG:g} deg (ten turns), "
                f"found {values[bad[0]]:g}",
                path=table.path,
                row=int(table.rows[bad[0]]),
                column=column,
            )


def angle_columns(
    header: Sequence[str], joint_names: Sequence[str] | None, path=None, header_row: int = 1
) -> tuple[str, ...]:
    """The commanded-angle column of each joint in a CSV ``header``: ``phiK_deg`` (K counted
    from the base, chain order) or ``<joint>_deg``; the one rule of every file with positions.

    Without ``joint_names`` the table is the paper's two-axis one (``phi1_deg, phi2_deg``).

    Raises:
        InputError: a joint without its column, or with both spellings, or a ``phiK_deg`` column
            for a joint the table does not have (data of another table), at the header's row.
    """
    names = tuple(joint_names) if joint_names else ("", "")
    beyond = [c for c in header if (k := _numbered_joint(c)) is not None and k > len(names)]
    if beyond:
        joints = ", ".join(n for n in names if n) or "the paper's phi1, phi2"
        raise InputError(
            f"column {beyond[0]} is the angle of a joint this table does not have: it has "
            f"{len(names)} joint(s) ({joints}); are these data of the table given by --urdf?",
            path=path, row=header_row, column=beyond[0],
        )  # fmt: skip
    out = []
    for k, joint in enumerate(names, start=1):
        found = [c for c in (f"phi{k}_deg", f"{joint}_deg" if joint else None) if c in header]
        if not found:
            spelled = f"'phi{k}_deg'" + (f" or '{joint}_deg'" if joint else "")
            hint = closest_column_hint(f"phi{k}_deg", header) or (
                closest_column_hint(f"{joint}_deg", header) if joint else ""
            )
            raise InputError(
                f"missing required column {spelled} (the commanded angle of joint {k}"
                f"{' ' + joint if joint else ''}){hint}; the header has {', '.join(header)}",
                path=path, row=header_row,
            )  # fmt: skip
        if len(found) > 1:
            raise InputError(
                f"joint {k} has two angle columns, {found[0]} and {found[1]}; keep one",
                path=path, row=header_row,
            )  # fmt: skip
        out.append(found[0])
    return tuple(out)


def _numbered_joint(column: str) -> int | None:
    """K of a column named ``phiK_deg``, else None."""
    match = re.fullmatch(r"phi([0-9]+)_deg", column)
    return int(match.group(1)) if match else None


def base_frame_inputs(latitude_rad: float) -> tuple[np.ndarray, np.ndarray]:
    """Specific force (g) and earth rate (deg/h) in the base frame F0 (x north, y west, z up)."""
    force = np.array([0.0, 0.0, 1.0])
    rate = EARTH_RATE_DPH * np.array([np.cos(latitude_rad), 0.0, np.sin(latitude_rad)])
    return force, rate


def position_inputs(
    positions: PositionSet, latitude_rad: float, model: TurntableModel | None = None
) -> PositionInputs:
    """Specific force and earth rate along the payload axes at each position (eq. 3).

    Args:
        positions: the commanded angles: a :class:`PositionSet` of the paper's table, or a
            :class:`~turntable_pin.calibration.table_positions.JointPositions` of any table
            (whose nominal chain then gives ``Rd``; ``model`` is not used).
        latitude_rad: latitude of the test site, radians (|lat| <= pi/2).
        model: the turntable whose *ideal* (nominal) payload orientation is used; default the
            bundled URDF. Orientation errors enter later (eq. 8), not here.
    """
    largest = deg_to_rad(MAX_LATITUDE_DEG) + 1e-12
    if not (np.isfinite(latitude_rad) and abs(latitude_rad) <= largest):
        raise InputError(
            f"latitude must be within +-{MAX_LATITUDE_DEG:g} degrees, got "
            f"{rad_to_deg(latitude_rad)!r}"
        )
    if hasattr(positions, "nominal_rotations"):  # any table's positions (table_positions)
        rotations = positions.nominal_rotations()
    else:
        model = model if model is not None else TurntableModel()
        rotations = np.array(
            [
                model.ideal_pose(p1, p2).rotation
                for p1, p2 in zip(positions.phi1_rad, positions.phi2_rad, strict=True)
            ]
        )
    force, rate = base_frame_inputs(latitude_rad)
    # Rd maps payload to base coordinates, so payload components are Rd^T v (row vector v Rd).
    return PositionInputs(
        positions=positions,
        latitude_rad=float(latitude_rad),
        specific_force_g=force @ rotations,
        earth_rate_dph=rate @ rotations,
        payload_rotation=rotations,
    )

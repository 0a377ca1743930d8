"""Test positions of a multi-position calibration on any table, and the inputs the GyroWheel
senses at each.

A position is a tuple of commanded joint angles in chain order from the base (the order of
:attr:`~turntable_pin.model.generic_table.GenericTable.joint_names`); on the paper's table, the
default, these are phi1 about the outer axis y and phi2 about the inner axis z. A position set
comes from a scheme name, a CSV file or a seeded uniform draw (:meth:`PositionSet.random`):

- ``grid:STEP``: every joint in {0, STEP, ..., < 360} degrees, every combination (12 positions
  for one joint at 30 degrees, 144 for two, 1728 for three);
- ``grid:S1xS2[xS3]``: the same with one step per joint, in chain order;
- a CSV file with one angle column per joint: ``phi1_deg .. phiN_deg`` (chain order) or
  ``<joint>_deg`` (the joint names); other columns are ignored.

A set may also say when each position is measured (``time_s``) and from which side each joint
comes to it (``dirs``, +1/-1 per joint): the rows of a measurement run.

The specific force and the earth rate along the payload axes are ``Rd^T`` times their base-frame
values: in the base frame F0 (x north, y west, z up) the specific force of a resting body is
``+e_z`` (1 g up) and the earth rate is ``we (cos lat, 0, sin lat)``; ``Rd`` is the nominal
payload orientation of the table's Pinocchio model (forward kinematics of its URDF). On the
paper's table this is the closed form of paper eq. 3.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..core.csv_table import CsvTable, closest_column_hint, read_csv_table
from ..core.exceptions import InputError, check_seed
from ..core.sizes import MAX_POSITIONS, MAX_TIME_S, MIN_GRID_STEP_DEG, check_count, turn_grid_count
from ..core.turn_grid import full_turn_grid_deg, random_turn_positions_deg
from ..core.units import deg_to_rad, rad_to_deg
from ..core.words import argument
from ..model.paper_table import resolve_table
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
    "check_times_and_directions",
    "checked_times_and_directions",
    "position_inputs",
]

EARTH_RATE_DPH = 15.041067
"""Earth rotation rate used by the paper (eq. 3), deg/h."""

MAX_COMMANDED_ANGLE_DEG = 3600.0
"""Largest ``|angle|`` a position may command of any joint, degrees (ten turns either way): angles
are taken as written (a table may log its turns), but beyond ten turns a value is a unit mix-up
or a typo, and trigonometry of huge angles only returns rounding noise."""

POSITION_BYTES = 4096
"""Memory a position costs in the calibration layer's computations (rough upper bound), bytes."""

_GRID = re.compile(r"^grid:\s*([0-9.eE+-]+(?:\s*x\s*[0-9.eE+-]+)*)$")


def _grid_steps(text: str) -> list[float] | None:
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


@dataclass(frozen=True, init=False)
class PositionSet:
    """Commanded positions of a table with 1 to 3 joints, in the order they are measured.

    ``PositionSet(*angles_rad, table=None, name="", time_s=None, dirs=())`` takes one (N,) array
    per joint in chain order (``PositionSet(phi1_rad, phi2_rad)`` on the paper's table) or one
    (N, J) array.

    Attributes:
        angles_rad: (N, J) joint angles in chain order, radians (read-only).
        table: the :class:`~turntable_pin.model.generic_table.GenericTable` they command
            (default: the paper's, :func:`~turntable_pin.model.paper_table.paper_table`).
        name: the scheme name or file the positions came from.
        time_s: when each position is measured (N,), s in [0, ``MAX_TIME_S``], or ``None``.
        dirs: per joint, the side it approaches each position from (N,) (+1/-1), or ``None``.
    """

    angles_rad: np.ndarray
    table: object = field(repr=False, compare=False)
    name: str = ""
    time_s: np.ndarray | None = field(default=None, repr=False)
    dirs: tuple[np.ndarray | None, ...] = field(default=(), repr=False)

    def __init__(self, *angles_rad, table=None, name: str = "", time_s=None, dirs=()) -> None:
        table = resolve_table(table)
        n_joints = len(table.joint_names)
        if len(angles_rad) == 1 and np.ndim(angles_rad[0]) == 2:
            angles = np.array(angles_rad[0], dtype=float)
        else:
            columns = [np.array(a, dtype=float).reshape(-1) for a in angles_rad]
            if len({c.size for c in columns}) > 1:
                sizes = " and ".join(str(c.size) for c in columns)
                raise InputError(f"positions: {sizes} angles of the {len(columns)} joints")
            angles = np.stack(columns, axis=1) if columns else np.zeros((0, 0))
        if angles.shape[1] != n_joints:
            raise InputError(
                f"positions: expected {n_joints} angle(s) per position "
                f"({', '.join(table.joint_names)}), got {angles.shape[1]}"
            )
        if angles.shape[0] == 0:
            raise InputError("positions: the set is empty")
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
        object.__setattr__(self, "table", table)
        object.__setattr__(self, "name", name)
        if len(dirs) > n_joints:
            raise InputError(
                f"positions: {argument('dirs')} of {len(dirs)} joints, the table has {n_joints}"
            )
        dirs = (*dirs, *(None,) * (n_joints - len(dirs)))
        time_s, dirs = checked_times_and_directions(len(angles), time_s, dirs)
        object.__setattr__(self, "time_s", time_s)
        object.__setattr__(self, "dirs", dirs)

    def __len__(self) -> int:
        return int(self.angles_rad.shape[0])

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The joints, in the order of the columns of :attr:`angles_rad`."""
        return tuple(self.table.joint_names)

    @property
    def column_names(self) -> tuple[str, ...]:
        """The key of each joint's angle (degrees) in reports: ``<angle>_deg`` of the table's
        angle names (the paper's ``phi1_deg, phi2_deg``; ``<joint>_deg`` on a table whose layout
        names no angles)."""
        return tuple(f"{a}_deg" for a in self.table.angle_names)

    def joint_rad(self, k: int) -> np.ndarray:
        """The angles of joint ``k`` from the base (1 = the first), radians.

        Raises:
            InputError: the table has no joint ``k``.
        """
        if not 1 <= k <= len(self.joint_names):
            raise InputError(
                f"positions of {self.table.title} have no joint {k}: its joints are "
                f"{', '.join(self.joint_names)}"
            )
        return self.angles_rad[:, k - 1]

    # ---- construction -------------------------------------------------------------------------
    @classmethod
    def grid(cls, *steps_deg: float, table=None) -> PositionSet:
        """Every joint in {0, step, ..., < 360} degrees, every combination, the last joint
        fastest (one step for all joints, or one per joint in chain order); :class:`InputError`
        for a step outside [``MIN_GRID_STEP_DEG``, 360] or more than ``MAX_POSITIONS``."""
        table = resolve_table(table)
        n_joints = len(table.joint_names)
        if len(steps_deg) not in (1, n_joints):
            raise InputError(
                f"grid: {len(steps_deg)} steps for {table.title} of {n_joints} "
                f"joint{'s' if n_joints > 1 else ''} ({', '.join(table.joint_names)}); give one "
                "step, or one per joint"
            )
        steps = list(steps_deg) * (n_joints // len(steps_deg))
        for step in steps:
            if not (np.isfinite(step) and MIN_GRID_STEP_DEG <= step <= 360):
                raise InputError(
                    f"grid step must be in [{MIN_GRID_STEP_DEG:g}, 360] degrees, got {step!r}"
                )
        same = all(s == steps[0] for s in steps)
        name = f"grid:{steps[0]:g}" if same else "grid:" + "x".join(f"{s:g}" for s in steps)
        count = math.prod(float(turn_grid_count(step)) for step in steps)
        check_count(count, MAX_POSITIONS, f"positions of {name}", POSITION_BYTES)
        return cls(deg_to_rad(full_turn_grid_deg(*steps)), table=table, name=name)

    @classmethod
    def random(cls, n: int, table=None, seed: int = 0) -> PositionSet:
        """``n`` positions uniform over every joint's turn [0, 360) deg (rounded to 1e-6 deg), from
        their own stream of ``seed``; InputError for ``n`` below 1 or above ``MAX_POSITIONS``."""
        table = resolve_table(table)
        seed = check_seed(seed)
        if n < 1:
            raise InputError(f"random positions: expected N >= 1, got {n}")
        check_count(n, MAX_POSITIONS, "random positions of a calibration run", POSITION_BYTES)
        rng = np.random.default_rng([seed, 1])
        angles = random_turn_positions_deg(rng, n, len(table.joint_names))
        return cls(deg_to_rad(angles), table=table, name=f"random:{n}")

    @classmethod
    def from_csv(cls, path: str | Path, table=None) -> PositionSet:
        """Read the angle columns (``phi1_deg .. phiN_deg`` or ``<joint>_deg``) of a CSV file."""
        table = resolve_table(table)
        csv = read_csv_table(path, (), cls.candidate_columns(table))
        return cls.from_csv_table(csv, cls.columns_of(csv, table), table, str(path))

    @classmethod
    def from_csv_table(
        cls, csv: CsvTable, columns: tuple[str, ...], table, name: str
    ) -> PositionSet:
        """The positions of the angle ``columns`` (degrees) of a read :class:`CsvTable`."""
        check_commanded_angles(csv, columns)
        angles = np.stack([csv[c] for c in columns], axis=1)
        return cls(deg_to_rad(angles), table=table, name=name)

    @staticmethod
    def candidate_columns(table) -> tuple[str, ...]:
        """Every column name an angle may have for ``table`` (numbered, then by joint name)."""
        n = len(table.joint_names)
        names = [f"phi{i + 1}_deg" for i in range(n)] + [f"{j}_deg" for j in table.joint_names]
        return tuple(dict.fromkeys(names))

    @staticmethod
    def columns_of(csv: CsvTable, table) -> tuple[str, ...]:
        """The angle columns present in ``csv`` for ``table``, or :class:`InputError`."""
        return angle_columns(csv.header, table.joint_names, csv.path, csv.header_row)

    @classmethod
    def parse(cls, spec: str, table=None) -> PositionSet:
        """A scheme name (``grid:STEP``, ``grid:S1xS2[xS3]``) or the path of a CSV file."""
        text = str(spec).strip()
        steps = _grid_steps(text)
        if steps is not None:
            try:
                return cls.grid(*steps, table=table)
            except InputError as exc:
                if "grid:" in exc.detail:  # it names the spec already
                    raise
                raise InputError(f"positions '{text}': {exc.detail}") from None
        path = Path(text)
        if not path.exists():
            raise InputError(
                f"positions '{text}': neither a scheme (grid:STEP) nor an existing CSV file"
            )
        return cls.from_csv(path, table)

    # ---- what the payload sees ----------------------------------------------------------------
    def nominal_rotations(self) -> np.ndarray:
        """(N, 3, 3) nominal payload orientations ``Rd`` (base <- payload): Pinocchio forward
        kinematics of the table's URDF, for at most ``MAX_POSITIONS`` positions (the cost of a
        position in the calibration layer's computations, checked before any is computed)."""
        check_count(len(self), MAX_POSITIONS, "positions", POSITION_BYTES)
        pose = self.table.payload_pose
        return np.array([pose(None, angles).rotation for angles in self.angles_rad])

    def distinct_count(self, decimals: int = 9) -> int:
        """Number of distinct commanded positions (angles taken modulo 360 degrees)."""
        wrapped = np.round(np.mod(rad_to_deg(self.angles_rad), 360.0), decimals) % 360.0
        return int(np.unique(wrapped, axis=0).shape[0])

    def angles_deg(self) -> np.ndarray:
        """(N, J) the angles in degrees, rounded to 1e-9 deg (a 30-degree grid reads 30.0)."""
        return np.round(rad_to_deg(self.angles_rad), 9)

    def columns(self) -> dict[str, np.ndarray]:
        """The columns of a positions CSV: ``phiK_deg`` (:meth:`angles_deg`) of each joint, then
        ``time_s`` and ``dirK`` (integers) where the set has them."""
        out = {f"phi{k}_deg": a for k, a in enumerate(self.angles_deg().T, start=1)}
        if self.time_s is not None:
            out["time_s"] = self.time_s
        for k, d in enumerate(self.dirs, start=1):
            if d is not None:
                out[f"dir{k}"] = d.astype(int)
        return out

    def to_dict(self) -> dict:
        """Name, count, joint names and the angles in degrees per joint, as a dict."""
        out = {"name": self.name, "n_positions": len(self), "joints": list(self.joint_names)}
        for column, values in zip(self.column_names, rad_to_deg(self.angles_rad).T, strict=True):
            out[column] = values
        return out


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


def checked_times_and_directions(
    n: int, time_s=None, dirs=(), names: tuple[str, str] = ("time_s", "dirs")
) -> tuple[np.ndarray | None, tuple[np.ndarray | None, ...]]:
    """``time_s`` ((n,) s in [0, :data:`MAX_TIME_S`], or ``None``) and ``dirs`` (per joint (n,)
    +1/-1, or ``None``) as read-only arrays; :class:`InputError` naming the arguments ``names``."""
    if time_s is not None:
        time_s = np.array(time_s, dtype=float).reshape(-1)
        if time_s.shape != (n,) or not np.all((time_s >= 0) & (time_s <= MAX_TIME_S)):
            raise InputError(
                f"positions: {argument(names[0])} needs {n} times in [0, {MAX_TIME_S:g}] s, one "
                "per position"
            )
        time_s.setflags(write=False)
    checked = []
    for k, d in enumerate(dirs, start=1):
        if d is not None:
            d = np.array(d, dtype=float).reshape(-1)
            if d.shape != (n,) or not np.all(np.abs(d) == 1):
                raise InputError(
                    f"positions: {argument(names[1])} of joint {k} needs {n} values, each +1 or -1"
                )
            d.setflags(write=False)
        checked.append(d)
    return time_s, tuple(checked)


def check_times_and_directions(rows, dir_columns: Sequence[str]) -> None:
    """Refuse a ``time_s`` below 0 or above :data:`MAX_TIME_S` and a ``dirK`` not +1 or -1 of
    ``rows`` (a ``CsvTable``), naming file, row and column."""
    if rows.has("time_s"):
        time_s = rows["time_s"]
        rows.refuse("time_s", time_s < 0, "time since the start of the run must be >= 0")
        rows.refuse(
            "time_s", time_s > MAX_TIME_S,
            f"time since the start of the run must be at most {MAX_TIME_S:g} s (a year)",
        )  # fmt: skip
    for column in dir_columns:
        if rows.has(column):
            rows.refuse(column, np.abs(rows[column]) != 1, "an approach direction must be +1 or -1")


def check_commanded_angles(table, columns: Sequence[str]) -> None:
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
            f"{len(names)} joint(s) ({joints}); are these data of the table given by "
            f"{argument('urdf')}?",
            path=path, row=header_row, column=beyond[0],
        )  # fmt: skip
    known = [f"phi{k}_deg" for k in range(1, len(names) + 1)] + [f"{j}_deg" for j in names if j]
    return tuple(
        _angle_column(k, joint, header, known, path, header_row)
        for k, joint in enumerate(names, start=1)
    )


def _angle_column(k: int, joint: str, header, known: list[str], path, header_row: int) -> str:
    """The angle column of joint ``k`` (``joint``: its name, or empty on the paper's table) in
    ``header`` (:func:`angle_columns`)."""
    found = [c for c in (f"phi{k}_deg", f"{joint}_deg" if joint else None) if c in header]
    if not found:
        spelled = f"'phi{k}_deg'" + (f" or '{joint}_deg'" if joint else "")
        hint = closest_column_hint(f"phi{k}_deg", header, known) or (
            closest_column_hint(f"{joint}_deg", header, known) if joint else ""
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
    return found[0]


def _numbered_joint(column: str) -> int | None:
    """K of a column named ``phiK_deg``, else None."""
    match = re.fullmatch(r"phi([0-9]+)_deg", column)
    return int(match.group(1)) if match else None


def base_frame_inputs(latitude_rad: float) -> tuple[np.ndarray, np.ndarray]:
    """Specific force (g) and earth rate (deg/h) in the base frame F0 (x north, y west, z up)."""
    force = np.array([0.0, 0.0, 1.0])
    rate = EARTH_RATE_DPH * np.array([np.cos(latitude_rad), 0.0, np.sin(latitude_rad)])
    return force, rate


def position_inputs(positions: PositionSet, latitude_rad: float) -> PositionInputs:
    """Specific force and earth rate along the payload axes at each position (eq. 3).

    Args:
        positions: the commanded angles of a table; its *ideal* (nominal) payload orientation
            is used: orientation errors enter later (eq. 8), not here.
        latitude_rad: latitude of the test site, radians (|lat| <= pi/2).
    """
    largest = deg_to_rad(MAX_LATITUDE_DEG) + 1e-12
    if not (np.isfinite(latitude_rad) and abs(latitude_rad) <= largest):
        raise InputError(
            f"latitude must be within +-{MAX_LATITUDE_DEG:g} degrees, got "
            f"{rad_to_deg(latitude_rad)!r}"
        )
    rotations = positions.nominal_rotations()
    force, rate = base_frame_inputs(latitude_rad)
    # Rd maps payload to base coordinates, so payload components are Rd^T v (row vector v Rd).
    return PositionInputs(
        positions=positions,
        latitude_rad=float(latitude_rad),
        specific_force_g=force @ rotations,
        earth_rate_dph=rate @ rotations,
        payload_rotation=rotations,
    )

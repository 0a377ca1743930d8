"""The space a design chooses from: the table, the effects, the joints' limits, the candidates.

Every design starts here. A joint turns within its URDF ``<limit>`` (a continuous joint, or one
whose limits span a full turn, anywhere in [0, 360) deg), narrowed by ``limits_deg``
(``J=LO:HI``: ``J`` the joint's name or ``phiK``); the candidate positions are
drawn uniformly within the limits (seeded) and joined by the 30-degree grid within them, which
is also the design every result is compared with. The effects decide what the measurements must
also record: an effect that needs ``time_s`` makes the run repeat its positions early and late,
one that needs an approach direction ``dirK`` makes it approach each position from both sides
(:mod:`.schedule`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..core.exceptions import InputError, check_seed
from ..core.sizes import check_count
from ..core.turn_grid import RANDOM_ROUND_DECIMALS, every_combination, full_turn_grid_deg
from ..core.units import DEG_PER_RAD
from ..core.words import argument
from ..measurement.table import measured_table
from ..model.paper_table import resolve_table
from .schedule import Visits, candidate_visits

__all__ = [
    "DEFAULT_CANDIDATES",
    "DEFAULT_POSITIONS",
    "GRID_STEP_DEG",
    "MAX_CANDIDATES",
    "DesignSpace",
    "JointRange",
    "design_space",
    "joint_ranges",
    "parse_limits_deg",
]

GRID_STEP_DEG = 30.0
"""Step of the grid designs are compared with (and that joins the candidates), degrees."""

DEFAULT_CANDIDATES = 10_000
"""Random candidate positions a design chooses from by default."""

DEFAULT_POSITIONS = 24
"""Positions a design chooses when not told how many."""

MAX_CANDIDATES = 200_000
"""Most random candidates (each costs a few kB of Jacobian rows while the design runs)."""

CANDIDATE_BYTES = 4_000
"""Memory of one candidate while a design runs (its Jacobian rows and their products), bytes."""


@dataclass(frozen=True)
class JointRange:
    """Where one joint may be commanded, degrees.

    Attributes:
        joint: the joint's name; index: its place from the base (``phiK``).
        low_deg, high_deg: the range; a full-turn joint has ``[low_deg, low_deg + 360)``.
        full_turn: the joint turns all the way round (no limit narrower than a turn).
        source: ``urdf`` (its ``<limit>``), ``continuous`` (none) or ``limits_deg`` (its
            :func:`~turntable_pin.core.words.argument` name: the flag on the command line).
    """

    joint: str
    index: int
    low_deg: float
    high_deg: float
    full_turn: bool
    source: str

    def grid_deg(self, step_deg: float = GRID_STEP_DEG) -> np.ndarray:
        """The multiples of ``step_deg`` within the range (a full turn: [0, 360)); a range that
        holds none gives its two ends (its one angle when they are equal)."""
        if self.full_turn:
            return full_turn_grid_deg(step_deg)[:, 0]
        first = math.ceil(self.low_deg / step_deg - 1e-9)
        last = math.floor(self.high_deg / step_deg + 1e-9)
        if last >= first:
            return np.arange(first, last + 1) * step_deg
        return np.unique([self.low_deg, self.high_deg])

    def draw_deg(self, rng: np.random.Generator, count: int) -> np.ndarray:
        """``count`` angles uniform in the range, rounded to 1e-6 deg."""
        high = self.low_deg + 360.0 if self.full_turn else self.high_deg
        return np.round(rng.uniform(self.low_deg, high, count), RANDOM_ROUND_DECIMALS)

    def describe(self) -> str:
        """``outer_axis (phi1): full turn`` or ``elevation (phi2): 0 .. 90 deg (urdf)``."""
        where = "full turn" if self.full_turn else f"{self.low_deg:g} .. {self.high_deg:g} deg"
        return f"{self.joint} (phi{self.index}): {where} ({self.source})"

    def to_dict(self) -> dict:
        """The range as a JSON-ready dict."""
        return {
            "joint": self.joint,
            "angle": f"phi{self.index}",
            "low_deg": self.low_deg,
            "high_deg": None if self.full_turn else self.high_deg,
            "full_turn": self.full_turn,
            "source": self.source,
        }


_LIMIT = re.compile(r"^\s*([^=\s]+)\s*=\s*([^:]+):(.+)$")


def parse_limits_deg(text: str, joint_names: Sequence[str]) -> dict[int, tuple[float, float]]:
    """``limits_deg`` text ``J=LO:HI,...`` as ``{joint index (1 = phi1): (low, high)}``, degrees.

    ``J`` is a joint's name or ``phiK``; each joint at most once; ``LO <= HI``.

    Raises:
        InputError: a malformed item, an unknown joint, a bound that is not a finite number.
    """
    known = {f"phi{k}": k for k in range(1, len(joint_names) + 1)}
    known.update({name: k for k, name in enumerate(joint_names, start=1)})
    out: dict[int, tuple[float, float]] = {}
    flag = argument("limits_deg")
    for item in filter(None, (x.strip() for x in str(text).split(","))):
        match = _LIMIT.match(item)
        if not match:
            raise InputError(f"{flag} '{item}': expected JOINT=LO:HI, e.g. phi2=0:90")
        name, low_text, high_text = match.groups()
        if name not in known:
            raise InputError(
                f"{flag} '{item}': unknown joint '{name}'; the table's joints: "
                + ", ".join(f"{n} (phi{k})" for k, n in enumerate(joint_names, start=1))
            )
        try:
            low, high = float(low_text), float(high_text)
        except ValueError:
            raise InputError(f"{flag} '{item}': the bounds must be numbers") from None
        if not (math.isfinite(low) and math.isfinite(high)):
            raise InputError(f"{flag} '{item}': the bounds must be finite numbers")
        if low > high:
            raise InputError(
                f"{flag} '{item}': the lower bound {low:g} is above the upper {high:g}, "
                "which leaves no position"
            )
        if known[name] in out:
            raise InputError(f"{flag} '{item}': joint {name} is limited twice")
        out[known[name]] = (low, high)
    return out


def joint_ranges(table, limits_deg=None) -> tuple[JointRange, ...]:
    """Each joint's range: its URDF ``<limit>`` narrowed by ``limits_deg`` (``J=LO:HI,...`` text
    or ``{index or name: (low, high)}``); a joint without limits turns a full turn.

    Raises:
        InputError: limits that leave a joint no position (naming the joint and both ranges).
    """
    measured = measured_table(table)
    names = measured.joint_names
    if isinstance(limits_deg, str):
        given = parse_limits_deg(limits_deg, names)
    else:
        given = {}
        for key, bounds in (limits_deg or {}).items():
            index = key if isinstance(key, int) else (names.index(key) + 1 if key in names else 0)
            if not 1 <= index <= len(names):
                raise InputError(f"limits: unknown joint {key!r}; the table's: {', '.join(names)}")
            given[index] = (float(bounds[0]), float(bounds[1]))
    out = []
    for k, (name, urdf) in enumerate(zip(names, measured.joint_limits_rad, strict=True), start=1):
        if urdf is not None:
            low, high = (round(v * DEG_PER_RAD, 9) for v in urdf)
            source = "urdf"
        else:
            low, high, source = 0.0, 360.0, "continuous"
        full = urdf is None
        if k in given:
            g_low, g_high = given[k]
            if full:
                low, high = g_low, g_high
                full = g_high - g_low >= 360.0
            else:
                if g_low > high or g_high < low:
                    raise InputError(
                        f"{argument('limits_deg')} {name}={g_low:g}:{g_high:g} leaves no "
                        "position: the URDF "
                        f"limits {name} to {low:g} .. {high:g} deg"
                    )
                low, high = max(low, g_low), min(high, g_high)
            source = argument("limits_deg")
        out.append(JointRange(name, k, float(low), float(high), bool(full), source))
    return tuple(out)


def _design_columns(effects) -> tuple[bool, bool]:
    """``(needs time_s, needs dirK)`` of ``effects``.

    Raises:
        InputError: an effect that needs a column a design cannot set (a temperature log).
    """
    needs_time = needs_dirs = False
    for effect in effects:
        for column in effect.required_columns:
            if column == "time_s":
                needs_time = True
            elif re.fullmatch(r"dir\d+", column):
                needs_dirs = True
            elif not effect.any_column:
                raise InputError(
                    f"effect '{effect.name}' needs the column {column}, which a design cannot "
                    "choose (only positions, their order and time, and approach directions); "
                    f"leave it out of {argument('effects')}"
                )
    return needs_time, needs_dirs


@dataclass(frozen=True)
class DesignSpace:
    """What a design may choose from and what it must identify.

    Attributes:
        table: the table (a :class:`~turntable_pin.model.generic_table.GenericTable`).
        effects: the effects to identify besides the base errors.
        ranges: each joint's :class:`JointRange`.
        candidates_deg: the candidate positions (C, J), the random draws then the grid.
        grid_deg: the 30-degree grid within the limits (G, J).
        seed: the seed of the random candidates.
        needs_time: an effect needs ``time_s`` (the run repeats positions early and late).
        needs_dirs: an effect needs ``dirK`` (each position is approached from both sides).
        visits: how each candidate would be measured (:class:`~.schedule.Visits`: when, from
            which side; seeded).
    """

    table: object
    effects: tuple
    ranges: tuple[JointRange, ...]
    candidates_deg: np.ndarray = field(repr=False)
    grid_deg: np.ndarray = field(repr=False)
    seed: int
    needs_time: bool
    needs_dirs: bool
    visits: Visits = field(repr=False)

    @property
    def n_joints(self) -> int:
        """Number of joints J."""
        return len(self.ranges)

    @property
    def measured(self):
        """The :class:`~turntable_pin.measurement.table.MeasuredTable` of :attr:`table`."""
        return measured_table(self.table)

    @property
    def table_name(self) -> str:
        """How the results name the table: ``paper``, or its URDF's file name."""
        return Path(self.measured.label).name

    @property
    def effect_names(self) -> tuple[str, ...]:
        """The names of :attr:`effects`."""
        return tuple(e.name for e in self.effects)

    @property
    def limits_text(self) -> str:
        """``limits: `` and each joint's range in words (the designs' reports and comments)."""
        return "limits: " + "; ".join(r.describe() for r in self.ranges)

    def seed_text(self, n_positions: int) -> str:
        """The CSV comment's ``seed=.. candidates=.. n_positions=..``."""
        return (
            f"seed={self.seed} candidates={self.candidates_deg.shape[0]} n_positions={n_positions}"
        )

    def chosen_text(self, n_positions: int) -> str:
        """``N positions of C candidates (seed S) on TABLE`` (the reports' first line)."""
        return (
            f"{n_positions} positions of {self.candidates_deg.shape[0]} candidates (seed "
            f"{self.seed}) on {self.table_name}"
        )

    def positions_lines(self, positions_deg: np.ndarray) -> list[str]:
        """The positions in a report: a line naming the angles, then one line each, degrees."""
        names = ", ".join(f"phi{r.index}" for r in self.ranges)
        rows = ["  " + "  ".join(f"{v:10.4f}" for v in row) for row in positions_deg]
        return [f"positions ({names}, deg):", *rows]

    def to_dict(self) -> dict:
        """The space as a JSON-ready dict (limits, candidate count, grid size, seed)."""
        return {
            "table": self.table_name,
            "effects": list(self.effect_names),
            "limits": [r.to_dict() for r in self.ranges],
            "n_candidates": int(self.candidates_deg.shape[0]),
            "n_grid": int(self.grid_deg.shape[0]),
            "grid_step_deg": GRID_STEP_DEG,
            "seed": self.seed,
            "needs_time": self.needs_time,
            "needs_dirs": self.needs_dirs,
        }


def design_space(
    table=None,
    effects: Sequence = (),
    *,
    limits_deg: str | Mapping | None = None,
    candidates: int = DEFAULT_CANDIDATES,
    seed: int = 0,
) -> DesignSpace:
    """The :class:`DesignSpace` of a table.

    Args:
        table: a ``GenericTable`` (default: the paper's table).
        effects: effects (objects, e.g. from ``resolve_effects``) to identify besides the base.
        limits_deg: ``J=LO:HI,...`` text or ``{joint name or index: (low, high)}``, degrees.
        candidates: how many random candidate positions (the grid joins them).
        seed: seed of the random candidates (0 <= seed < 2**63).
    """
    table = resolve_table(table)
    seed = check_seed(seed)
    candidates = int(
        check_count(candidates, MAX_CANDIDATES, "candidate positions", CANDIDATE_BYTES)
    )
    if candidates < 1:
        raise InputError(f"candidates must be >= 1, got {candidates}")
    needs_time, needs_dirs = _design_columns(effects)
    ranges = joint_ranges(table, limits_deg)
    rng = np.random.default_rng(seed)
    drawn = np.stack([r.draw_deg(rng, candidates) for r in ranges], axis=1)
    grid = every_combination([r.grid_deg() for r in ranges])
    check_count(grid.shape[0], MAX_CANDIDATES, "grid positions", CANDIDATE_BYTES)
    all_deg = np.concatenate([drawn, grid])
    visits = candidate_visits(
        all_deg.shape[0], len(ranges), needs_time=needs_time, needs_dirs=needs_dirs,
        rng=np.random.default_rng([seed, 1]),
    )  # fmt: skip
    for array in (all_deg, grid):
        array.setflags(write=False)
    return DesignSpace(
        table=table,
        effects=tuple(effects),
        ranges=ranges,
        candidates_deg=all_deg,
        grid_deg=grid,
        seed=seed,
        needs_time=needs_time,
        needs_dirs=needs_dirs,
        visits=visits,
    )

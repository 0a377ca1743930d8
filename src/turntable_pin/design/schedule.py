"""The chosen positions as a run: order, times and approach directions (issue 19, item 3).

How a position is measured depends on what the effects need to be seen:

- nothing in time or direction: each position once, in the order of its angles (a tidy tour);
- an effect that needs ``time_s`` (thermal drift): each position twice, early and late: a seeded
  random pass over the positions and then the same pass backwards, so that every position's two
  times average to the run's middle and a slow drift is told apart from the positions' own
  errors (time and angle are decoupled);
- an effect that needs ``dirK`` (backlash): each position approached from both sides, once with
  ``dirK = +1`` and once with ``-1`` (per joint, the first side seeded and balanced).

With both, the early visit comes from one side and the late one from the other. The
:class:`MeasurementPlan` writes the CSV the simulation reads as its positions (``phiK_deg``, then
``time_s`` and ``dirK`` when the design needs them: one row per measurement).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..calibration.positions import PositionSet
from ..core.csv_table import write_csv_table
from ..core.units import DEG_PER_RAD

__all__ = ["MeasurementPlan", "Visits", "candidate_visits", "plan_measurements"]


@dataclass(frozen=True)
class Visits:
    """How each of C positions would be measured, as a design's criterion sees it before the
    order is known: once, or twice (early and late: at ``f`` and ``1 - f`` of the run, ``f``
    drawn in [0, 1/2), as a random pass and its reverse place it; from the sides ``s`` and
    ``-s``, drawn per joint).

    Attributes:
        count: measurements of each position (1 or 2).
        early_fraction: when the first is made, as a fraction of the run (C,), or ``None``.
        sides: the approach side of each joint on the first (C, J) (+1/-1), or ``None``.
    """

    count: int
    early_fraction: np.ndarray | None = field(default=None, repr=False)
    sides: np.ndarray | None = field(default=None, repr=False)

    def subset(self, index) -> Visits:
        """The visits of the positions ``index``."""
        return Visits(
            self.count,
            None if self.early_fraction is None else self.early_fraction[index],
            None if self.sides is None else self.sides[index],
        )

    def time_fractions(self) -> np.ndarray | None:
        """When each measurement is made, as a fraction of the run (C, count), or ``None``."""
        if self.early_fraction is None:
            return None
        return np.stack([self.early_fraction, 1.0 - self.early_fraction], axis=1)

    def signs(self) -> np.ndarray | None:
        """The approach side of each joint on each measurement (C, count, J), or ``None``."""
        if self.sides is None:
            return None
        return np.stack([self.sides, -self.sides], axis=1)


def candidate_visits(
    count: int, n_joints: int, *, needs_time: bool, needs_dirs: bool, rng: np.random.Generator
) -> Visits:
    """The :class:`Visits` of ``count`` positions (module docstring for the rules), drawn with
    ``rng``."""
    if not (needs_time or needs_dirs):
        return Visits(1)
    early = rng.uniform(0.0, 0.5, count) if needs_time else None
    sides = rng.choice([-1.0, 1.0], (count, n_joints)) if needs_dirs else None
    return Visits(2, early, sides)


@dataclass(frozen=True)
class MeasurementPlan:
    """The measurements of a design, one row each, in the order they are made.

    Attributes:
        rows: the rows' positions (M) with their ``time_s`` and approach directions ``dirs``
            when an effect needs them (a :class:`~turntable_pin.calibration.positions.PositionSet`).
        position: which of the design's positions each row measures (M,).
        dwell_s: time between rows; seed: the seed of the order and directions.
        rule: the order in words.
    """

    rows: PositionSet = field(repr=False)
    position: np.ndarray = field(repr=False)
    dwell_s: float
    seed: int
    rule: str

    @property
    def n_rows(self) -> int:
        """Number of measurements M."""
        return len(self.rows)

    def first_order(self) -> np.ndarray:
        """The design's positions (indices) in the order they are first measured."""
        return self.position[np.sort(np.unique(self.position, return_index=True)[1])]

    def write_csv(self, path: str | Path, comment: str = "") -> Path:
        """Write the plan's CSV (:meth:`PositionSet.columns`) atomically (``comment`` lines first,
        with a ``#``)."""
        return write_csv_table(path, self.rows.columns(), comment=comment)

    def to_dict(self) -> dict:
        """The plan as a JSON-ready dict (its rows as the CSV has them)."""
        columns = self.rows.columns()
        return {
            "n_measurements": self.n_rows,
            "rule": self.rule,
            "dwell_s": self.dwell_s,
            "seed": self.seed,
            "columns": list(columns),
            "rows": [[float(columns[c][i]) for c in columns] for i in range(self.n_rows)],
        }


def plan_measurements(
    positions_deg,
    *,
    needs_time: bool = False,
    needs_dirs: bool = False,
    dwell_s: float = 60.0,
    seed: int = 0,
    start_s: float = 0.0,
    visits: Visits | None = None,
    table=None,
) -> MeasurementPlan:
    """The run that measures ``positions_deg`` (N, J) (module docstring for the rules).

    Args:
        positions_deg: the design's positions, degrees.
        needs_time: an effect needs ``time_s``: each position early and late.
        needs_dirs: an effect needs ``dirK``: each position from both sides.
        dwell_s: time between measurements (the ``time_s`` column), seconds.
        seed: seed of the order and of the first approach sides (when ``visits`` does not say
            them).
        start_s: time of the first measurement (after a run already measured).
        visits: the positions' :class:`Visits` as the design chose them: the first pass goes in
            the order of their early times, and each joint comes first from their side
            (default: a seeded random order and balanced random sides).
        table: the table the positions are of (default: the paper's).
    """
    positions = np.asarray(positions_deg, dtype=float)
    if positions.ndim == 1:
        positions = positions[:, None]
    n, n_joints = positions.shape
    rng = np.random.default_rng(seed)
    tour = np.lexsort(positions.T[::-1])  # by phi1, then phi2, ...
    if needs_time:
        given = visits is not None and visits.early_fraction is not None
        first = np.argsort(visits.early_fraction, kind="stable") if given else rng.permutation(n)
        order = np.concatenate([first, first[::-1]])
        rule = (
            "each position twice, early and late: a random pass (seeded), then the same pass "
            "backwards (time and angle decoupled)"
        )
    elif needs_dirs:
        order = np.repeat(tour, 2)
        rule = "each position twice in a row, once from each side, in the order of the angles"
    else:
        order = tour
        rule = "each position once, in the order of the angles"
    time_s = start_s + np.arange(order.size) * float(dwell_s) if needs_time else None
    dirs = ()
    if needs_dirs:
        if visits is not None and visits.sides is not None:
            side = np.asarray(visits.sides, dtype=float)
        else:  # per joint, half the positions come first from +1 (seeded)
            half = np.arange(n) % 2 * 2.0 - 1.0
            side = np.stack([rng.permutation(half) for _ in range(n_joints)], axis=1)
        second = np.zeros(order.size, dtype=bool)
        seen = np.zeros(n, dtype=bool)
        for row, p in enumerate(order):
            second[row] = seen[p]
            seen[p] = True
        dirs = tuple(np.where(second[:, None], -side[order], side[order]).T)
        rule += "; dirK: each position from +1 and from -1"
    return MeasurementPlan(
        rows=PositionSet(positions[order] / DEG_PER_RAD, table=table, time_s=time_s, dirs=dirs),
        position=order,
        dwell_s=float(dwell_s),
        seed=int(seed),
        rule=rule,
    )

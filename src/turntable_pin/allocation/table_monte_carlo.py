"""Monte Carlo check of an allocation on any table (1 to 3 joints), with its exact chain.

N random tables are drawn inside the allocated box: each of the table's angular errors gets a
magnitude uniform in ``[LB_i, UB_i]`` and a random sign (the offsets stay 0: they move the
payload, never its orientation). Each table's exact ``dR`` comes from
:meth:`OrientationErrorField.from_chain` on the table's :class:`ErrorChain`, evaluated on the full
grid over every joint of the allocation (:func:`.table_allocation.grid_angles_rad`); the result
keeps each table's largest ``|dpsi|, |dtheta|, |dgamma|`` over the grid.

Chunks draw their samples from ``SeedSequence(seed).spawn(...)``, so the result depends on the seed
only, not on the number of worker processes; the checks, the draw, the chunks, the
workers and the verdict are :mod:`.monte_carlo`'s.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..core.units import arcmin_by_name
from ..model.batch_field import OrientationErrorField
from .monte_carlo import MonteCarloSummary, check_run, chunk_plan, run_chunks, signed_magnitudes
from .solver import OrientationLimits
from .table_allocation import angular_names, default_grid_step_deg, grid_angles_rad

__all__ = [
    "TABLE_CHUNK_SIZE",
    "TableMonteCarloResult",
    "run_table_monte_carlo",
    "sample_table_errors",
]

TABLE_CHUNK_SIZE = 500
"""Tables per task: with a block of grid positions the (chunk, 3, block) arrays stay small."""
_POSITION_BLOCK = 1024  # grid positions evaluated at once


def sample_table_errors(table, rng: np.random.Generator, n: int, upper_rad, lower_rad):
    """(n, E) error vectors in ``table.chain.error_names`` order: each angular error uniform in
    magnitude in [lower, upper] (radians) with a random sign, offsets 0."""
    values = np.zeros((n, len(table.chain.error_names)))
    columns = [table.chain.error_names.index(name) for name in angular_names(table)]
    values[:, columns] = signed_magnitudes(rng, n, upper_rad, lower_rad)
    return values


@lru_cache(maxsize=4)
def _table(urdf: str, payload_frame: str):
    """One :class:`GenericTable` per process, URDF and payload frame."""
    from ..model.generic_table import GenericTable

    return GenericTable(urdf, payload_frame)


def _run_table_chunk(args) -> tuple[np.ndarray, None]:
    """Worker: sample one chunk of tables, return each one's max |angle| over the grid (n, 3)
    (and nothing else)."""
    seed_seq, n, upper, lower, urdf, frame, step = args
    table = _table(urdf, frame)
    rng = np.random.default_rng(seed_seq)
    field = OrientationErrorField.from_chain(
        table.chain, sample_table_errors(table, rng, n, upper, lower)
    )
    grid = grid_angles_rad(table, step)
    worst = np.zeros((n, 3))
    for start in range(0, grid[0].size, _POSITION_BLOCK):
        block = [g[start : start + _POSITION_BLOCK] for g in grid]
        angles = np.abs(field.angles(*block))  # (n, B, 3)
        np.maximum(worst, angles.max(axis=1), out=worst)
    return worst, None


@dataclass(frozen=True)
class TableMonteCarloResult(MonteCarloSummary):
    """The outcome of :func:`run_table_monte_carlo`.

    Attributes:
        worst_rad: (N, 3) each table's largest |dpsi|, |dtheta|, |dgamma| over the grid, rad.
        error_names: the angular errors drawn.
        upper_bounds_rad, lower_bounds_rad: (P,) the box sampled.
        limits: the orientation limits checked against.  n, seed: sample size and seed.
        grid_step_deg, n_grid_points: the grid over every joint.
        elapsed_s: wall time.  workers: processes used.  urdf, payload_frame: the table.
    """

    worst_rad: np.ndarray
    error_names: tuple[str, ...]
    upper_bounds_rad: np.ndarray
    lower_bounds_rad: np.ndarray
    limits: OrientationLimits
    n: int
    seed: int
    grid_step_deg: float
    n_grid_points: int
    elapsed_s: float
    workers: int
    urdf: str = ""
    payload_frame: str = ""

    @property
    def evaluations(self) -> int:
        """Table x grid-position evaluations done."""
        return self.n * self.n_grid_points

    def to_dict(self) -> dict:
        """The outcome as a JSON-ready dict (angles in arcmin, steps in degrees, time in s)."""
        return {
            "urdf": self.urdf,
            "payload_frame": self.payload_frame,
            **self.verdict_dict(),
            "sampling": "magnitude uniform in [lower, upper] bound, random sign; offsets 0",
            "upper_bounds_arcmin": arcmin_by_name(self.error_names, self.upper_bounds_rad),
            "lower_bounds_arcmin": arcmin_by_name(self.error_names, self.lower_bounds_rad),
            "grid_step_deg": self.grid_step_deg,
            "n_grid_points": self.n_grid_points,
            **self.timing_dict(),
        }


def run_table_monte_carlo(
    table,
    upper_bounds_rad,
    limits: OrientationLimits,
    n: int,
    seed: int,
    *,
    lower_bounds_rad=None,
    grid_step_deg: float | None = None,
    workers: int = 1,
    progress: bool = True,
) -> TableMonteCarloResult:
    """Evaluate ``n`` random tables inside the box on the exact chain; compare with ``limits``.

    Args:
        table: a :class:`~turntable_pin.model.generic_table.GenericTable`.
        upper_bounds_rad, lower_bounds_rad: (P,) bounds of the magnitudes of the table's angular
            errors (:func:`.table_allocation.angular_names` order; lower default 0), radians.
        limits: orientation limits.  n: number of tables.  seed: random seed (recorded).
        grid_step_deg: the grid over every joint (default by joint count).
        workers: processes (the result does not depend on it).  progress: report on stderr.
    """
    names = angular_names(table)
    upper, lower, seed = check_run(
        upper_bounds_rad,
        lower_bounds_rad,
        n,
        seed,
        len(names),
        f"expected {len(names)} upper and lower bounds ({', '.join(names)})",
        finite=True,
    )
    step = default_grid_step_deg(table) if grid_step_deg is None else float(grid_step_deg)
    n_grid = grid_angles_rad(table, step)[0].size  # checks the step
    sizes, seeds = chunk_plan(n, TABLE_CHUNK_SIZE, seed)
    urdf, frame = str(table.urdf_path), table.payload_frame
    tasks = [
        (s, size, upper, lower, urdf, frame, step) for s, size in zip(seeds, sizes, strict=True)
    ]
    worst, _, workers, elapsed = run_chunks(_run_table_chunk, tasks, sizes, workers, progress)
    return TableMonteCarloResult(
        worst_rad=worst,
        error_names=names,
        upper_bounds_rad=upper,
        lower_bounds_rad=lower,
        limits=limits,
        n=n,
        seed=seed,
        grid_step_deg=step,
        n_grid_points=int(n_grid),
        elapsed_s=elapsed,
        workers=workers,
        urdf=urdf,
        payload_frame=frame,
    )

"""Monte Carlo check of an allocation on any table, with its exact chain (paper Figure 9).

N random tables are drawn inside the allocated box: each of the table's angular errors gets a
magnitude uniform in ``[LB_i, UB_i]`` and a random sign (the other errors -- the paper's
intersection error ``deta``, a table's axis offsets -- stay 0: they move the payload origin, never
its orientation). Each table's exact ``dR`` over a full grid of joint angles comes from the
trigonometric coefficients of :class:`~turntable_pin.model.batch_field.ChainExpansion` (one batch
of tables at a time: their coefficients, then the grid one joint at a time); the run keeps each
table's largest ``|dpsi|, |dtheta|, |dgamma|``. A joint whose angle no drawn table's ``dR``
depends on (the paper's outer axis phi1 with the errors of its Table 2: every harmonic of phi1 is
zero) is evaluated at 0 only; :data:`DEPENDENCE_TOLERANCE` says what zero is.

:func:`run_chain_monte_carlo` is the run, for any :class:`~turntable_pin.model.chain.ErrorChain`;
:func:`run_monte_carlo` gives it a table (default the bundled one) over the same grid on every
joint.

Chunks of :data:`CHUNK_SIZE` tables draw their samples from ``SeedSequence(seed).spawn(...)``, so
the result depends on the seed only, not on the number of worker processes. Worker processes
never outlive the run: on an error or an interruption (SIGINT, SIGTERM) they are killed at once,
not waited for; Ctrl-C, which reaches the whole process group, is left to the parent.
"""

from __future__ import annotations

import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, replace

import numpy as np

from ..core.blas_threads import blas_thread_controls, one_blas_thread
from ..core.exceptions import InputError, check_seed
from ..core.interrupts import deferred, register_cleanup, signals_blocked, worker_initializer
from ..core.progress import Progress
from ..core.sizes import (
    MAX_MONTE_CARLO_TURNTABLES,
    MIN_GRID_STEP_DEG,
    check_count,
    turn_grid_count,
)
from ..core.turn_grid import full_turn_grid_deg
from ..core.units import DEG_PER_RAD, arcmin_by_name
from ..model.angles import ANGLE_SYMBOLS
from ..model.batch_field import ChainExpansion, joint_dependence, max_abs_on_grid
from ..model.errors import ANGULAR_ERROR_NAMES, ERROR_NAMES
from ..model.paper_table import resolve_table
from .sensitivity import MAX_GRID_POINTS, check_grid_step
from .solver import OrientationLimits

__all__ = [
    "CHUNK_SIZE",
    "DEPENDENCE_TOLERANCE",
    "TURNTABLE_BYTES",
    "MonteCarloResult",
    "run_chain_monte_carlo",
    "run_monte_carlo",
    "sample_errors",
]

CHUNK_SIZE = 2000
"""Tables drawn from one spawned seed (one task), on every table: part of what a seed means (it
fixes which tables the seed draws)."""

TURNTABLE_BYTES = 64
"""Memory a turntable of the run keeps (its three worst angles, its share of the tasks), bytes."""

DEPENDENCE_TOLERANCE = 1e-12
"""Largest harmonic of a joint's angle in ``dpsi, dtheta, dgamma`` below which the joint is taken
to drop out (rounding of the coefficients is about 1e-16)."""


def sample_errors(
    rng: np.random.Generator,
    n: int,
    upper_bounds_rad,
    lower_bounds_rad,
    error_names=ERROR_NAMES,
    drawn_names=ANGULAR_ERROR_NAMES,
) -> np.ndarray:
    """(n, E) error vectors in ``error_names`` order: the ``drawn_names`` (the order of the
    bounds) with magnitudes uniform in [LB, UB] and random signs (magnitudes drawn first, then
    signs), every other error 0. Default: the paper's nine errors, ``deta = 0``."""
    upper = np.asarray(upper_bounds_rad, dtype=float)
    magnitudes = rng.uniform(np.asarray(lower_bounds_rad, dtype=float), upper, (n, upper.size))
    values = np.zeros((n, len(error_names)))
    columns = [list(error_names).index(name) for name in drawn_names]
    values[:, columns] = magnitudes * rng.choice(np.array([-1.0, 1.0]), size=(n, upper.size))
    return values


def _run_chunk(task) -> tuple[np.ndarray, np.ndarray]:
    """Worker: draw one chunk of tables; each one's max |angle| over the grid (n, 3) and the
    chunk's largest harmonic of each joint."""
    seed_seq, n, expansion, names, upper, lower, grids, tolerance = task
    values = sample_errors(np.random.default_rng(seed_seq), n, upper, lower, *names)
    coefficients = expansion.coefficients(values)
    dependence = joint_dependence(coefficients, expansion.n_joints)
    grids = [g if d > tolerance else g[:1] for g, d in zip(grids, dependence, strict=True)]
    return max_abs_on_grid(coefficients, grids), dependence


def _start_worker() -> None:
    """Pool initializer: the interruption handling of every worker, and one BLAS thread for
    the worker's life (a product split over threads on cores the other workers use was 3 to 6
    times slower)."""
    worker_initializer()
    for set_threads, _ in blas_thread_controls():
        set_threads(1)


def _stop_workers(pools: list[ProcessPoolExecutor], kill: bool = True) -> None:
    """Stop the workers of ``pools``. Idempotent; a no-op for a pool already shut down normally.

    ``kill`` (an interruption): SIGKILL the workers, wait for none of their chunks, and do not
    join the pool's manager thread: a worker killed while it wrote a result leaves half a message
    in the result pipe, which the manager thread then waits on for ever (the interrupted command
    ends with ``os._exit``, so nothing joins it later). Otherwise (an error): cancel what has not
    started and wait for the chunks that run.
    """
    with deferred():
        for pool in pools:
            if not kill:
                pool.shutdown(wait=True, cancel_futures=True)
                continue
            processes = list((getattr(pool, "_processes", None) or {}).values())
            for process in processes:
                if process.exitcode is None:
                    process.kill()
            for process in processes:
                process.join()
            pool.shutdown(wait=False, cancel_futures=True)
        pools.clear()


def _chunk_results(tasks, sizes, workers: int, progress: bool):
    """Yield ``_run_chunk(task)`` of every task in order, in this process (``workers == 1``) or
    in a pool of ``workers`` processes, reporting the turntables done (``sizes``) on stderr.

    The workers never outlive the run (see the module docstring).
    """
    pools: list[ProcessPoolExecutor] = []
    # Registered before the workers start: an interruption at any moment still stops them.
    unregister = register_cleanup(lambda: _stop_workers(pools))
    try:
        with Progress(int(sum(sizes)), "Monte Carlo", enabled=progress) as bar:
            if workers == 1:
                results = map(_run_chunk, tasks)
            else:
                # Workers start with SIGINT/SIGTERM blocked and set up their own handling.
                with deferred(), signals_blocked():
                    pools.append(
                        ProcessPoolExecutor(max_workers=workers, initializer=_start_worker)
                    )
                    # Not pool.map: its generator cancels the futures when interrupted, and
                    # Python 3.11's pool then fails (a traceback) marking them broken.
                    futures = [pools[0].submit(_run_chunk, task) for task in tasks]
                results = (future.result() for future in futures)
            for result, size in zip(results, sizes, strict=True):
                yield result
                bar.update(size)
        with deferred():
            for pool in pools:  # every chunk is done: the workers are idle
                pool.shutdown(cancel_futures=True)
            pools.clear()
    finally:
        # On an interruption kill them and wait for no chunk; on an error let running chunks end.
        # A generator closed before its end (GeneratorExit) was abandoned: kill as well.
        _stop_workers(pools, kill=isinstance(sys.exc_info()[1], (KeyboardInterrupt, GeneratorExit)))
        unregister()


@dataclass(frozen=True)
class MonteCarloResult:
    """The outcome of :func:`run_chain_monte_carlo`.

    Attributes:
        worst_rad: (N, 3) each table's largest |dpsi|, |dtheta|, |dgamma| over the grid, rad.
        error_names: the angular errors drawn; upper_bounds_rad, lower_bounds_rad: (P,) the box.
        limits: the orientation limits checked against.  n, seed: sample size and seed.
        joint_names: the grid's joints (chain order); grid_steps_deg: each one's step, degrees.
        evaluated_deg: each joint's angles evaluated, degrees: its grid, or 0 alone when no drawn
            table's ``dR`` depends on it; max_dependence: its largest harmonic in any table.
        elapsed_s: wall time.  workers: processes used.
        zero_names: the errors held at 0 (the lengths: the paper's ``deta``, a table's offsets).
        urdf, payload_frame: the table's.  angle_names: the joints' angles in keys (default the
            joint names).
    """

    worst_rad: np.ndarray
    error_names: tuple[str, ...]
    upper_bounds_rad: np.ndarray
    lower_bounds_rad: np.ndarray
    limits: OrientationLimits
    n: int
    seed: int
    joint_names: tuple[str, ...]
    grid_steps_deg: tuple[float, ...]
    evaluated_deg: tuple[tuple[float, ...], ...]
    max_dependence: tuple[float, ...]
    elapsed_s: float
    workers: int
    zero_names: tuple[str, ...] = ()
    urdf: str = ""
    payload_frame: str = ""
    angle_names: tuple[str, ...] = ()

    @property
    def max_abs_rad(self) -> np.ndarray:
        """(3,) largest |dpsi|, |dtheta|, |dgamma| over all tables and positions."""
        return self.worst_rad.max(axis=0)

    @property
    def all_within(self) -> bool:
        """Whether every table stays within the limits on every angle."""
        return bool(np.all(self.max_abs_rad <= self.limits.as_array()))

    @property
    def n_grid_points(self) -> int:
        """Positions of the full grid over every joint."""
        return int(np.prod([turn_grid_count(step) for step in self.grid_steps_deg]))

    @property
    def evaluations(self) -> int:
        """Table x position evaluations done."""
        return self.n * int(np.prod([len(angles) for angles in self.evaluated_deg]))

    @property
    def _keys(self) -> tuple[str, ...]:
        return self.angle_names or self.joint_names

    @property
    def held_at_deg(self) -> dict[str, float]:
        """``{angle: degrees}`` of each joint evaluated at one angle only (no drawn table's
        ``dR`` depends on it: the paper's phi1)."""
        return {
            key: angles[0]
            for key, angles in zip(self._keys, self.evaluated_deg, strict=True)
            if len(angles) == 1
        }

    def to_dict(self) -> dict:
        """The outcome as a JSON-ready dict (angles in arcmin, steps in degrees, time in s): the
        table, the verdict, the box sampled, the grid, the joints held and each joint's largest
        harmonic, the timing; one schema for every table."""
        limits = self.limits.as_array()
        exceeding = map(int, np.sum(self.worst_rad > limits, axis=0))
        zeros = f"; {', '.join(self.zero_names)} = 0" if self.zero_names else ""
        steps = dict(zip(self._keys, self.grid_steps_deg, strict=True))
        return {
            "urdf": self.urdf,
            "payload_frame": self.payload_frame,
            "max_abs_arcmin": arcmin_by_name(ANGLE_SYMBOLS, self.max_abs_rad),
            "limits_arcmin": self.limits.to_dict(),
            "all_within": self.all_within,
            "n_exceeding": dict(zip(ANGLE_SYMBOLS, exceeding, strict=True)),
            "n": self.n,
            "seed": self.seed,
            "sampling": f"magnitude uniform in [lower, upper] bound, random sign{zeros}",
            "upper_bounds_arcmin": arcmin_by_name(self.error_names, self.upper_bounds_rad),
            "lower_bounds_arcmin": arcmin_by_name(self.error_names, self.lower_bounds_rad),
            "grid_step_deg": self.grid_steps_deg[0] if len(set(steps.values())) == 1 else steps,
            "n_grid_points": self.n_grid_points,
            "held_at_deg": self.held_at_deg,
            "max_dependence": dict(zip(self._keys, self.max_dependence, strict=True)),
            "elapsed_s": self.elapsed_s,
            "evaluations_per_s": self.evaluations / max(self.elapsed_s, 1e-12),
            "workers": self.workers,
        }


def _checked_bounds(names, upper_bounds_rad, lower_bounds_rad) -> tuple[np.ndarray, np.ndarray]:
    """The (P,) upper and lower bounds (lower default 0), or :class:`InputError`."""
    upper = np.asarray(upper_bounds_rad, dtype=float).reshape(-1)
    lower = (
        np.zeros_like(upper) if lower_bounds_rad is None else np.asarray(lower_bounds_rad, float)
    )
    if upper.size != len(names) or lower.shape != upper.shape:
        raise InputError(f"expected {len(names)} upper and lower bounds ({', '.join(names)})")
    if not np.all(np.isfinite(upper)):
        raise InputError("every upper bound must be a finite number")
    if np.any(lower > upper) or np.any(lower < 0.0):
        raise InputError("every lower bound must be between 0 and its upper bound")
    return upper, lower


def _checked_steps(joint_names, grid_steps_deg) -> tuple[float, ...]:
    """One grid step per joint in [MIN, 90] degrees, each joint's grid within its limit."""
    steps = tuple(float(step) for step in grid_steps_deg)
    if len(steps) != len(joint_names) or not all(MIN_GRID_STEP_DEG <= s <= 90.0 for s in steps):
        raise InputError(
            f"expected a grid step in [{MIN_GRID_STEP_DEG:g}, 90] degrees for each of "
            f"{', '.join(joint_names)}, got {steps}"
        )
    for joint, step in zip(joint_names, steps, strict=True):
        check_count(turn_grid_count(step), MAX_GRID_POINTS,
                    f"grid angles of {joint} (a {step:g}-degree step)")  # fmt: skip
    return steps


def run_chain_monte_carlo(
    chain,
    error_names,
    upper_bounds_rad,
    limits: OrientationLimits,
    n: int,
    seed: int,
    *,
    grid_steps_deg,
    lower_bounds_rad=None,
    chunk_size: int = CHUNK_SIZE,
    workers: int = 1,
    progress: bool = True,
) -> MonteCarloResult:
    """Evaluate ``n`` random tables inside the box on the exact chain; compare with ``limits``.

    Args:
        chain: the table's :class:`~turntable_pin.model.chain.ErrorChain` (1 to 3 joints).
        error_names: the angular errors drawn, in the order of the bounds (the others stay 0).
        upper_bounds_rad, lower_bounds_rad: (P,) bounds of their magnitudes (lower default 0).
        limits: orientation limits.  n: number of tables.  seed: random seed (recorded).
        grid_steps_deg: each joint's grid step over the whole turn, degrees, in chain order.
        chunk_size: tables drawn from one spawned seed (the seed's meaning depends on it).
        workers: processes (the result does not depend on it).  progress: report on stderr.

    Raises:
        InputError: not one bound per angular error, an upper bound not finite, a lower bound
            outside ``[0, upper]``, fewer than 1 or too many tables, a bad seed or grid step.
    """
    names = tuple(error_names)
    upper, lower = _checked_bounds(names, upper_bounds_rad, lower_bounds_rad)
    if n < 1:
        raise InputError(f"the number of turntables must be at least 1, got {n}")
    check_count(n, MAX_MONTE_CARLO_TURNTABLES, "random turntables", TURNTABLE_BYTES)
    seed = check_seed(seed)
    steps = _checked_steps(chain.joint_names, grid_steps_deg)
    grids = [full_turn_grid_deg(step)[:, 0] / DEG_PER_RAD for step in steps]
    sizes = [chunk_size] * (n // chunk_size) + ([n % chunk_size] if n % chunk_size else [])
    chunk_names = (chain.error_names, names)
    expansion = ChainExpansion(chain)
    tasks = [
        (s, size, expansion, chunk_names, upper, lower, grids, DEPENDENCE_TOLERANCE)
        for s, size in zip(np.random.SeedSequence(seed).spawn(len(sizes)), sizes, strict=True)
    ]
    workers = max(1, min(int(workers), os.cpu_count() or 1, len(tasks)))
    start = time.perf_counter()
    worst = np.empty((n, 3))
    dependence = np.zeros(len(steps))
    offset = 0
    with one_blas_thread():  # for the chunks run in this process (workers == 1)
        for (chunk_worst, chunk_dependence), size in zip(
            _chunk_results(tasks, sizes, workers, progress), sizes, strict=True
        ):
            worst[offset : offset + size] = chunk_worst
            np.maximum(dependence, chunk_dependence, out=dependence)
            offset += size
    elapsed = time.perf_counter() - start
    evaluated = tuple(
        tuple(map(float, full_turn_grid_deg(step)[:, 0])) if d > DEPENDENCE_TOLERANCE else (0.0,)
        for step, d in zip(steps, dependence, strict=True)
    )
    return MonteCarloResult(
        zero_names=tuple(name for name in chain.error_names if name not in names),
        worst_rad=worst,
        error_names=names,
        upper_bounds_rad=upper,
        lower_bounds_rad=lower,
        limits=limits,
        n=n,
        seed=seed,
        joint_names=tuple(chain.joint_names),
        grid_steps_deg=steps,
        evaluated_deg=evaluated,
        max_dependence=tuple(float(d) for d in dependence),
        elapsed_s=elapsed,
        workers=workers,
    )


def run_monte_carlo(
    upper_bounds_rad,
    limits: OrientationLimits,
    n: int,
    seed: int,
    *,
    table=None,
    lower_bounds_rad=None,
    grid_step_deg: float | None = None,
    workers: int = 1,
    progress: bool = True,
) -> MonteCarloResult:
    """:func:`run_chain_monte_carlo` on a
    :class:`~turntable_pin.model.generic_table.GenericTable` (its angular errors drawn, its lengths
    0) over the same grid on every joint; a joint no drawn table depends on is evaluated at 0
    only.

    Args:
        upper_bounds_rad, lower_bounds_rad: (P,) bounds of the table's angular errors
            (``table.angular_names`` order; lower default 0), radians.
        table: the table (default the bundled one).
        grid_step_deg: the grid step (default by table: 1, 5, 15 deg when its first-order model
            depends on 1, 2, 3 joints).
        limits, n, seed, workers, progress: as :func:`run_chain_monte_carlo`.
    """
    table = resolve_table(table)
    step = check_grid_step(table, grid_step_deg)
    result = run_chain_monte_carlo(
        table.chain,
        table.angular_names,
        upper_bounds_rad,
        limits,
        n,
        seed,
        grid_steps_deg=(step,) * len(table.joint_names),
        lower_bounds_rad=lower_bounds_rad,
        workers=workers,
        progress=progress,
    )
    return replace(
        result, urdf=str(table.urdf_path), payload_frame=table.payload_frame,
        angle_names=tuple(table.angle_names),
    )  # fmt: skip

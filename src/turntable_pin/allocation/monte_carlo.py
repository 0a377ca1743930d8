"""Monte Carlo check of an allocation with the exact Pinocchio chain (paper Figure 9).

N random turntables are drawn inside the allocated box: each angular error gets a magnitude uniform
in ``[LB_i, UB_i]`` and a random sign (the intersection error is left at 0: it moves the payload
origin, never its orientation). Each turntable's exact ``dR`` is evaluated on a dense grid of phi2
through :class:`OrientationErrorField` (coefficients read off the Pinocchio placements). With the
errors of Table 2 ``dR`` does not depend on phi1 at all; the run checks that on every chunk (the
phi1 harmonics of the coefficients) and, should some effect make it depend on phi1, evaluates a phi1
grid as well. The result keeps each turntable's largest ``|dpsi|, |dtheta|, |dgamma|``.

Chunks draw their samples from ``SeedSequence(seed).spawn(...)``, so the result depends on the seed
only, not on the number of worker processes. Worker processes never outlive the run: on an error or
an interruption (SIGINT, SIGTERM) they are killed at once, not waited for; Ctrl-C, which reaches
the whole process group, is left to the parent.

The run's machinery is shared with the Monte Carlo of any table (:mod:`.table_monte_carlo`):
:func:`check_run` (the box, the count, the seed), :func:`signed_magnitudes` (the draw),
:func:`chunk_plan` (chunks and their seeds), :func:`run_chunks` (the workers) and
:class:`MonteCarloSummary` (the verdict and its JSON form).
"""

from __future__ import annotations

import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..core.exceptions import InputError, check_seed
from ..core.interrupts import deferred, register_cleanup, signals_blocked, worker_initializer
from ..core.progress import Progress
from ..core.sizes import MAX_MONTE_CARLO_TURNTABLES, check_count
from ..core.units import DEG_PER_RAD, arcmin_by_name
from ..model.batch_field import ANGLE_ENTRIES, OrientationErrorField
from ..model.errors import ANGULAR_ERROR_NAMES, ERROR_NAMES
from ..model.turntable import TurntableModel
from .solver import ORIENTATION_ANGLES, OrientationLimits

__all__ = [
    "TURNTABLE_BYTES",
    "CHUNK_SIZE",
    "PHI1_TOLERANCE",
    "MonteCarloResult",
    "MonteCarloSummary",
    "check_run",
    "chunk_plan",
    "phi1_dependence",
    "run_chunks",
    "run_monte_carlo",
    "sample_errors",
    "signed_magnitudes",
]

CHUNK_SIZE = 2000  # turntables per block: the (chunk, 3, 360) intermediates stay small

TURNTABLE_BYTES = 64
"""Memory a turntable of the run keeps (its three worst angles, its share of the tasks), bytes."""

# Relative size of phi1 harmonics in dR below which phi1 is taken to drop out (rounding of the
# 5x5 trigonometric fit is ~1e-16 of the largest coefficient, which is ~1).
PHI1_TOLERANCE = 1e-12


def signed_magnitudes(
    rng: np.random.Generator, n: int, upper_bounds_rad, lower_bounds_rad
) -> np.ndarray:
    """(n, P) errors of magnitude uniform in [LB, UB] and random sign (magnitudes drawn first,
    then signs)."""
    upper = np.asarray(upper_bounds_rad, dtype=float)
    lower = np.asarray(lower_bounds_rad, dtype=float)
    magnitudes = rng.uniform(lower, upper, size=(n, upper.size))
    signs = rng.choice(np.array([-1.0, 1.0]), size=(n, upper.size))
    return magnitudes * signs


def sample_errors(
    rng: np.random.Generator, n: int, upper_bounds_rad, lower_bounds_rad
) -> np.ndarray:
    """(n, 9) error sets: magnitudes uniform in [LB, UB], random signs, deta = 0."""
    drawn = signed_magnitudes(rng, n, upper_bounds_rad, lower_bounds_rad)
    values = np.zeros((n, len(ERROR_NAMES)))
    values[:, : drawn.shape[1]] = drawn
    return values


def check_run(
    upper_bounds_rad, lower_bounds_rad, n: int, seed, size: int, size_message: str, *, finite=False
) -> tuple[np.ndarray, np.ndarray, int]:
    """The box ``(upper, lower)`` (lower default 0) and the seed of a run, checked.

    Raises:
        InputError: not ``size`` bounds each (``size_message``), an upper bound not finite (when
            ``finite``), a lower bound outside ``[0, upper]``, fewer than 1 or too many tables,
            a bad seed.
    """
    upper = np.asarray(upper_bounds_rad, dtype=float).reshape(-1)
    lower = (
        np.zeros_like(upper) if lower_bounds_rad is None else np.asarray(lower_bounds_rad, float)
    )
    if upper.size != size or lower.shape != upper.shape:
        raise InputError(size_message)
    if finite and not np.all(np.isfinite(upper)):
        raise InputError("every upper bound must be a finite number")
    if np.any(lower > upper) or np.any(lower < 0.0):
        raise InputError("every lower bound must be between 0 and its upper bound")
    if n < 1:
        raise InputError(f"the number of turntables must be at least 1, got {n}")
    check_count(n, MAX_MONTE_CARLO_TURNTABLES, "random turntables", TURNTABLE_BYTES)
    return upper, lower, check_seed(seed)


def chunk_plan(n: int, chunk_size: int, seed: int) -> tuple[list[int], list]:
    """The sizes of the chunks of ``n`` tables (``chunk_size`` each, the rest last) and each
    chunk's ``SeedSequence`` (spawned from ``seed``: the result depends on the seed only)."""
    sizes = [chunk_size] * (n // chunk_size) + ([n % chunk_size] if n % chunk_size else [])
    return sizes, np.random.SeedSequence(seed).spawn(len(sizes))


def phi1_dependence(field: OrientationErrorField) -> float:
    """Largest coefficient of a phi1 harmonic in dpsi, dtheta, dgamma (0 when phi1 drops out)."""
    c = field.coefficients
    return float(max(np.abs(c[:, i, j, 1:, :]).max() for i, j in ANGLE_ENTRIES))


@lru_cache(maxsize=4)
def _nominal_model(urdf_path: str | None) -> TurntableModel:
    """One nominal model per process and URDF (chunks only read its placements)."""
    return TurntableModel(urdf_path=urdf_path)


def _run_chunk(args) -> tuple[np.ndarray, float]:
    """Worker: sample one chunk and return each turntable's max |angle| (n, 3) and phi1 check."""
    seed_seq, n, upper, lower, phi2_grid_rad, phi1_grid_rad, urdf_path = args
    rng = np.random.default_rng(seed_seq)
    values = sample_errors(rng, n, upper, lower)
    field = OrientationErrorField.from_error_values(values, _nominal_model(urdf_path))
    dependence = phi1_dependence(field)
    phi1_values = [0.0] if dependence <= PHI1_TOLERANCE else phi1_grid_rad
    worst = np.zeros((n, 3))
    for phi1 in phi1_values:
        angles = field.angles_on_phi2_grid(phi1, phi2_grid_rad)  # (n, 3, M)
        np.maximum(worst, np.maximum(angles.max(axis=2), -angles.min(axis=2)), out=worst)
    return worst, dependence


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


def _chunk_results(worker, tasks, sizes, workers: int, progress: bool):
    """Yield ``worker(task)`` of every task in order, in this process (``workers == 1``) or in
    a pool of ``workers`` processes, reporting the turntables done (``sizes``) on stderr.

    The workers never outlive the run (see the module docstring).
    """
    pools: list[ProcessPoolExecutor] = []
    # Registered before the workers start: an interruption at any moment still stops them.
    unregister = register_cleanup(lambda: _stop_workers(pools))
    try:
        with Progress(int(sum(sizes)), "Monte Carlo", enabled=progress) as bar:
            if workers == 1:
                results = map(worker, tasks)
            else:
                # Workers start with SIGINT/SIGTERM blocked and set up their own handling.
                with deferred(), signals_blocked():
                    pools.append(
                        ProcessPoolExecutor(max_workers=workers, initializer=worker_initializer)
                    )
                    # Not pool.map: its generator cancels the futures when interrupted, and
                    # Python 3.11's pool then fails (a traceback) marking them broken.
                    futures = [pools[0].submit(worker, task) for task in tasks]
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


def run_chunks(worker, tasks, sizes, workers: int, progress: bool):
    """Run ``worker(task) -> (worst (size, 3), extra)`` on every task, in this process or in at
    most ``workers`` processes (never more than the CPUs or the tasks; see the module docstring).

    Returns ``(worst (N, 3) in task order, [extra of each task], workers used, elapsed s)``.
    """
    workers = max(1, min(int(workers), os.cpu_count() or 1, len(tasks)))
    start = time.perf_counter()
    worst = np.empty((int(sum(sizes)), 3))
    extras = []
    offset = 0
    for (chunk_worst, extra), size in zip(
        _chunk_results(worker, tasks, sizes, workers, progress), sizes, strict=True
    ):
        worst[offset : offset + size] = chunk_worst
        extras.append(extra)
        offset += size
    return worst, extras, workers, time.perf_counter() - start


class MonteCarloSummary:
    """What every Monte Carlo result (fields ``worst_rad``, ``limits``, ``n``, ``seed``,
    ``elapsed_s``, ``workers`` and an ``evaluations`` count) says alike."""

    @property
    def max_abs_rad(self) -> np.ndarray:
        """(3,) largest |dpsi|, |dtheta|, |dgamma| over all tables and positions."""
        return self.worst_rad.max(axis=0)

    @property
    def all_within(self) -> bool:
        """Whether every table stays within the limits on every angle."""
        return bool(np.all(self.max_abs_rad <= self.limits.as_array()))

    def verdict_dict(self) -> dict:
        """Largest angles and limits (arcmin), the verdict, tables over each limit, n and seed."""
        limits = self.limits.as_array()
        return {
            "max_abs_arcmin": arcmin_by_name(ORIENTATION_ANGLES, self.max_abs_rad),
            "limits_arcmin": self.limits.to_dict(),
            "all_within": self.all_within,
            "n_exceeding": dict(
                zip(
                    ORIENTATION_ANGLES,
                    map(int, np.sum(self.worst_rad > limits, axis=0)),
                    strict=True,
                )
            ),
            "n": self.n,
            "seed": self.seed,
        }

    def timing_dict(self) -> dict:
        """Wall time (s), evaluations per second and workers, JSON-ready."""
        return {
            "elapsed_s": self.elapsed_s,
            "evaluations_per_s": self.evaluations / max(self.elapsed_s, 1e-12),
            "workers": self.workers,
        }


@dataclass(frozen=True)
class MonteCarloResult(MonteCarloSummary):
    """The outcome of :func:`run_monte_carlo`.

    Attributes:
        worst_rad: (N, 3) each turntable's largest |dpsi|, |dtheta|, |dgamma| over the grid, rad.
        upper_bounds_rad, lower_bounds_rad: (8,) the box sampled.
        limits: the orientation limits checked against.
        n, seed: sample size and the seed that reproduces it.
        phi2_step_deg: grid step of phi2.  phi1_evaluated_deg: the phi1 values evaluated.
        max_phi1_dependence: largest phi1 harmonic found in any turntable's dR.
        elapsed_s: wall time.  workers: processes used.
    """

    worst_rad: np.ndarray
    upper_bounds_rad: np.ndarray
    lower_bounds_rad: np.ndarray
    limits: OrientationLimits
    n: int
    seed: int
    phi2_step_deg: float
    phi1_evaluated_deg: tuple[float, ...]
    max_phi1_dependence: float
    elapsed_s: float
    workers: int

    @property
    def evaluations(self) -> int:
        """Turntable x angle-pair evaluations done."""
        return self.n * int(round(360.0 / self.phi2_step_deg)) * len(self.phi1_evaluated_deg)

    def to_dict(self) -> dict:
        """The outcome as a JSON-ready dict (angles in arcmin, steps in degrees, time in s)."""
        return {
            **self.verdict_dict(),
            "sampling": "magnitude uniform in [lower, upper] bound, random sign; deta = 0",
            "upper_bounds_arcmin": arcmin_by_name(ANGULAR_ERROR_NAMES, self.upper_bounds_rad),
            "lower_bounds_arcmin": arcmin_by_name(ANGULAR_ERROR_NAMES, self.lower_bounds_rad),
            "phi2_step_deg": self.phi2_step_deg,
            "phi1_evaluated_deg": list(self.phi1_evaluated_deg),
            "max_phi1_dependence": self.max_phi1_dependence,
            **self.timing_dict(),
        }


def run_monte_carlo(
    upper_bounds_rad,
    limits: OrientationLimits,
    n: int,
    seed: int,
    *,
    lower_bounds_rad=None,
    phi2_step_deg: float = 1.0,
    phi1_step_deg: float = 10.0,
    workers: int = 1,
    progress: bool = True,
    urdf_path=None,
) -> MonteCarloResult:
    """Evaluate ``n`` random turntables inside the box and compare with ``limits``.

    Args:
        upper_bounds_rad, lower_bounds_rad: (8,) bounds of the magnitudes (lower default 0).
        limits: orientation limits.  n: number of turntables.  seed: random seed (recorded).
        phi2_step_deg: phi2 grid step over the whole turn.
        phi1_step_deg: phi1 grid step, used only if dR turns out to depend on phi1.
        workers: processes (the result does not depend on it).  progress: report on stderr.
        urdf_path: nominal URDF (default bundled).
    """
    count = len(ANGULAR_ERROR_NAMES)
    message = f"expected {count} upper and lower bounds"
    upper, lower, seed = check_run(upper_bounds_rad, lower_bounds_rad, n, seed, count, message)
    for name, step in (("phi2", phi2_step_deg), ("phi1", phi1_step_deg)):
        if not 0.0 < step <= 90.0:
            raise InputError(f"{name} grid step must be in (0, 90] degrees, got {step}")
    phi2_grid = np.arange(0.0, 360.0, phi2_step_deg) / DEG_PER_RAD
    phi1_grid = np.arange(0.0, 360.0, phi1_step_deg) / DEG_PER_RAD
    urdf = None if urdf_path is None else str(urdf_path)
    sizes, seeds = chunk_plan(n, CHUNK_SIZE, seed)
    tasks = [
        (s, size, upper, lower, phi2_grid, phi1_grid, urdf)
        for s, size in zip(seeds, sizes, strict=True)
    ]
    worst, dependences, workers, elapsed = run_chunks(_run_chunk, tasks, sizes, workers, progress)
    dependence = max([0.0, *dependences])
    phi1_used = (0.0,) if dependence <= PHI1_TOLERANCE else tuple(phi1_grid * DEG_PER_RAD)
    return MonteCarloResult(
        worst_rad=worst,
        upper_bounds_rad=upper,
        lower_bounds_rad=lower,
        limits=limits,
        n=n,
        seed=seed,
        phi2_step_deg=phi2_step_deg,
        phi1_evaluated_deg=phi1_used,
        max_phi1_dependence=dependence,
        elapsed_s=elapsed,
        workers=workers,
    )

"""Monte Carlo check of an allocation: seconds, tables per second and memory, and the ratio to the
per-chunk evaluation the package used before (issue 18).

Run by hand:  python benchmarks/bench_montecarlo.py [--paper-n 1000000] [--three-n 100000]
                  [--workers 1 2] [--seed 1] [--old-chunks 5]

Two runs, each with every worker count, each in a fresh process (its peak memory is its own):

- paper: the paper's table allocated with the paper's inputs (Table 4), 10^6 tables on a 1-degree
  phi2 grid (360 positions; phi1 drops out);
- three: ``models/three_axis_imu_table.urdf`` allocated for its default limits, 10^5 tables on a
  15-degree grid over its three joints (24^3 = 13,824 positions).

The results must be identical for every worker count (same seed): checked. Then, in this process
with one BLAS thread, the first ``--old-chunks`` chunks of each run (the same tables: the seed of
chunk i is the i-th spawned one) are evaluated by the new path and by a private copy of the one
before (the chain composed at 5^J angles and the basis inverted for each chunk's coefficients,
then products with the basis of the grid); their times per table give the ratio, and the largest
difference of the two results must stay below 1e-12 rad.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import resource
import subprocess
import sys
import time

import numpy as np

from turntable_pin.allocation.monte_carlo import (
    CHUNK_SIZE,
    run_chain_monte_carlo,
    sample_errors,
)
from turntable_pin.allocation.solver import OrientationLimits, allocate_tolerances
from turntable_pin.core.blas_threads import one_blas_thread
from turntable_pin.core.resources import models_dir
from turntable_pin.core.units import ARCMIN_PER_RAD
from turntable_pin.model.angles import ANGLE_ENTRIES
from turntable_pin.model.batch_field import trig_basis
from turntable_pin.model.chain import compose_rotation
from turntable_pin.model.errors import ANGULAR_ERROR_NAMES
from turntable_pin.model.generic_table import GenericTable
from turntable_pin.model.paper_table import paper_table

THREE_AXIS = "three_axis_imu_table.urdf"
THREE_LIMITS_ARCMIN = (0.6112299121, 0.2660663146, 0.4608392377)  # its `allocate` default


def _setup(case: str) -> dict:
    """The chain, the drawn errors, their box and limits, the grid and the chunk size of a run."""
    if case == "paper":
        allocation = allocate_tolerances(
            OrientationLimits.from_arcmin(1.4801, 1.56, 1.4801), "paper"
        )
        return {
            "chain": paper_table().chain,
            "names": ANGULAR_ERROR_NAMES,
            "upper": allocation.upper_bounds_rad,
            "lower": allocation.capability.lower_bounds_rad,
            "limits": allocation.limits,
            "steps": (10.0, 1.0),
            "chunk": CHUNK_SIZE,
            "phi1_drops": True,
        }
    table = GenericTable(models_dir() / THREE_AXIS)
    allocation = allocate_tolerances(
        OrientationLimits.from_arcmin(*THREE_LIMITS_ARCMIN), table=table
    )
    return {
        "chain": table.chain,
        "names": table.angular_names,
        "upper": allocation.upper_bounds_rad,
        "lower": allocation.lower_bounds_rad,
        "limits": allocation.limits,
        "steps": (15.0,) * 3,
        "chunk": CHUNK_SIZE,
        "phi1_drops": False,
    }


def _run(setup: dict, n: int, seed: int, workers: int = 1, progress: bool = False):
    return run_chain_monte_carlo(
        setup["chain"], setup["names"], setup["upper"], setup["limits"], n, seed,
        grid_steps_deg=setup["steps"], lower_bounds_rad=setup["lower"],
        chunk_size=setup["chunk"], workers=workers, progress=progress,
    )  # fmt: skip


def _rss_mb(field: str) -> float:
    """``VmRSS`` or ``VmHWM`` (peak) of this process, MB (Linux)."""
    with open("/proc/self/status", encoding="ascii") as status:
        line = next(line for line in status if line.startswith(field))
    return int(line.split()[1]) / 1024


def _cpu_s() -> float:
    """CPU seconds of this process and of its ended children."""
    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def _one_case(spec: str) -> None:
    """Child process: one run, printed as a JSON line (memory: the run's peak resident set,
    from the resident set before it; the workers' largest peak)."""
    case, n, workers, seed = spec.split(",")
    setup = _setup(case)
    _run(setup, 10, int(seed))  # imports and first-call work out of the figures
    with open("/proc/self/clear_refs", "w", encoding="ascii") as refs:
        refs.write("5")  # peak resident set := resident set now
    before_mb, cpu = _rss_mb("VmRSS"), _cpu_s()
    result = _run(setup, int(n), int(seed), int(workers), progress=True)
    print(
        json.dumps(
            {
                "wall_s": result.elapsed_s,
                "cpu_s": _cpu_s() - cpu,
                "rss_before_mb": before_mb,
                "peak_mb": _rss_mb("VmHWM"),
                "worker_peak_mb": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024,
                "evaluations": result.evaluations,
                "positions": result.evaluations // result.n,
                "max_arcmin": list(result.max_abs_rad * ARCMIN_PER_RAD),
                "digest": hashlib.sha256(result.worst_rad.tobytes()).hexdigest(),
            }
        )
    )


# ---- the per-chunk evaluation before issue 18 (private copy, for the ratio) -------------------

_GRID_RAD = 2.0 * np.pi * np.arange(5) / 5
_BASIS_INV = np.linalg.inv(trig_basis(_GRID_RAD))


def _old_coefficients(chain, values: np.ndarray) -> np.ndarray:
    """(K, 3, 5^J): the chain composed on a 5^J grid of angles, the basis inverted there."""
    n_joints = len(chain.joints)
    grid = np.meshgrid(*([_GRID_RAD] * n_joints), indexing="ij")
    lead = (slice(None),) + (None,) * n_joints
    rt = compose_rotation([(p[lead], a) for p, a in chain.placements(values)], grid)
    rd = compose_rotation([(p[None][lead], a) for p, a in chain.placements()], grid)
    d_r = np.swapaxes(rd, -1, -2) @ rt
    grid_in, grid_out = "abc"[:n_joints], "mno"[:n_joints]
    inputs = [f"{grid_out[0]}{grid_in[0]}", f"k{grid_in}ij"]
    inputs += [f"{o}{i}" for o, i in zip(grid_out[1:], grid_in[1:], strict=True)]
    operands = [_BASIS_INV, d_r] + [_BASIS_INV] * (n_joints - 1)
    c = np.einsum(f"{','.join(inputs)}->kij{grid_out}", *operands)
    return np.stack([c[:, i, j] for i, j in ANGLE_ENTRIES], axis=1).reshape(len(values), 3, -1)


def _old_chunk(setup: dict, values: np.ndarray) -> np.ndarray:
    """Each table's largest |angle| as the package computed it before (phi1 dropped on the
    paper's table; one product with the Kronecker basis of 1024 grid positions at a time)."""
    c = _old_coefficients(setup["chain"], values)
    grids = [np.radians(np.arange(0.0, 360.0, step)) for step in setup["steps"]]
    if setup["phi1_drops"]:  # the paper's: phi2 grid at phi1 = 0
        per_phi2 = np.einsum("m,kemn->ken", trig_basis(0.0), c.reshape(-1, 3, 5, 5))
        angles = per_phi2 @ trig_basis(grids[1]).T
        return np.maximum(angles.max(axis=2), -angles.min(axis=2))
    mesh = [m.ravel() for m in np.meshgrid(*grids, indexing="ij")]
    flat = c.reshape(-1, c.shape[2])
    worst = np.zeros(flat.shape[0])
    for start in range(0, mesh[0].size, 1024):
        rows = [trig_basis(a[start : start + 1024]).T for a in mesh]
        basis = rows[0]
        for b in rows[1:]:
            basis = (basis[:, None, :] * b[None, :, :]).reshape(-1, b.shape[1])
        np.maximum(worst, np.abs(flat @ basis).max(axis=1), out=worst)
    return worst.reshape(-1, 3)


def _ratio(case: str, chunks: int, seed: int) -> str:
    """Old and new path on the first ``chunks`` chunks of a run, one process, one BLAS thread."""
    setup = _setup(case)
    n = chunks * setup["chunk"]
    with one_blas_thread():
        start = time.process_time()
        new = _run(setup, n, seed).worst_rad
        new_s = time.process_time() - start
        seeds = np.random.SeedSequence(seed).spawn(chunks)
        start = time.process_time()
        old = np.concatenate(
            [
                _old_chunk(
                    setup,
                    sample_errors(
                        np.random.default_rng(s),
                        setup["chunk"],
                        setup["upper"],
                        setup["lower"],
                        setup["chain"].error_names,
                        setup["names"],
                    ),  # fmt: skip
                )
                for s in seeds
            ]
        )
        old_s = time.process_time() - start
    gap = float(np.abs(new - old).max())
    if gap > 1e-12:
        raise SystemExit(f"{case}: the new path differs from the old one by {gap:.2e} rad")
    return (
        f"{case}: {n} tables ({chunks} chunks), one process: before {old_s / n * 1e6:.2f} s, "
        f"now {new_s / n * 1e6:.2f} s CPU per 10^6 tables -> {old_s / new_s:.1f}x; "
        f"largest difference {gap:.1e} rad"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--paper-n", type=int, default=1_000_000)
    parser.add_argument("--three-n", type=int, default=100_000)
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--old-chunks", type=int, default=5)
    parser.add_argument("--case", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.case:
        _one_case(args.case)
        return
    print(f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.1f}, seed {args.seed}")
    head = ("run", "tables", "positions", "workers", "wall s", "CPU s", "tables/s", "evals/s",
            "RSS->peak MB (worker)", "max |dpsi|, |dtheta|, |dgamma| arcmin")  # fmt: skip
    print(f"{head[0]:6s}{head[1]:>9s}{head[2]:>10s}{head[3]:>8s}{head[4]:>8s}{head[5]:>8s}"
          f"{head[6]:>10s}{head[7]:>10s}{head[8]:>22s}  {head[9]}")  # fmt: skip
    for case, n in (("paper", args.paper_n), ("three", args.three_n)):
        digests = set()
        for workers in args.workers:
            proc = subprocess.run(
                [sys.executable, __file__, "--case", f"{case},{n},{workers},{args.seed}"],
                capture_output=True, text=True, check=True,
            )  # fmt: skip
            out = json.loads(proc.stdout.strip().splitlines()[-1])
            digests.add(out["digest"])
            worst = ", ".join(f"{v:.4f}" for v in out["max_arcmin"])
            peak = f"{out['rss_before_mb']:.0f}->{out['peak_mb']:.0f}" + (
                f" ({out['worker_peak_mb']:.0f})" if workers > 1 else ""
            )
            print(
                f"{case:6s}{n:9d}{out['positions']:10d}{workers:8d}{out['wall_s']:8.2f}"
                f"{out['cpu_s']:8.2f}{n / out['wall_s']:10.3g}"
                f"{out['evaluations'] / out['wall_s']:10.3g}{peak:>22s}  {worst}"
            )
        if len(digests) != 1:
            raise SystemExit(f"{case}: results differ between worker counts")
    for case in ("paper", "three"):
        print(_ratio(case, args.old_chunks, args.seed))


if __name__ == "__main__":
    main()

"""Monte Carlo of the allocation check: wall time and evaluations per second.

Run by hand:  python benchmarks/bench_montecarlo.py [-n 1000000] [--workers 1 2] [--seed 1]

Allocates with the paper's inputs (Table 4), then draws ``n`` turntables inside the bounds and
evaluates each on a 1-degree phi2 grid (360 angles) with the exact chain, once per worker count.
The results must be identical for every worker count (same seed), which is checked. The CPU time
of the single-worker run is printed too: on a shared machine it is steadier than the wall time.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from turntable_pin.allocation.monte_carlo import run_monte_carlo
from turntable_pin.allocation.solver import OrientationLimits, allocate_tolerances
from turntable_pin.core.units import ARCMIN_PER_RAD


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-n", type=int, default=1_000_000)
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    allocation = allocate_tolerances(OrientationLimits.from_arcmin(1.4801, 1.56, 1.4801), "paper")
    print(f"{args.n} turntables, 1-degree phi2 grid, seed {args.seed}, {os.cpu_count()} CPUs")
    reference = None
    for workers in args.workers:
        cpu_start = time.process_time()  # this process only: meaningful for workers == 1
        result = run_monte_carlo(
            allocation.upper_bounds_rad,
            allocation.limits,
            args.n,
            args.seed,
            lower_bounds_rad=allocation.capability.lower_bounds_rad,
            phi2_step_deg=1.0,
            workers=workers,
            progress=True,
        )
        cpu_s = time.process_time() - cpu_start
        if reference is None:
            reference = result.worst_rad
        elif not np.array_equal(reference, result.worst_rad):
            raise SystemExit("results differ between worker counts")
        worst = ", ".join(
            f"{n} {v:.4f}'"
            for n, v in zip(
                ("psi", "theta", "gamma"), result.max_abs_rad * ARCMIN_PER_RAD, strict=True
            )
        )
        print(
            f"workers {workers}: {result.elapsed_s:.1f} s, "
            f"{result.evaluations / result.elapsed_s:.3g} evaluations/s "
            f"({result.n / result.elapsed_s:.3g} turntables/s); max |angle|: {worst}; "
            f"all within: {result.all_within}" + (f"; CPU {cpu_s:.1f} s" if workers == 1 else "")
        )


if __name__ == "__main__":
    main()

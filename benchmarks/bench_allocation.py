"""The one allocation on the paper's table and on 1-, 2- and 3-axis tables: time, result, check.

Run by hand:  python benchmarks/bench_allocation.py [--repeats 3]

One core (BLAS threads pinned to 1). For each table (the paper's with its Table 4 inputs and
weights, the bundled rate, vertical-outer and three-axis tables with limits 0.6', 0.25', 0.45')
prints the wall and CPU time of ``allocate_tolerances`` (median of ``--repeats``, the table and
its Pinocchio model already built), each sub-problem's method and J, and the worst case of the
final bounds against the limits: the solver's (continuous) and a direct evaluation of the
regressor on a grid much denser than the solver's starting grid (never above it).
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from turntable_pin.allocation.solver import OrientationLimits, allocate_tolerances  # noqa: E402
from turntable_pin.core.resources import default_urdf_path  # noqa: E402
from turntable_pin.core.units import ARCMIN_PER_RAD  # noqa: E402
from turntable_pin.model.paper_table import table_of  # noqa: E402

MODELS = default_urdf_path().parent
CASES = (  # urdf, limits (arcmin), weights, dense grid step (deg)
    ("turntable.urdf", (1.4801, 1.56, 1.4801), "paper", 0.05),
    ("single_axis_rate_table.urdf", (0.6, 0.25, 0.45), "model", 0.01),
    ("two_axis_vertical_outer.urdf", (0.6, 0.25, 0.45), "model", 0.5),
    ("three_axis_imu_table.urdf", (0.6, 0.25, 0.45), "model", 5.0),
)


def dense_worst(table, upper_rad, step_deg: float) -> np.ndarray:
    """``max over a full grid of sum_i |C_ki(q)| UB_i`` per angle, from the regressor, rad."""
    axis = np.radians(np.arange(0.0, 360.0 - 1e-9, step_deg))
    columns = [table.parameter_names.index(n) for n in table.angular_names]
    worst = np.zeros(3)
    d = len(table.joint_names)
    for first in np.array_split(axis, max(1, axis.size**d // 40_000)):
        mesh = np.meshgrid(first, *([axis] * (d - 1)), indexing="ij")
        c = table.regressor([m.ravel() for m in mesh])[:, :, columns]
        worst = np.maximum(worst, (np.abs(c) @ upper_rad).max(axis=0))
    return worst


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    for urdf, limits_arcmin, weights, dense_deg in CASES:
        table = table_of(MODELS / urdf)
        limits = OrientationLimits.from_arcmin(*limits_arcmin)
        allocate_tolerances(limits, weights, table=table)  # warm: caches, lazy imports
        wall, cpu = [], []
        for _ in range(args.repeats):
            t0, c0 = time.perf_counter(), time.process_time()
            allocation = allocate_tolerances(limits, weights, table=table)
            wall.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
        subs = ", ".join(f"{k} {s.method} J {s.J:.6g}" for k, s in allocation.subproblems.items())
        dense = dense_worst(table, allocation.upper_bounds_rad, dense_deg) * ARCMIN_PER_RAD
        solver = allocation.worst_case_rad * ARCMIN_PER_RAD
        print(f"{urdf}: {np.median(wall):.2f} s wall, {np.median(cpu):.2f} s CPU; {subs}")
        print(
            f"  worst case (arcmin) solver {np.round(solver, 5).tolist()}, "
            f"{dense_deg:g}-deg grid {np.round(dense, 5).tolist()}, limits {list(limits_arcmin)}"
        )


if __name__ == "__main__":
    main()

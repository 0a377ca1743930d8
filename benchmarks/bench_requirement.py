"""Timing of the orientation requirement, and how it depends on positions, latitude, definition.

Run by hand:  python benchmarks/bench_requirement.py [--repeats 3]

One core (BLAS threads pinned to 1). Prints (1) the wall time of ``orientation_requirement`` per
position scheme (median of ``--repeats``; CPU time beside it, since a shared machine inflates wall
time), (2) the README table of I_psi, I_theta, I_gamma for w_m = 0.01 deg/h over schemes,
latitudes and both rate-error definitions, (3) the Figure 4 ratios: dwx caused by dgamma alone
over dwx caused by dpsi alone, and dwy caused by dpsi over dwy caused by dgamma (0.027 deg each).
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from turntable_pin import (  # noqa: E402
    GyroWheelModel,
    IdentifiabilityError,
    PositionSet,
    orientation_requirement,
    position_inputs,
    rate_error,
)

SCHEMES = ("grid:90", "grid:60", "grid:45", "grid:30", "grid:15")
LATITUDES_DEG = (0.0, 45.75, 80.0)
DEFINITIONS = ("true_coefficients", "calibrated_coefficients")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    lat = np.radians(45.75)

    print("## timing of orientation_requirement (w_m = 0.01 deg/h, latitude 45.75, eq. 13)")
    print("| positions | n | wall s (median) | CPU s (median) |")
    print("|---|---|---|---|")
    for scheme in ("grid:90", "grid:45", "grid:30", "grid:15"):
        positions = PositionSet.parse(scheme)
        walls, cpus = [], []
        for _ in range(args.repeats):
            w0, c0 = time.perf_counter(), time.process_time()
            orientation_requirement(0.01, positions, lat)
            walls.append(time.perf_counter() - w0)
            cpus.append(time.process_time() - c0)
        print(f"| {scheme} | {len(positions)} | {np.median(walls):.2f} | {np.median(cpus):.2f} |")

    print("\n## requirement for w_m = 0.01 deg/h: I_psi / I_theta / I_gamma in degrees")
    print("| positions | latitude deg | eq. 13 as printed (beta2) | with beta1 |")
    print("|---|---|---|---|")
    for scheme in SCHEMES:
        positions = PositionSet.parse(scheme)
        for latitude in LATITUDES_DEG:
            cells = []
            for definition in DEFINITIONS:
                try:
                    r = orientation_requirement(
                        0.01, positions, np.radians(latitude), definition=definition
                    )
                except IdentifiabilityError:
                    cells.append("A rank 6: not calibratable")
                    continue
                limits = np.degrees(r.limits_rad)
                cells.append(" / ".join(f"{v:.4f}" for v in limits))
            print(f"| {scheme} | {latitude:g} | {cells[0]} | {cells[1]} |")

    print("\n## Figure 4 ratios at 0.027 deg (latitude 45.75, eq. 13 as printed)")
    print("| positions | dwx(dgamma) / dwx(dpsi) | dwy(dpsi) / dwy(dgamma) |")
    print("|---|---|---|")
    gyro = GyroWheelModel.nominal()
    h = np.radians(0.027)
    for scheme in SCHEMES:
        inputs = position_inputs(PositionSet.parse(scheme), lat)
        psi, gamma = rate_error(gyro, inputs, h, 0, 0), rate_error(gyro, inputs, 0, 0, h)
        print(
            f"| {scheme} | {gamma.dwx_dph / psi.dwx_dph:.3f} | {psi.dwy_dph / gamma.dwy_dph:.3f} |"
        )


if __name__ == "__main__":
    main()

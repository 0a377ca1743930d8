"""Timing of ``turntable-pin design`` (identify): a 24-position D-optimal design from 10^4
candidates, on the bundled tables and effect sets (the issue's target: under 10 s).

Run by hand:  python benchmarks/bench_design.py [--repeats 3] [--candidates 10000] [-n 24]

One core (BLAS threads pinned to 1). For each case it prints the wall and CPU time of
``design_identify`` with ``design_space`` (median of ``--repeats``; CPU time beside it, since a
shared machine inflates wall time), the candidates it chose from, the number of determined
combinations, the exchanges taken and the D-efficiency against the 30-degree grid.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from turntable_pin.design import design_identify, design_space  # noqa: E402
from turntable_pin.measurement.user_effects import resolve_effects  # noqa: E402
from turntable_pin.model.paper_table import table_of  # noqa: E402

MODELS = Path(__file__).resolve().parents[1] / "models"

# (label, URDF or None for the paper's table, effects, --limits-deg)
CASES = (
    ("paper, base", None, "", None),
    ("paper, 2 harmonics + drift + backlash", None,
     "inner_encoder_harmonics,outer_wobble_harmonics,thermal_drift,backlash", None),
    ("one axis, encoder harmonics", "single_axis_rate_table.urdf", "encoder_harmonics@spindle",
     None),
    ("alt-az 15..90, elevation harmonics + gravity sag", "altaz_mount.urdf",
     "encoder_harmonics@elevation,gravity_sag", "elevation=15:90"),
    ("three axes, all wobbles", "three_axis_imu_table.urdf",
     "wobble_harmonics@outer_gimbal,wobble_harmonics@middle_gimbal,"
     "wobble_harmonics@inner_gimbal", None),
    ("three axes, 11 effects with drift and backlash", "three_axis_imu_table.urdf",
     ",".join(f"{kind}@{joint}_gimbal" for kind in ("encoder_harmonics", "wobble_harmonics",
                                                    "backlash")
              for joint in ("outer", "middle", "inner")) + ",gravity_sag,thermal_drift", None),
)  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--candidates", type=int, default=10_000)
    parser.add_argument("-n", type=int, default=24)
    args = parser.parse_args()
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    print(f"## design (identify): {args.n} positions from {args.candidates} candidates (+ grid)")
    print("| case | params | combinations | exchanges | D-eff vs grid | wall s | CPU s |")
    print("|---|---|---|---|---|---|---|")
    for label, urdf, effects, limits in CASES:
        table = table_of(None if urdf is None else MODELS / urdf)
        chosen = resolve_effects([effects], table)
        walls, cpus = [], []
        for _ in range(args.repeats):
            w0, c0 = time.perf_counter(), time.process_time()
            space = design_space(table, chosen, limits_deg=limits, candidates=args.candidates)
            design = design_identify(space, args.n)
            walls.append(time.perf_counter() - w0)
            cpus.append(time.process_time() - c0)
        n_params = len(design.combinations) + len(design.undetermined)
        efficiency = "-" if design.d_efficiency is None else f"{design.d_efficiency:.3f}"
        print(f"| {label} | {n_params} | {design.rank} | {design.n_exchanges} | {efficiency} | "
              f"{np.median(walls):.2f} | {np.median(cpus):.2f} |")  # fmt: skip


if __name__ == "__main__":
    main()

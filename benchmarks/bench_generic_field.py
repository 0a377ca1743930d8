"""Batch orientation error of any table (1 to 3 axes) against per-call Pinocchio.

Run by hand:  python benchmarks/bench_generic_field.py [--tuples 1000000] [--per-call 5000]

For each bundled table (single-axis rate table, the paper's two-axis table, a two-axis table with
a vertical outer axis, a three-axis IMU table) with a random generic error set of a few arc
seconds: evaluations per second of the batch path (``OrientationErrorField.from_chain``: each dR
entry a trigonometric polynomial of degree two in every joint angle, 5^K coefficients) on one
core, median of 5 runs, and of per-call Pinocchio forward kinematics on the model with the errors
in its placements; the two are checked to agree to 1e-12 rad. Targets: at least 1e7
evaluations/s for two axes and 3e6 for three.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402

from turntable_pin import OrientationErrorField  # noqa: E402
from turntable_pin.core.resources import models_dir  # noqa: E402
from turntable_pin.model.generic_table import GenericTable  # noqa: E402

TABLES = (
    "single_axis_rate_table.urdf",
    "turntable.urdf",
    "two_axis_vertical_outer.urdf",
    "three_axis_imu_table.urdf",
)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tuples", type=int, default=1_000_000)
    parser.add_argument("--per-call", type=int, default=5_000)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})
    rng = np.random.default_rng(args.seed)
    print(f"seed {args.seed}, {args.tuples} random joint-angle tuples, one core")
    head = ("table", "axes", "batch evals/s", "Pinocchio/s", "max gap rad")
    print(f"{head[0]:32s}{head[1]:>5s}{head[2]:>15s}{head[3]:>13s}{head[4]:>13s}")
    for name in TABLES:
        table = GenericTable(models_dir() / name)
        values = rng.uniform(-2e-5, 2e-5, len(table.parameter_names))
        field = OrientationErrorField.from_chain(table.chain, values[None])
        angles = [rng.uniform(0.0, 2 * np.pi, args.tuples) for _ in table.joint_names]
        field.angles(*(a[:1000] for a in angles))  # warm-up
        times = []
        for _ in range(5):
            t0 = time.perf_counter()
            batch = field.angles(*angles)[0]
            times.append(time.perf_counter() - t0)
        rate = args.tuples / float(np.median(times))

        model, nominal = table.pinocchio_model(values), table.nominal_pin_model
        data, ndata = model.createData(), nominal.createData()
        frame = model.getFrameId(table.payload_frame)
        n = min(args.per_call, args.tuples)
        per_call = np.empty((n, 3))
        t0 = time.perf_counter()
        for i in range(n):
            q = table.chain.joint_vector(*(a[i] for a in angles))
            pin.framesForwardKinematics(model, data, q)
            pin.framesForwardKinematics(nominal, ndata, q)
            dR = ndata.oMf[frame].rotation.T @ data.oMf[frame].rotation
            per_call[i] = dR[0, 2], dR[1, 0], dR[2, 1]
        rate_pin = n / (time.perf_counter() - t0)
        gap = float(np.abs(batch[:n] - per_call).max())
        axes = len(table.joint_names)
        print(f"{name:32s}{axes:5d}{rate:15.3e}{rate_pin:13.3e}{gap:13.2e}")
        if gap > 1e-12:
            raise SystemExit(f"{name}: batch and Pinocchio disagree by {gap:.2e} rad")


if __name__ == "__main__":
    main()

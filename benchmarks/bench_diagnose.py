"""Wall time of diagnosing a 144-position measurement file against the whole effect catalogue.

Run by hand:  python benchmarks/bench_diagnose.py [--repeats 5] [--seed 1]

One core (BLAS threads pinned to 1). For each hidden effect of the catalogue (and clean data) a
30-degree grid is simulated; the file is written and the timing covers reading it and the full
diagnosis (base fit, nine candidates, alternatives with separation advice, structure search);
``--until-explained`` is timed too. Target: under 2 s per file.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from turntable_pin import TurntableErrors  # noqa: E402
from turntable_pin.measurement.data import read_measurements  # noqa: E402
from turntable_pin.measurement.diagnosis import diagnose_measurements  # noqa: E402
from turntable_pin.measurement.simulation import simulate_measurements  # noqa: E402

HIDDEN = {
    "none": {},
    "outer_encoder_harmonics": {"c1": 3.0, "s2": -2.0},
    "inner_encoder_harmonics": {"c1": 3.0, "s2": -2.0},
    "outer_wobble_harmonics": {"x_c1": 3.0, "z_s2": -2.0},
    "inner_wobble_harmonics": {"x_c2": 3.0, "y_s2": -2.0},
    "gravity_sag": {"k": 3.0},
    "base_tilt": {"tx": 3.0, "tz": -2.0},
    "thermal_drift": {"rz": 1.5, "ry": -1.0, "rx": 0.5},
    "backlash": {"b1": 3.0, "b2": -2.0},
    "payload_mount": {"mx": 3.0, "my": 2.0, "mz": 1.0},
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    errors = TurntableErrors.from_arcsec(
        dphi_y1=5, dphi_z2=-3, dalpha_x1=2, dalpha_z1=4, dalpha_x2=-6, dalpha_y2=3, deps_x=7,
        deps_y=-2,
    )  # fmt: skip
    diagnose_measurements(simulate_measurements(seed=0).data)  # warm-up (URDF load, imports)
    print(f"{'hidden effect':26s} {'verdict':26s} {'median s':>9s} {'until s':>8s}")
    medians = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, params in HIDDEN.items():
            sim = simulate_measurements(errors, {name: params} if params else {}, seed=args.seed)
            path = sim.write_csv(Path(tmp) / f"{name}.csv")
            times, until = [], []
            for _ in range(args.repeats):
                start = time.perf_counter()
                verdict = diagnose_measurements(read_measurements(path)).missing_effect
                times.append(time.perf_counter() - start)
                start = time.perf_counter()
                diagnose_measurements(read_measurements(path), until_explained=True)
                until.append(time.perf_counter() - start)
            medians.append(np.median(times))
            print(f"{name:26s} {str(verdict):26s} {np.median(times):9.3f} {np.median(until):8.3f}")
    print(f"worst median {max(medians):.3f} s, mean {np.mean(medians):.3f} s (target < 2 s)")


if __name__ == "__main__":
    main()

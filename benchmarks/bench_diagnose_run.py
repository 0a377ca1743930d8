"""Wall time of diagnosing a GyroWheel calibration run against the whole run catalogue.

Run by hand:  python benchmarks/bench_diagnose_run.py [--positions 10000] [--repeats 3]

One core (BLAS threads pinned to 1). For clean runs and runs with one hidden effect (a table
error, an instrument tilt, a bias drift), N random positions of the paper's table are simulated
(``simulate_calibration_run``), written as a run CSV, and the timing covers reading it and the
whole diagnosis with its structured result (base fit, 22 candidates, outliers, structure search,
the other side, the table from the run). Target: a 10^4-position run in under 5 s.
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

from turntable_pin.calibration.positions import PositionSet  # noqa: E402
from turntable_pin.calibration.run import read_run  # noqa: E402
from turntable_pin.instrument.diagnosis import diagnose_run  # noqa: E402
from turntable_pin.instrument.simulate import simulate_calibration_run  # noqa: E402

LATITUDE_RAD = np.radians(45.75)
HIDDEN = {
    "none": {},
    "table:deps_x": {"table_errors_rad": {"deps_x": np.radians(20 / 3600)}},
    "instrument_tilt": {"instrument": {"instrument_tilt": {"mx": 30.0, "my": -20.0}}},
    "bias_drift": {"instrument": {"bias_drift": {"x": 0.002, "y": -0.001}}},
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--positions", type=int, default=10_000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    positions = PositionSet(rng.uniform(-np.pi, np.pi, (args.positions, 2)), name="random")
    time_s = np.arange(args.positions) * 30.0
    with tempfile.TemporaryDirectory() as folder:
        for name, hidden in HIDDEN.items():
            sim = simulate_calibration_run(
                positions, LATITUDE_RAD, noise_dph=(0.002, 0.002), seed=args.seed,
                time_s=time_s, **hidden,
            )  # fmt: skip
            path = sim.write_csv(Path(folder) / f"{name.replace(':', '_')}.csv")
            times = []
            for _ in range(args.repeats):
                start = time.perf_counter()
                run = read_run(path, LATITUDE_RAD)
                result = diagnose_run(run).to_dict()
                times.append(time.perf_counter() - start)
            print(
                f"{args.positions} positions, hidden {name:16s}: best {min(times):.2f} s, "
                f"median {np.median(times):.2f} s -> {result['verdict']['missing_effect']}"
            )


if __name__ == "__main__":
    main()

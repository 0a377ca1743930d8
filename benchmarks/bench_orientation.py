"""Orientation-error evaluations per second: per-call Pinocchio, per-call yourdfpy, batch path.

Run by hand:  python benchmarks/bench_orientation.py [--pairs 1000000] [--per-call-pairs 20000]

One core (CPU affinity and BLAS threads pinned to 1). The per-call loops run on the first
``--per-call-pairs`` of the pairs (a million yourdfpy calls would take over an hour); the batch path
runs on all of them. All three are checked to agree on the common pairs.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from turntable_pin import (  # noqa: E402
    OrientationErrorField,
    TurntableErrors,
    YourdfpyTurntable,
)
from turntable_pin.model.paper_table import paper_table  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=1_000_000)
    parser.add_argument("--per-call-pairs", type=int, default=20_000)
    parser.add_argument("--yourdfpy-pairs", type=int, default=2_000)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})

    rng = np.random.default_rng(args.seed)
    errors = TurntableErrors.from_arcsec(
        dphi_y1=2.0, dphi_z2=-1.5, dalpha_x1=3.0, dalpha_z1=-2.5,
        dalpha_x2=1.8, dalpha_y2=-2.2, deps_x=4.0, deps_y=-3.0, deta_mm=0.2,
    )  # fmt: skip
    table, values = paper_table(), errors.as_array()
    phi1, phi2 = rng.uniform(0.0, 2 * np.pi, size=(2, args.pairs))
    print(f"seed {args.seed}, {args.pairs} random angle pairs, one core")

    field = OrientationErrorField.from_chain(table.chain, values[None])
    field.angles(phi1[:1000], phi2[:1000])  # warm-up
    batch_times = []
    for _ in range(5):
        t0 = time.perf_counter()
        batch = field.angles(phi1, phi2)[0]
        batch_times.append(time.perf_counter() - t0)
    t_batch = float(np.median(batch_times))
    t0 = time.perf_counter()
    field = OrientationErrorField.from_chain(table.chain, values[None])
    t_setup = time.perf_counter() - t0

    n_pin = min(args.per_call_pairs, args.pairs)
    t0 = time.perf_counter()
    per_call = np.array(
        [
            table.orientation_error(values, (a, b)).dR
            for a, b in zip(phi1[:n_pin], phi2[:n_pin], strict=True)
        ]
    )
    t_pin = time.perf_counter() - t0

    n_yd = min(args.yourdfpy_pairs, args.pairs)
    with tempfile.TemporaryDirectory() as tmp:
        other = YourdfpyTurntable(table.write_urdf(values, os.path.join(tmp, "t.urdf")))
        t0 = time.perf_counter()
        yd = np.array(
            [
                other.orientation_error_matrix(a, b)
                for a, b in zip(phi1[:n_yd], phi2[:n_yd], strict=True)
            ]
        )
        t_yd = time.perf_counter() - t0

    pin_angles = per_call[:, [0, 1, 2], [2, 0, 1]]
    yd_angles = yd[:, [0, 1, 2], [2, 0, 1]]
    gap_pin = np.abs(batch[:n_pin] - pin_angles).max()
    gap_yd = np.abs(pin_angles[:n_yd] - yd_angles).max()
    rate_batch = args.pairs / t_batch
    rate_pin = n_pin / t_pin
    rate_yd = n_yd / t_yd
    print(f"{'path':28s}{'pairs':>10s}{'seconds':>10s}{'evals/s':>14s}")
    print(f"{'per-call Pinocchio':28s}{n_pin:10d}{t_pin:10.3f}{rate_pin:14.3e}")
    print(f"{'per-call yourdfpy':28s}{n_yd:10d}{t_yd:10.3f}{rate_yd:14.3e}")
    print(f"{'batch (trig coefficients)':28s}{args.pairs:10d}{t_batch:10.3f}{rate_batch:14.3e}")
    print(f"batch: median of 5 runs; best {args.pairs / min(batch_times):.3e} evals/s")
    print(f"batch set-up from the model: {t_setup * 1e3:.2f} ms")
    print(f"batch / per-call Pinocchio: {rate_batch / rate_pin:.0f} x")
    print(
        f"max |batch - Pinocchio| = {gap_pin:.2e} rad, "
        f"max |Pinocchio - yourdfpy| = {gap_yd:.2e} rad"
    )
    if gap_pin > 1e-12 or gap_yd > 1e-12:
        raise SystemExit("the three paths disagree by more than 1e-12 rad")


if __name__ == "__main__":
    main()

"""Wall time and peak memory of ``turntable-pin diagnose`` on a long measurement log.

Run by hand:  python benchmarks/bench_diagnose_long.py [--rows 100000] [--seed 1] [--keep DIR]

A log of ``--rows`` positions in random order (a 400 x 250 grid of the two axes for 100,000
rows, all three angles, with sigma, time_s, dir1 and dir2 columns) is simulated twice, clean and
with a hidden ``inner_encoder_harmonics``, and written to a temporary directory. Each file is
diagnosed by the command line in a child process (``diagnose FILE --json``: read, diagnose and
print the JSON), timed with the wall clock and measured for peak memory (max RSS of the child).
Targets: under 5 s wall and 500 MB peak per file. The child's CPU time (user + system) is shown
too: on a machine busy with other work the wall time also counts waiting for a core.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from turntable_pin import TurntableErrors
from turntable_pin.measurement.simulation import Schedule, simulate_measurements

HIDDEN = {"none": {}, "inner_encoder_harmonics": {"c1": 3.0, "s2": -2.0}}


def _grid(rows: int) -> tuple[int, int]:
    """Two grid counts whose product is ``rows`` (as square as possible, outer axis larger)."""
    best = (rows, 1)
    for b in range(1, math.isqrt(rows) + 1):
        if rows % b == 0:
            best = (rows // b, b)
    return best


def _run(path: Path, folder: Path) -> tuple[float, float, float, dict]:
    """Wall seconds, CPU seconds (user + system), peak RSS (MB) and JSON of
    ``diagnose path --json`` in a child process."""
    out_path = folder / f"{path.stem}.json"
    start = time.perf_counter()
    with out_path.open("w") as out:
        child = subprocess.Popen(
            [sys.executable, "-m", "turntable_pin", "diagnose", str(path), "--json"], stdout=out
        )
        _, status, usage = os.wait4(child.pid, 0)  # this child's own rusage
    wall = time.perf_counter() - start
    child.returncode = os.waitstatus_to_exitcode(status)
    if child.returncode:
        raise SystemExit(f"diagnose failed on {path} (exit {child.returncode})")
    cpu = usage.ru_utime + usage.ru_stime
    return wall, cpu, usage.ru_maxrss / 1024.0, json.loads(out_path.read_text())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=100_000)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--keep", help="write the files to this directory and keep them")
    args = parser.parse_args()
    n1, n2 = _grid(args.rows)
    schedule = Schedule(360.0 / n1, 360.0 / n2, order="random", dwell_s=30.0)
    errors = TurntableErrors.from_arcsec(
        dphi_y1=5, dphi_z2=-3, dalpha_x1=2, dalpha_z1=4, dalpha_x2=-6, dalpha_y2=3, deps_x=7,
        deps_y=-2,
    )  # fmt: skip
    print(f"{args.rows} rows ({n1} x {n2} grid, random order)")
    print(f"{'hidden effect':26s} {'verdict':26s} {'wall s':>7s} {'cpu s':>6s} {'peak MB':>8s}")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(args.keep or tmp)
        folder.mkdir(parents=True, exist_ok=True)
        for name, params in HIDDEN.items():
            sim = simulate_measurements(
                errors, {name: params} if params else {}, schedule=schedule, seed=args.seed
            )
            path = sim.write_csv(folder / f"long_{name}.csv")
            wall, cpu, peak, out = _run(path, folder)
            verdict = out["verdict"]["missing_effect"]
            print(f"{name:26s} {str(verdict):26s} {wall:7.2f} {cpu:6.2f} {peak:8.0f}")
    print("targets: < 5 s wall, < 500 MB peak (max RSS of the child); the wall time includes")
    print("waiting for the CPU when other work runs (cpu s: the child's own user + system time)")


if __name__ == "__main__":
    main()

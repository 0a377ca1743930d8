"""Time the command line's start-up: ``turntable-pin --help`` and one ``orientation`` call.

Run by hand: ``python benchmarks/bench_startup.py [--repeat 10]``. Each run is a fresh child
process (``python -m turntable_pin``), timed by wall clock; prints the median and the range, and
which heavy libraries each command imported (``-X importtime``). Targets (issue: a light import):
``--help`` under 0.3 s, ``orientation`` under 0.6 s on an idle machine.
"""

import argparse
import statistics
import subprocess
import sys
import time

COMMANDS = {
    "--help": ["--help"],
    "orientation": ["orientation", "--phi1-deg", "30", "--phi2-deg", "45", "--error", "dphi_y1=3"],
}
HEAVY = ("numpy", "scipy", "pinocchio", "matplotlib", "yourdfpy", "meshcat", "yaml")


def imported_heavy(args: list[str]) -> list[str]:
    """The heavy top-level libraries a command imports."""
    proc = subprocess.run(
        [sys.executable, "-X", "importtime", "-m", "turntable_pin", *args],
        capture_output=True, text=True, check=True,
    )  # fmt: skip
    names = {line.split("|")[-1].strip() for line in proc.stderr.splitlines() if "|" in line}
    return sorted(h for h in HEAVY if h in names)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=10)
    args = parser.parse_args()
    for label, argv in COMMANDS.items():
        times = []
        for _ in range(args.repeat):
            start = time.perf_counter()
            subprocess.run([sys.executable, "-m", "turntable_pin", *argv],
                           capture_output=True, check=True)  # fmt: skip
            times.append(time.perf_counter() - start)
        print(
            f"{label:12s} median {statistics.median(times):.3f} s  "
            f"(min {min(times):.3f}, max {max(times):.3f}, n={len(times)})  "
            f"imports: {', '.join(imported_heavy(argv)) or 'none of ' + ', '.join(HEAVY)}"
        )


if __name__ == "__main__":
    main()

"""A GyroWheel calibration run: the table or the instrument? Residuals before and after.

Reads the bundled blind run ``models/examples/runs/run_mount.csv`` (144 positions of the
paper's table, 0.002 deg/h noise, something hidden), diagnoses it against the run catalogue (the
table's errors and effects through eqs. 8-13, the instrument's tilt, heading, drift, temperature
coefficient, earth-rate scale and g-squared terms), and plots both outputs' residuals of the
plain calibration beside those with the effect it names, against the position, each joint
angle and time, with their harmonics. The HTML report of the same diagnosis is written beside
them.
"""

import sys
from pathlib import Path

import numpy as np

from turntable_pin.calibration.run import read_run
from turntable_pin.core.resources import examples_dir
from turntable_pin.instrument.diagnosis import diagnose_run
from turntable_pin.report.html_report import write_report
from turntable_pin.report.measurement_figures import write_diagnosis_plots


def main(out_dir: Path, fast: bool = False) -> list[Path]:
    out_dir = Path(out_dir) / "run_diagnosis"  # its residuals.png is not the orientation one's
    run = read_run(examples_dir() / "runs" / "run_mount.csv", np.radians(45.75))
    diagnosis = diagnose_run(run)
    paths = [Path(p) for p in write_diagnosis_plots(diagnosis, out_dir)]
    write_report(diagnosis, out_dir / "run_report.html", title="bundled calibration run")
    return paths


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--fast"]
    main(Path(args[0]) if args else Path("figures"), fast="--fast" in sys.argv)

"""Residuals of the bundled measurement example before and after adding the diagnosed effect.

Reads ``models/examples/measurements_example.csv`` (144 positions, a hidden effect), runs the
diagnosis, and plots the residuals of the base model beside those of base + the effects it names
(against position, phi1, phi2, time and approach direction), with their harmonic content per axis.
The HTML report of the same diagnosis is written beside them.
"""

import sys
from pathlib import Path

from turntable_pin.core.resources import models_dir
from turntable_pin.measurement.data import read_measurements
from turntable_pin.measurement.diagnosis import diagnose_measurements
from turntable_pin.measurement.residuals import orientation_residuals
from turntable_pin.report.html_report import write_report
from turntable_pin.report.measurement_figures import write_residual_plots


def main(out_dir: Path, fast: bool = False) -> list[Path]:
    out_dir = Path(out_dir)
    data = read_measurements(models_dir() / "examples" / "measurements_example.csv")
    diagnosis = diagnose_measurements(data, until_explained=True)
    sets = [orientation_residuals(diagnosis.base_fit, "base model")]
    if diagnosis.steps:
        added = " + ".join(step.added for step in diagnosis.steps)
        sets.append(orientation_residuals(diagnosis.best_fit, f"base + {added}"))
    paths = [Path(p) for p in write_residual_plots(sets, out_dir)]
    write_report(diagnosis, out_dir / "measurement_report.html", title="bundled example")
    return paths


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--fast"]
    main(Path(args[0]) if args else Path("figures"), fast="--fast" in sys.argv)

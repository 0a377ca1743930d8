"""Numeric extremes in one line: a calibration run's time_s is capped at a year as orientation
data's are (a time of 1e308 s ended in "SVD did not converge"), and a grid step too fine to count
(1e-320 deg: OverflowError; 1e-6 deg in the Monte Carlo grid: an allocation of terabytes) is
refused naming the option or the positions, before anything is computed or written."""

import pytest

from conftest import EXAMPLES_DIR, REPO_DIR, cli, refused, write_file


@pytest.mark.parametrize("mode", [[], ["--diagnose"], ["--effects", "bias_drift"]])
def test_a_run_whose_time_reaches_1e308_is_refused_like_orientation_data(tmp_path, mode):
    lines = (EXAMPLES_DIR / "runs" / "run_bias_drift.csv").read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    column = lines[start].split(",").index("time_s")
    cells = lines[start + 5].split(",")
    cells[column] = "1e308"
    lines[start + 5] = ",".join(cells)
    run = write_file(tmp_path, "\n".join(lines) + "\n", "run.csv")
    refused(cli("calibrate", str(run), *mode), f"{run}, row {start + 6}, column 'time_s': time "
              "since the start of the run must be at most 3.16224e+07 s (a year)")  # fmt: skip


URDF = str(REPO_DIR / "models" / "three_axis_imu_table.urdf")


@pytest.mark.parametrize(
    "args, words",
    [
        (["simulate", "--phi1-step-deg", "1e-320"], ["--phi1-step-deg", "[1e-06, 360]"]),
        (["simulate", "--phi2-step-deg", "1e-320"], ["--phi2-step-deg"]),
        (["simulate", "--phi3-step-deg", "5e-324"], ["--phi3-step-deg"]),
        (["simulate", "--sweep", "phi1", "--phi1-step-deg", "1e-6"], ["rows of simulated"]),
        (["simulate", "--run", "--positions", "grid:1e-320"], ["positions 'grid:1e-320'"]),
        (["rate-error", "--positions", "grid:1e-320", "--dpsi-deg", "0.01"], ["grid:1e-320"]),
        (
            ["requirement", "--accuracy-dph", "0.01", "--positions", "grid:1e-320x30"],
            ["grid:1e-320x30"],
        ),  # fmt: skip
        (["montecarlo", "--limits-arcmin", "1", "--grid-step-deg", "1e-320"], ["--grid-step-deg"]),
        (
            ["montecarlo", "--limits-arcmin", "1", "--quiet", "--grid-step-deg", "1e-6"],
            ["a 1e-06-degree grid over 1 joints", "choose a coarser --grid-step-deg"],
        ),  # fmt: skip
        (
            ["allocate", "--limits-arcmin", "2", "--urdf", URDF, "--grid-step-deg", "1e-320"],
            ["--grid-step-deg"],
        ),  # fmt: skip
        (
            ["montecarlo", "--limits-arcmin", "2", "--urdf", URDF, "--grid-step-deg", "1e-6"],
            ["choose a coarser --grid-step-deg"],
        ),  # fmt: skip
    ],
)
def test_a_grid_step_too_fine_to_count_is_one_line(tmp_path, args, words):
    out = tmp_path / "out.csv"
    if args[0] == "simulate":
        args = [*args, "-o", str(out)]
    refused(cli(*args), *words)
    assert not out.exists()

"""``rate-error``, ``requirement``, ``calibrate`` on the command line: keys, files, bad input."""

import json

import numpy as np
import pytest

from conftest import EXAMPLES_DIR, cli, write_file
from turntable_pin import GyroWheelModel, PositionSet, position_inputs, rate_error

EXAMPLE = EXAMPLES_DIR / "gyrowheel_run_example.csv"


def test_rate_error_json_matches_the_library():
    proc = cli(
        "rate-error", "--dpsi-deg", "0.02", "--dtheta-deg", "0.01", "--dgamma-deg", "-0.015",
        "--positions", "grid:90", "--latitude-deg", "45.75", "--json",
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    inputs = position_inputs(PositionSet.parse("grid:90"), np.radians(45.75))
    expected = rate_error(GyroWheelModel.nominal(), inputs, *np.radians([0.02, 0.01, -0.015]))
    assert out["dwx_dph"] == pytest.approx(expected.dwx_dph, rel=1e-12)
    assert out["dwy_dph"] == pytest.approx(expected.dwy_dph, rel=1e-12)
    assert out["positions"] == "grid:90" and out["latitude_deg"] == 45.75


def test_rate_error_text_output():
    proc = cli("rate-error", "--dpsi-deg", "0.02", "--positions", "grid:45", "--exact")
    assert proc.returncode == 0, proc.stderr
    assert "dwx = " in proc.stdout and "exact rotation" in proc.stdout


@pytest.mark.slow
def test_requirement_json_and_plots(tmp_path):
    plots = tmp_path / "figs"
    proc = cli(
        "requirement", "--accuracy-dph", "0.01", "--positions", "grid:45",
        "--latitude-deg", "45.75", "--json", "--plots", str(plots),
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    for key in ("I_psi_deg", "I_theta_deg", "I_gamma_deg"):
        assert 0 < out[key] < 0.1
    for name in ("figure4_rate_errors.png", "figure5_requirement.png"):
        data = (plots / name).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 20_000


def test_calibrate_example_json():
    proc = cli("calibrate", str(EXAMPLE), "--latitude-deg", "45.75", "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["x"]["coefficients_dph"]["DF"] == pytest.approx(-93.3, abs=0.01)
    assert out["y"]["coefficients_dph"]["yx"] == pytest.approx(47.8, abs=0.01)
    assert set(out["x"]["standard_errors_dph"]) == {"DF", "x", "y", "z", "xx", "zz", "xy"}
    assert len(out["residuals"]) == 64
    assert out["x"]["condition_number"] > 1


def test_calibrate_text_report():
    proc = cli("calibrate", str(EXAMPLE))
    assert proc.returncode == 0, proc.stderr
    assert "DxDF" in proc.stdout and "res_x_dph" in proc.stdout


@pytest.mark.parametrize(
    "content, fragment",
    [
        (
            "phi1_deg,phi2_deg,out_x_dph,out_y_dph\n"
            + "".join(f"{p},{q},1,2\n" for p, q in [(0, 0), (90, 0), (180, 0), (270, 0), (90, 90),
                                                    (90, 0), (0, 360), (90, 270)]),
            "too few distinct positions: 6",
        ),
        ("phi1_deg,phi2_deg,out_x_dph\n0,0,1\n", "missing required column(s) 'out_y_dph'"),
        ("phi1_deg,phi2_deg,out_x_dph,out_y_dph\n0,0,1,2\n0,90,NaN,2\n",
         "row 3, column 'out_x_dph': expected a finite number"),
    ],
)  # fmt: skip
def test_calibrate_bad_runs_exit_2(tmp_path, content, fragment):
    proc = cli("calibrate", str(write_file(tmp_path, content, "run.csv")))
    assert proc.returncode == 2
    assert fragment in proc.stderr
    assert "run.csv" in proc.stderr
    assert "Traceback" not in proc.stderr


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["rate-error", "--positions", "grid:0"], "grid step must be in [1e-06, 360]"),
        (["rate-error", "--dpsi-deg", "nan"], "--dpsi-deg: expected a finite number"),
        (["requirement", "--accuracy-dph", "0"], "expected a number > 0"),
        (["requirement", "--positions", "grid:90", "--definition", "calibrated_coefficients"],
         "rank 6 < 7"),
        (["rate-error", "--latitude-deg", "100"], "latitude must be within +-90"),
        (["rate-error", "--gyrowheel", "/no/such.yaml"], "cannot read the file"),
    ],
)  # fmt: skip
def test_bad_arguments_exit_2(args, fragment):
    proc = cli(*args)
    assert proc.returncode == 2
    assert fragment in proc.stderr
    assert "Traceback" not in proc.stderr

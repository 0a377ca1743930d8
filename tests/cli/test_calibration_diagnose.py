"""``calibrate --diagnose`` and ``calibrate --effects`` on the command line: the verdict first,
the JSON, the plots and the HTML page, the refusals in plain words."""

from __future__ import annotations

import json

import pytest

from conftest import EXAMPLES_DIR, REPO_DIR, cli, temperature_run, write_file

RUNS = EXAMPLES_DIR / "runs"
MODELS_DIR = REPO_DIR / "models"


def test_diagnose_text_opens_with_the_verdict_and_names_the_side():
    proc = cli("calibrate", str(RUNS / "run_bias_drift.csv"), "--diagnose")
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0].startswith("Missing effect: bias_drift [instrument]")
    assert "  side: the instrument (the GyroWheel itself, not the table)" in lines
    assert any(line.startswith("coefficients of the final model") for line in lines)
    assert any(line.startswith("the table from the run:") for line in lines)


def test_diagnose_json_plots_and_report(tmp_path):
    plots, report = tmp_path / "plots", tmp_path / "run.html"
    proc = cli("calibrate", str(RUNS / "run_orthogonality.csv"), "--diagnose", "--json",
               "--plots", str(plots), "--report", str(report))  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    verdict = out["verdict"]
    assert verdict["side"] == "table"
    assert verdict["missing_effect"] in {"table:deps_x", "table:dalpha_x1"}
    for key in ("candidates", "steps", "outliers", "coefficients_dph", "table_from_run"):
        assert key in out
    assert {p.rsplit("/", 1)[-1] for p in out["plots"]} >= {"residuals.png", "harmonics.png"}
    page = report.read_text()
    assert page.startswith("<!DOCTYPE html>") and "Missing effect:" in page
    assert "data:image/png;base64," in page


def test_structure_found_is_given_as_a_calibrate_command(tmp_path):
    """A term no catalogued effect has (a 3/rev of the inner angle on out_x) is named as a
    shape, with the calibrate --effects command that adds it; that command takes it away."""
    import numpy as np

    from turntable_pin.calibration.positions import PositionSet
    from turntable_pin.instrument.simulate import simulate_calibration_run

    positions = PositionSet.grid(30)
    sim = simulate_calibration_run(positions, np.radians(45.75), noise_dph=0.002, seed=2)
    extra = 0.008 * np.cos(3 * positions.angles_rad[:, 1])
    columns = sim.columns()
    columns["out_x_dph"] = columns["out_x_dph"] + extra
    from turntable_pin.core.csv_table import write_csv_table

    path = write_csv_table(tmp_path / "run.csv", columns)
    proc = cli("calibrate", str(path), "--diagnose")
    assert proc.returncode == 0, proc.stderr
    assert "out_x 3/rev in phi2" in proc.stdout
    command = next(line for line in proc.stdout.splitlines() if "fit with what remains" in line)
    assert "turntable-pin calibrate" in command and "out_x~h3(phi2)" in command
    fit = cli("calibrate", str(path), "--effects", "out_x~h3(phi2)", "--json")
    assert fit.returncode == 0, fit.stderr
    assert json.loads(fit.stdout)["chi2_reduced"] < 1.3


def test_effects_text_shows_before_and_after():
    proc = cli("calibrate", str(RUNS / "run_g_squared.csv"), "--effects", "g_squared_terms")
    assert proc.returncode == 0, proc.stderr
    assert "before: base" in proc.stdout and "after: base + g_squared_terms" in proc.stdout
    assert "g_squared_terms.x_xz" in proc.stdout


@pytest.mark.parametrize(
    "args, message",
    [
        (["--report", "x.html"], "--report goes with --diagnose"),
        (["--plots", "d"], "--plots goes with --diagnose or --effects"),
        (["--diagnose", "--effects", "bias_drift"], "give one of them"),
        (["--effects", "nonsense"], "unknown run effect 'nonsense'"),
        (["--effects", "temperature_coefficient"], "needs the column(s) temperature_c"),
    ],
)
def test_bad_option_combinations_exit_2_with_one_line(args, message):
    proc = cli("calibrate", str(RUNS / "run_clean.csv"), *args)
    assert proc.returncode == 2
    assert message in proc.stderr and "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_refusal_on_the_vertical_outer_table_says_the_physical_reason_first(tmp_path):
    rows = "\n".join(f"{a},{b},1.0,2.0" for a in range(0, 360, 30) for b in range(0, 360, 30))
    path = write_file(tmp_path, "phi1_deg,phi2_deg,out_x_dph,out_y_dph\n" + rows + "\n")
    proc = cli("calibrate", str(path), "--urdf", str(MODELS_DIR / "two_axis_vertical_outer.urdf"))
    assert proc.returncode == 2
    message = proc.stderr
    reason = "gravity's x component along the GyroWheel stays 0 g at every position"
    assert reason in message
    assert message.index(reason) < message.index("cannot determine")


def test_diagnose_on_the_vertical_outer_table_warns_instead_of_refusing(tmp_path):
    import numpy as np

    from turntable_pin.calibration.positions import PositionSet
    from turntable_pin.instrument.simulate import simulate_calibration_run
    from turntable_pin.model.generic_table import GenericTable

    table = GenericTable(MODELS_DIR / "two_axis_vertical_outer.urdf")
    sim = simulate_calibration_run(PositionSet.grid(30, table=table), np.radians(45.75),
                                   noise_dph=0.002, seed=1)  # fmt: skip
    path = sim.write_csv(tmp_path / "run.csv")
    proc = cli("calibrate", str(path), "--urdf", str(MODELS_DIR / "two_axis_vertical_outer.urdf"),
               "--diagnose", "--json")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert any("gravity's x component" in w for w in out["warnings"])
    assert out["verdict"]["missing_effects"] == []


USER_EFFECT = """
import numpy as np

from turntable_pin.instrument.effects import RunEffect
from turntable_pin.instrument.effects.base import ParameterSpec


class CableDrag(RunEffect):
    name = "cable_drag"
    side = "table"
    title = "the slip-ring cable drags the inner frame"
    explanation = "A cable wound around the inner axis pulls harder one way than the other."
    confirm = "Turn the inner axis back and forth with the cable unplugged."

    def parameters(self, run):
        return (ParameterSpec("b", "deg/h", 1.0, "drag amplitude"),)

    def columns(self, context):
        out = np.zeros((context.run.n_positions, 2, 1))
        out[:, 0, 0] = np.sin(context.run.joint_rad[:, 1]) * np.cos(context.run.joint_rad[:, 0])
        return out
"""


def test_a_run_effect_the_user_writes_is_diagnosed_and_fitted(tmp_path):
    import numpy as np

    from turntable_pin.calibration.positions import PositionSet
    from turntable_pin.core.csv_table import write_csv_table
    from turntable_pin.instrument.simulate import simulate_calibration_run

    module = write_file(tmp_path, USER_EFFECT, "cable.py")
    positions = PositionSet.grid(30)
    sim = simulate_calibration_run(positions, np.radians(45.75), noise_dph=0.002, seed=4)
    columns = sim.columns()
    a = positions.angles_rad
    columns["out_x_dph"] = columns["out_x_dph"] + 0.006 * np.sin(a[:, 1]) * np.cos(a[:, 0])
    path = write_csv_table(tmp_path / "run.csv", columns)
    proc = cli("calibrate", str(path), "--diagnose", "--effects-module", str(module), "--json")
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["verdict"]["missing_effect"] == "cable_drag"
    fit = cli("calibrate", str(path), "--effects", "cable_drag", "--effects-module", str(module),
              "--json")  # fmt: skip
    assert fit.returncode == 0, fit.stderr
    value = json.loads(fit.stdout)["params"]["cable_drag.b"]
    assert abs(value["value"] - 0.006) < 4 * value["std"]
    design = cli(
        "design",
        "--separate",
        "cable_drag,instrument_tilt",
        "--run",
        str(path),
        "--effects-module",
        str(module),
        "-n",
        "3",
        "--candidates",
        "300",
        "--json",
    )
    assert design.returncode == 0, design.stderr
    assert json.loads(design.stdout)["effects"] == ["cable_drag", "instrument_tilt"]
    empty = write_file(tmp_path, "X = 1\n", "none.py")
    bad = cli("calibrate", str(path), "--diagnose", "--effects-module", str(empty))
    assert bad.returncode == 2 and "turntable_pin.instrument.effects.RunEffect" in bad.stderr


@pytest.mark.parametrize("option", ["--report", "--plots"])
def test_an_output_onto_the_run_is_refused_and_the_run_kept(tmp_path, option):
    import shutil

    run = tmp_path / "run.csv"
    shutil.copy(RUNS / "run_clean.csv", run)
    before = run.read_bytes()
    proc = cli("calibrate", str(run), "--diagnose", option, str(run))
    assert proc.returncode == 2
    assert "it is the data file" in proc.stderr and "Traceback" not in proc.stderr
    assert run.read_bytes() == before


def test_a_text_cell_among_temperatures_exits_2_instead_of_a_wrong_verdict(tmp_path):
    """Issue 27: 'warm' in one temperature_c cell dropped the column: exit 0, verdict
    bias_drift, and "temperature_c ... absent from the run"."""
    path = temperature_run(tmp_path, lambda row, text: "warm" if row == 17 else text)
    proc = cli("calibrate", str(path), "--diagnose")
    assert proc.returncode == 2 and proc.stdout == ""
    assert "row 17, column 'temperature_c': 'warm' is not a number" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_text_columns_are_warned_of_and_never_called_absent(tmp_path):
    path = temperature_run(tmp_path, lambda row, text: "n/a", note="fine")
    proc = cli("calibrate", str(path), "--diagnose")
    assert proc.returncode == 0, proc.stderr
    warning = f"warning: {path}: column(s) temperature_c, note ignored: not numbers"
    assert warning in proc.stderr
    line = next(s for s in proc.stdout.splitlines() if "temperature_coefficient " in s)
    assert "not testable" in line and "present in the run but not numbers" in line
    assert "absent" not in line
    proc = cli("calibrate", str(path), "--effects", "temperature_coefficient")
    assert proc.returncode == 2 and "present in the run but not numbers" in proc.stderr
    proc = cli("calibrate", str(path), "--json")
    assert proc.returncode == 0 and warning in proc.stderr

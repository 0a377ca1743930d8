"""A calibration run is refused, naming file, row and column, when a row is copied or a value is
beyond its physical range (absurd outputs used to give nan residuals with exit status 0)."""

import pytest

from conftest import EXAMPLES_DIR, cli, write_file
from turntable_pin.calibration.drift_fit import calibrate_run, simulate_run
from turntable_pin.calibration.gyrowheel import GyroWheelModel
from turntable_pin.calibration.positions import PositionSet, position_inputs
from turntable_pin.calibration.run import MAX_RUN_OUTPUT_DPH, MIN_RUN_SIGMA_DPH
from turntable_pin.core.exceptions import InputError

RUN = (EXAMPLES_DIR / "gyrowheel_run_example.csv").read_text()
LATITUDE = 0.8


def _lines():
    lines = RUN.splitlines()
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    return lines, header


def _with_cell(tmp_path, data_row: int, column: str, value: str):
    lines, header = _lines()
    cells = lines[header + 1 + data_row].split(",")
    cells[lines[header].split(",").index(column)] = value
    lines[header + 1 + data_row] = ",".join(cells)
    return write_file(tmp_path, "\n".join(lines) + "\n", "run.csv")


def test_the_limits():
    assert MAX_RUN_OUTPUT_DPH == 1e6 and MIN_RUN_SIGMA_DPH == 1e-9


def test_a_copied_row_is_refused_like_the_measurement_reader(tmp_path):
    lines, header = _lines()
    lines.append(lines[header + 3])
    path = write_file(tmp_path, "\n".join(lines) + "\n", "run.csv")
    with pytest.raises(InputError) as info:
        calibrate_run(path, LATITUDE)
    assert str(info.value) == (
        f"{path}, row {len(lines)}, column 'phi1_deg': the same position as row {header + 4} "
        "(phi1_deg, phi2_deg all equal); a copied row counts one measurement twice (repeats must "
        "differ in time_s)"
    )


def test_repeats_at_different_times_are_fine(tmp_path):
    lines, header = _lines()
    body = [f"{line},{10.0 * k}" for k, line in enumerate(lines[header + 1 :])]
    repeat = lines[header + 3] + ",9999"
    text = "\n".join([lines[header] + ",time_s", *body, repeat]) + "\n"
    result = calibrate_run(write_file(tmp_path, text, "run.csv"), LATITUDE)
    assert len(result.inputs) == len(body) + 1


@pytest.mark.parametrize(
    "column, value, fragment",
    [
        ("out_x_dph", "1e308", "must be within +-1e+06 deg/h, found 1e+308"),
        ("out_y_dph", "-2e6", "must be within +-1e+06 deg/h"),
        ("sigma_dph", "1e-300", "sigma_dph must be at least 1e-09 deg/h"),
        ("sigma_dph", "1e7", "must be within +-1e+06 deg/h"),
        ("phi2_deg", "1e308", "a commanded angle must be within +-3600 deg"),
    ],
)
def test_absurd_values_are_refused(tmp_path, column, value, fragment):
    path = _with_cell(tmp_path, 4, column, value)
    with pytest.raises(InputError) as info:
        calibrate_run(path, LATITUDE)
    assert fragment in str(info.value)
    assert str(info.value).startswith(f"{path}, row ")
    proc = cli("calibrate", str(path))
    assert proc.returncode == 2 and len(proc.stderr.splitlines()) == 1
    assert "nan" not in proc.stdout


def test_simulate_run_checks_seed_and_noise():
    inputs = position_inputs(PositionSet.grid(90, 45), LATITUDE)
    model = GyroWheelModel.nominal()
    with pytest.raises(InputError, match="seed must be a whole number"):
        simulate_run(model, inputs, noise_dph=0.1, seed=-1)
    with pytest.raises(InputError, match=r"noise_dph must be in \[0, 1e\+06\]"):
        simulate_run(model, inputs, noise_dph=1e308, seed=1)
    assert simulate_run(model, inputs, noise_dph=0.0, seed=0)["out_x_dph"].size == len(inputs)

"""The run simulator against independent constructions: eq. 1 at the ideal inputs, the paper's
Table 1 back from a calibration, the first-order (small-angle) prediction of tiny table errors,
closed forms of the instrument effects; seeds, refusals, the CLI and the bundled blind runs."""

from __future__ import annotations

import shlex

import numpy as np
import pytest

from conftest import EXAMPLES_DIR, REPO_DIR, cli
from turntable_pin.calibration.drift_fit import calibrate
from turntable_pin.calibration.gyrowheel import GyroWheelModel
from turntable_pin.calibration.positions import PositionSet, position_inputs
from turntable_pin.calibration.rate_error import orientation_error_rotation
from turntable_pin.calibration.run import read_run
from turntable_pin.core.exceptions import InputError
from turntable_pin.core.files import read_yaml
from turntable_pin.core.units import arcsec_to_rad, deg_to_rad
from turntable_pin.instrument.simulate import (
    TemperatureProfile,
    simulate_calibration_run,
)
from turntable_pin.model.paper_table import paper_table

LATITUDE_RAD = deg_to_rad(45.75)
RUNS = sorted((EXAMPLES_DIR / "truth" / "runs").glob("*.yaml"))


@pytest.fixture(scope="module")
def grid30() -> PositionSet:
    return PositionSet.parse("grid:30")


@pytest.fixture(scope="module")
def clean(grid30):
    return simulate_calibration_run(grid30, LATITUDE_RAD)


def _with(grid30, **kw) -> np.ndarray:
    return simulate_calibration_run(grid30, LATITUDE_RAD, **kw).outputs_dph


def test_clean_noise_free_run_is_eq1_at_the_ideal_inputs(grid30, clean):
    inputs = position_inputs(grid30, LATITUDE_RAD)
    expected = GyroWheelModel.nominal().outputs_dph(inputs.specific_force_g, inputs.earth_rate_dph)
    np.testing.assert_allclose(clean.outputs_dph, expected, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(clean.outputs_dph, clean.exact_outputs_dph)


def test_calibrating_a_clean_noise_free_run_returns_table_1(grid30, clean):
    result = calibrate(position_inputs(grid30, LATITUDE_RAD), *clean.outputs_dph.T)
    nominal = GyroWheelModel.nominal()
    for axis in ("x", "y"):
        np.testing.assert_allclose(
            result.axis(axis).coefficients_dph, nominal.axis(axis).as_array(), rtol=0, atol=1e-9
        )


def test_tiny_table_errors_change_the_outputs_as_the_small_angle_model_says(grid30, clean):
    """Exact chain vs a0 Rd (I + [r]x), r the first-order angles of the table's regressor."""
    table = paper_table()
    rng = np.random.default_rng(7)
    values = {n: 1e-7 * rng.choice([-1.0, 1.0]) for n in table.angular_names}
    run = simulate_calibration_run(grid30, LATITUDE_RAD, table_errors_rad=values)
    change = run.outputs_dph - clean.outputs_dph
    first_order = table.regressor(list(grid30.angles_rad.T)) @ table.values(values)  # (N, 3)
    small = orientation_error_rotation(*first_order.T)  # I + [r]x
    inputs = position_inputs(grid30, LATITUDE_RAD)
    a = np.einsum("nj,njk->nk", inputs.specific_force_g, small)
    w = np.einsum("nj,njk->nk", inputs.earth_rate_dph, small)
    predicted = GyroWheelModel.nominal().outputs_dph(a, w) - clean.outputs_dph
    assert np.max(np.abs(change)) > 1e-6  # the errors do show
    np.testing.assert_allclose(change, predicted, rtol=0, atol=1e-10)


def test_a_table_effect_goes_through_the_exact_chain(grid30, clean):
    """Zero effect parameters change nothing; a tiny wobble acts as its first-order angles."""
    from turntable_pin.measurement.catalogue import resolve_effect
    from turntable_pin.measurement.effect_model import OrientationModel
    from turntable_pin.measurement.effects.base import PositionVariables
    from turntable_pin.measurement.table import measured_table

    errors = {"deps_x": arcsec_to_rad(5.0)}
    plain = _with(grid30, table_errors_rad=errors)
    zero = _with(grid30, table_errors_rad=errors,
                 table_effects={"inner_wobble_harmonics": {"x_c1": 0.0}})  # fmt: skip
    np.testing.assert_allclose(zero, plain, rtol=0, atol=1e-12)

    tiny_arcsec = 0.02  # 1e-7 rad
    wobble = _with(grid30, table_effects={"inner_wobble_harmonics": {"x_c1": tiny_arcsec}})
    table = measured_table(paper_table())
    effect = resolve_effect("inner_wobble_harmonics", table)
    variables = PositionVariables(np.array(grid30.angles_rad), time_s=np.zeros(len(grid30)))
    model = OrientationModel(variables, [effect], table)
    angles = model.predict(
        model.parameter_vector({"inner_wobble_harmonics.x_c1": arcsec_to_rad(tiny_arcsec)})
    )
    small = orientation_error_rotation(*angles.T)
    inputs = position_inputs(grid30, LATITUDE_RAD)
    a = np.einsum("nj,njk->nk", inputs.specific_force_g, small)
    w = np.einsum("nj,njk->nk", inputs.earth_rate_dph, small)
    predicted = GyroWheelModel.nominal().outputs_dph(a, w)
    assert np.max(np.abs(wobble - clean.outputs_dph)) > 1e-6
    np.testing.assert_allclose(wobble, predicted, rtol=0, atol=1e-10)


def test_a_mount_rotation_about_z_changes_out_x_by_the_closed_form(grid30):
    m = arcsec_to_rad(100.0)
    run = simulate_calibration_run(
        grid30, LATITUDE_RAD, instrument={"instrument_heading": {"mz": 100.0}}
    )
    inputs = position_inputs(grid30, LATITUDE_RAD)
    (ax, ay, az), (wx, _, _) = inputs.specific_force_g.T, inputs.earth_rate_dph.T
    wy = inputs.earth_rate_dph[:, 1]
    c, s = np.cos(m), np.sin(m)
    ax2, ay2 = ax * c + ay * s, -ax * s + ay * c  # row vector a Rz(m)
    df, kx, ky, kz, kxx, kzz, kxy = GyroWheelModel.nominal().x.values_dph
    expected = (wx * c + wy * s) + df + kx * ax2 + ky * ay2 + kz * az + kxx * ax2**2
    expected = expected + kzz * az**2 + kxy * ax2 * ay2
    np.testing.assert_allclose(run.outputs_dph[:, 0], expected, rtol=0, atol=1e-12)


def test_the_instrument_effects_add_their_closed_forms(grid30, clean):
    inputs = position_inputs(grid30, LATITUDE_RAD)
    a, w = inputs.specific_force_g, inputs.earth_rate_dph
    time_s = np.arange(len(grid30)) * 120.0
    base = clean.outputs_dph

    drift = _with(grid30, dwell_s=120.0, instrument={"bias_drift": {"x": 0.004, "y": -0.003}})
    np.testing.assert_allclose(drift - base, np.outer(time_s / 3600, [0.004, -0.003]), atol=1e-12)

    scale = _with(grid30, instrument={"earth_rate_scale": {"y": 50.0}})
    np.testing.assert_allclose(scale[:, 1] - base[:, 1], 50e-6 * w[:, 1], atol=1e-12)
    np.testing.assert_allclose(scale[:, 0], base[:, 0], atol=1e-12)

    g2 = _with(grid30, instrument={"g_squared_terms": {"x_xz": 0.03, "y_yz": -0.02}})
    np.testing.assert_allclose(g2[:, 0] - base[:, 0], 0.03 * a[:, 0] * a[:, 2], atol=1e-12)
    np.testing.assert_allclose(g2[:, 1] - base[:, 1], -0.02 * a[:, 1] * a[:, 2], atol=1e-12)

    profile = TemperatureProfile(20.0, 1.0, 2.5, 3.0)
    temperature = TemperatureProfile(20.0, 1.0, 2.5, 3.0).at(time_s)
    np.testing.assert_allclose(profile.at(time_s), temperature)
    thermal = simulate_calibration_run(
        grid30, LATITUDE_RAD, dwell_s=120.0, temperature_c=profile,
        instrument={"temperature_coefficient": {"x": 0.003}},
    )  # fmt: skip
    np.testing.assert_allclose(
        thermal.outputs_dph[:, 0] - base[:, 0], 0.003 * (temperature - temperature.mean()),
        atol=1e-12,
    )  # fmt: skip
    assert "temperature_c" in thermal.columns() and "temperature_c" not in clean.columns()


def test_seeds_reproduce_and_outliers_are_where_the_truth_says(grid30):
    kw = dict(noise_dph=0.002, outliers=3, seed=42)
    one = simulate_calibration_run(grid30, LATITUDE_RAD, **kw)
    two = simulate_calibration_run(grid30, LATITUDE_RAD, **kw)
    other = simulate_calibration_run(grid30, LATITUDE_RAD, **{**kw, "seed": 43})
    np.testing.assert_array_equal(one.outputs_dph, two.outputs_dph)
    assert one.truth == two.truth and one.seed == 42
    assert not np.array_equal(one.outputs_dph, other.outputs_dph)
    gross = np.abs(one.outputs_dph - one.exact_outputs_dph) > 10 * 0.002
    assert gross.sum() == 3
    for outlier in one.truth["outliers"]:
        channel = ("out_x_dph", "out_y_dph").index(outlier["column"])
        assert gross[outlier["index"], channel]
        assert abs(outlier["offset_dph"]) == pytest.approx(30 * 0.002)


@pytest.mark.parametrize(
    ("kw", "fragment"),
    [
        (dict(table_errors_rad={"deps_z": 1e-5}), "its errors: dphi_y1"),
        (dict(table_effects={"inner_wiggle": {"c1": 1}}), "inner_wiggle"),
        (dict(table_effects={"inner_wobble_harmonics": {"c1": 1}}), "x_c1"),
        (dict(instrument={"mount": {"mx": 1}}), "instrument effects: instrument_tilt"),
        (dict(instrument={"bias_drift": {"z": 1}}), "its parameters: x, y"),
        (dict(instrument={"temperature_coefficient": {"x": 1}}), "needs a temperature"),
        (dict(noise_dph=(0.1, 0.2, 0.3)), "one number or two"),
        (dict(outliers=2), "give outlier_dph"),
        (dict(seed=-1), "seed"),
    ],
)
def test_bad_names_and_values_are_refused_naming_the_known_ones(grid30, kw, fragment):
    with pytest.raises(InputError, match=fragment):
        simulate_calibration_run(grid30, LATITUDE_RAD, **kw)


def test_cli_run_writes_a_file_calibrate_reads(tmp_path):
    out = tmp_path / "run.csv"
    result = cli("simulate", "--run", "--positions", "grid:45", "--noise-dph", "0.001",
                 "--effect", "bias_drift:x=0.01", "--seed", "5", "-o", str(out),
                 "--truth", str(tmp_path / "truth.yaml"))  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[0] == f"wrote {out}: 64 positions, seed 5"
    run = read_run(out, LATITUDE_RAD)
    assert run.n_positions == 64 and run.time_s is not None
    np.testing.assert_allclose(run.sigma_dph, 0.001)
    truth = read_yaml(tmp_path / "truth.yaml")
    assert truth["instrument_effects"] == {"bias_drift": {"x": 0.01}} and truth["seed"] == 5
    assert "--truth" not in truth["command"] and truth["data"] == "run.csv"
    calibrated = cli("calibrate", str(out), "--json")
    assert calibrated.returncode == 0, calibrated.stderr


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--run", "--order", "random"], "--order is an option of orientation measurements"),
        (["--run", "--sweep", "phi1"], "--sweep is an option of orientation measurements"),
        (["--run", "--noise-arcsec", "2"], "--noise-arcsec is an option of orientation"),
        (["--noise-dph", "0.01"], "--noise-dph is an option of a calibration run"),
        (["--outliers", "2"], "--outliers is an option of a calibration run"),
        (["--run", "--effect", "nothing:x=1"], "instrument effects: instrument_tilt"),
        (["--run", "--effect", "bias_drift:x=1", "--effect", "bias_drift:y=1"], "twice"),
        (["--run", "--noise-dph", "1,2,3"], "one value or two"),
        (["--run", "--temperature", "20,1"], "START,RAMP_PER_H,SWING,PERIOD_H"),
        (["--run", "--positions", "grid:x"], "grid:STEP"),
    ],
)
def test_cli_refused_combinations_exit_2_with_one_line(args, fragment, tmp_path):
    result = cli("simulate", *args, "-o", str(tmp_path / "x.csv"))
    assert result.returncode == 2
    assert len(result.stderr.strip().splitlines()) == 1 and fragment in result.stderr
    assert not (tmp_path / "x.csv").exists()


def test_every_bundled_run_has_its_truth_and_none_tells_it():
    runs = {p.name for p in (EXAMPLES_DIR / "runs").glob("run_*.csv")}
    assert runs == {read_yaml(p)["data"] for p in RUNS} and len(runs) == 8
    for name in runs:
        comments = [ln for ln in (EXAMPLES_DIR / "runs" / name).read_text().splitlines()
                    if ln.startswith("#")]  # fmt: skip
        assert any("not recorded (--hide-truth)" in ln for ln in comments)
        assert not any(ln.startswith("# truth:") for ln in comments)


@pytest.mark.parametrize("path", RUNS, ids=lambda p: p.stem)
def test_the_truths_command_makes_the_same_run(path, tmp_path):
    truth = read_yaml(path)
    args = shlex.split(truth["command"])[1:]
    out = tmp_path / "again.csv"
    args[args.index("-o") + 1] = str(out)
    assert cli(*args).returncode == 0
    assert out.read_text() == (EXAMPLES_DIR / "runs" / truth["data"]).read_text()


@pytest.mark.parametrize("path", RUNS, ids=lambda p: p.stem)
def test_each_bundled_effect_shows_above_the_noise(path):
    """A plain calibration leaves >= 2x the noise (0.002 deg/h) on some channel, except clean."""
    truth = read_yaml(path)
    run = read_run(EXAMPLES_DIR / "runs" / truth["data"], deg_to_rad(truth["latitude_deg"]))
    result = calibrate(run.inputs, *run.outputs_dph.T)
    rms = max(np.sqrt(np.mean(result.axis(a).residuals_dph ** 2)) for a in ("x", "y"))
    if truth["data"] == "run_clean.csv":
        assert rms < 1.3 * 0.002
    else:
        assert rms >= 2.0 * 0.002


def test_make_runs_script_lists_every_run():
    script = (REPO_DIR / "models" / "examples" / "runs" / "make_runs.sh").read_text()
    for path in RUNS:
        assert f"make {path.stem} " in script


def test_cli_run_on_a_three_axis_table_with_a_table_effect(tmp_path):
    out = tmp_path / "three.csv"
    result = cli("simulate", "--run", "--urdf", "three_axis_imu_table", "--positions", "grid:45",
                 "--error", "middle_gimbal.tilt_a=10", "--effect", "instrument_heading:mz=30",
                 "--effect", "wobble_harmonics@inner_gimbal:a_c1=5", "-o", str(out))  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert cli("calibrate", str(out), "--urdf", "three_axis_imu_table").returncode == 0

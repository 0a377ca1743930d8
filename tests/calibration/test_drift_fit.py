"""Least-squares calibration (eqs. 5-6): recovery of Table 1, standard errors, identifiability."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import EXAMPLES_DIR
from turntable_pin import IdentifiabilityError, InputError
from turntable_pin.calibration.drift_fit import (
    calibrate,
    calibrate_run,
    regressor_matrix,
    simulate_run,
    write_simulated_run,
)
from turntable_pin.calibration.gyrowheel import GyroWheelModel
from turntable_pin.calibration.positions import PositionSet, position_inputs

LAT_RAD = np.radians(45.75)
EXAMPLE = EXAMPLES_DIR / "gyrowheel_run_example.csv"


@pytest.mark.parametrize("scheme", ["grid:30", "grid:45", "grid:60", "grid:45x30"])
def test_noise_free_outputs_calibrate_back_to_table_1(scheme):
    gyro = GyroWheelModel.nominal()
    inputs = position_inputs(PositionSet.parse(scheme), LAT_RAD)
    outputs = gyro.outputs_dph(inputs.specific_force_g, inputs.earth_rate_dph)
    result = calibrate(inputs, outputs[:, 0], outputs[:, 1])
    np.testing.assert_allclose(result.x.coefficients_dph, gyro.x.as_array(), rtol=0, atol=1e-9)
    np.testing.assert_allclose(result.y.coefficients_dph, gyro.y.as_array(), rtol=0, atol=1e-9)
    assert np.max(np.abs(result.x.residuals_dph)) < 1e-9
    assert 1 <= result.x.condition_number < 100
    fitted = result.model()
    np.testing.assert_allclose(fitted.y.as_array(), gyro.y.as_array(), atol=1e-9)


@given(
    phi=st.lists(
        st.tuples(st.floats(0, 360), st.floats(0, 360)), min_size=12, max_size=30, unique=True
    ),
    lat=st.floats(-80, 80),
)
@settings(max_examples=25, deadline=None)
def test_any_identifying_position_set_recovers_random_coefficients(phi, lat):
    rng = np.random.default_rng(len(phi))
    from turntable_pin.calibration.gyrowheel import DriftCoefficients

    gyro = GyroWheelModel(
        DriftCoefficients("x", tuple(rng.uniform(-100, 100, 7))),
        DriftCoefficients("y", tuple(rng.uniform(-100, 100, 7))),
    )
    p = np.radians(np.array(phi))
    inputs = position_inputs(PositionSet(p[:, 0], p[:, 1]), np.radians(lat))
    outputs = gyro.outputs_dph(inputs.specific_force_g, inputs.earth_rate_dph)
    try:
        result = calibrate(inputs, outputs[:, 0], outputs[:, 1])
    except IdentifiabilityError:
        return  # e.g. positions that all share one gravity direction
    tol = 1e-12 * result.x.condition_number**2 * 100 + 1e-9
    np.testing.assert_allclose(result.x.coefficients_dph, gyro.x.as_array(), atol=tol)
    np.testing.assert_allclose(result.y.coefficients_dph, gyro.y.as_array(), atol=tol)


def test_standard_errors_match_the_scatter_of_repeated_runs():
    gyro = GyroWheelModel.nominal()
    inputs = position_inputs(PositionSet.parse("grid:45"), LAT_RAD)
    estimates, reported, reported_unweighted = [], [], []
    for seed in range(300):
        run = simulate_run(gyro, inputs, noise_dph=0.01, seed=seed)
        fit = calibrate(inputs, run["out_x_dph"], run["out_y_dph"], run["sigma_dph"])
        estimates.append(fit.x.coefficients_dph)
        reported.append(fit.x.standard_errors_dph)
        unweighted = calibrate(inputs, run["out_x_dph"], run["out_y_dph"])
        reported_unweighted.append(unweighted.x.standard_errors_dph)
    scatter = np.std(estimates, axis=0, ddof=1)
    # 300 runs: the sample standard deviation is within ~4 * 1/sqrt(600) = 16 % of the truth.
    np.testing.assert_allclose(reported[0], scatter, rtol=0.16)
    np.testing.assert_allclose(np.mean(reported_unweighted, axis=0), scatter, rtol=0.16)
    # The mean is unbiased: within 4 standard errors of the mean of Table 1.
    assert np.all(
        np.abs(np.mean(estimates, axis=0) - gyro.x.as_array()) < 4 * scatter / np.sqrt(300)
    )


def test_too_few_distinct_positions():
    # Ten rows, but only five distinct positions (each repeated; 360 is 0).
    phi1 = np.radians([0, 30, 60, 90, 120, 360, 390, 60, 90, 120])
    phi2 = np.radians([0, 45, 90, 135, 180, 0, 45, 90, 135, 180])
    inputs = position_inputs(PositionSet(phi1, phi2), LAT_RAD)
    with pytest.raises(IdentifiabilityError, match="too few distinct positions: 5"):
        calibrate(inputs, np.zeros(10), np.zeros(10))


def test_a_90_degree_grid_has_only_six_gravity_directions():
    inputs = position_inputs(PositionSet.parse("grid:90"), LAT_RAD)
    with pytest.raises(IdentifiabilityError, match="only 6 distinct regressor rows"):
        calibrate(inputs, np.zeros(16), np.zeros(16))


def test_positions_that_never_tilt_about_x_are_rank_deficient():
    # phi2 = 0 keeps ay = 0: the ay and ax*ay columns vanish although 8 directions are distinct.
    inputs = position_inputs(PositionSet(np.radians(np.arange(0, 360, 45)), np.zeros(8)), LAT_RAD)
    with pytest.raises(IdentifiabilityError, match=r"rank 4 < 7; they cannot determine"):
        calibrate(inputs, np.zeros(8), np.zeros(8))


def test_phi2_only_positions_have_one_gravity_direction():
    inputs = position_inputs(PositionSet(np.zeros(12), np.radians(np.arange(0, 360, 30))), LAT_RAD)
    with pytest.raises(IdentifiabilityError, match="too few distinct gravity directions"):
        calibrate(inputs, np.zeros(12), np.zeros(12))


def test_nan_outputs_are_refused():
    inputs = position_inputs(PositionSet.parse("grid:45"), LAT_RAD)
    outputs = np.zeros(64)
    outputs[3] = np.nan
    with pytest.raises(InputError, match="NaN"):
        calibrate(inputs, outputs, np.zeros(64))


def test_shipped_example_is_reproducible_and_calibrates_to_table_1(tmp_path):
    gyro = GyroWheelModel.nominal()
    gyro = type(gyro)(gyro.x, gyro.y, source="Table 1")
    inputs = position_inputs(PositionSet.grid(45), LAT_RAD)
    again = write_simulated_run(tmp_path / "run.csv", gyro, inputs, noise_dph=0.002, seed=20261122)
    assert again.read_text() == EXAMPLE.read_text()
    result = calibrate_run(EXAMPLE, LAT_RAD)
    for axis in ("x", "y"):
        fit = result.axis(axis)
        assert fit.sigma_source == "sigma_dph"
        z = (fit.coefficients_dph - gyro.axis(axis).as_array()) / fit.standard_errors_dph
        assert np.all(np.abs(z) < 4.5), z
        assert 0.0015 < fit.rms_dph < 0.0025
    assert len(result.to_dict()["residuals"]) == 64


def test_run_file_problems_are_named(tmp_path):
    missing = tmp_path / "missing.csv"
    missing.write_text("phi1_deg,phi2_deg,out_x_dph\n0,0,1\n")
    with pytest.raises(InputError, match="missing required column.*out_y_dph"):
        calibrate_run(missing, LAT_RAD)
    nan = tmp_path / "nan.csv"
    nan.write_text("phi1_deg,phi2_deg,out_x_dph,out_y_dph\n0,0,1,2\n0,90,nan,2\n")
    with pytest.raises(InputError, match="row 3, column 'out_x_dph'"):
        calibrate_run(nan, LAT_RAD)
    sigma = tmp_path / "sigma.csv"
    sigma.write_text("phi1_deg,phi2_deg,out_x_dph,out_y_dph,sigma_dph\n0,0,1,2,0\n")
    with pytest.raises(InputError, match="sigma_dph must be positive"):
        calibrate_run(sigma, LAT_RAD)


def test_a_run_of_the_paper_table_by_joint_name_is_the_same_run(tmp_path):
    # One rule for every table's angle columns: phiK_deg or <joint>_deg, also on the paper's.
    text = EXAMPLE.read_text().replace("phi1_deg,phi2_deg", "outer_axis_deg,inner_axis_deg")
    named = tmp_path / "named.csv"
    named.write_text(text)
    a, b = calibrate_run(EXAMPLE, LAT_RAD), calibrate_run(named, LAT_RAD)
    np.testing.assert_array_equal(a.x.coefficients_dph, b.x.coefficients_dph)
    assert a.to_dict()["residuals"] == b.to_dict()["residuals"]  # reported as phi1_deg, phi2_deg
    extra = tmp_path / "extra.csv"
    extra.write_text("phi1_deg,phi2_deg,phi3_deg,out_x_dph,out_y_dph\n0,0,0,1,2\n")
    with pytest.raises(InputError, match="phi3_deg is the angle of a joint this table does not"):
        calibrate_run(extra, LAT_RAD)


def test_a_barely_identifying_position_set_still_has_real_standard_errors():
    """17 positions within about 0.04 deg of one another identify the seven coefficients with a
    condition number near 1e11; the inverse of the normal matrix then had negative variances
    (rounding), and their square roots NaN. The variances are sums of squares now, equal to
    those of the pseudo-inverse of the weighted design."""
    rng = np.random.default_rng(0)
    for _ in range(2):  # the second draw is the barely identifying set
        n = rng.integers(12, 20)
        base = rng.uniform(0, 360, 2)
        spread = 10 ** rng.uniform(-6, 0)
        phi = base + rng.normal(0, spread, (n, 2)) * rng.uniform(0, 360)
    p = np.radians(phi)
    inputs = position_inputs(PositionSet(p[:, 0], p[:, 1]), 0.7)
    gyro = GyroWheelModel.nominal()
    outputs = gyro.outputs_dph(inputs.specific_force_g, inputs.earth_rate_dph)
    noise = np.random.default_rng(1).normal(0, 0.01, outputs.shape)
    result = calibrate(inputs, *(outputs + noise).T, np.full(len(p), 0.01))
    assert result.x.condition_number > 1e10
    design = regressor_matrix("x", inputs.specific_force_g) / 0.01
    expected = np.sqrt(np.sum(np.linalg.pinv(design) ** 2, axis=1))
    np.testing.assert_allclose(result.x.standard_errors_dph, expected, rtol=1e-6)

"""The run model: the plain calibration inside it, Table 1 from a clean run, weights, masks and
the linearisation of the table's effects against the exact outputs."""

from __future__ import annotations

import numpy as np
import pytest

from turntable_pin.calibration.drift_fit import calibrate
from turntable_pin.calibration.gyrowheel import GyroWheelModel
from turntable_pin.calibration.positions import PositionSet, position_inputs
from turntable_pin.calibration.run import CalibrationRun
from turntable_pin.instrument.effects import resolve_run_effects
from turntable_pin.instrument.model import BASE_NAMES, fit_run, reference_coefficients

TABLE1 = GyroWheelModel.nominal()
BETA = np.stack([TABLE1.x.as_array(), TABLE1.y.as_array()])


def _clean_run(noise=0.0, seed=0, positions="grid:30"):
    inputs = position_inputs(PositionSet.parse(positions), np.radians(45.75))
    out = TABLE1.outputs_dph(inputs.specific_force_g, inputs.earth_rate_dph)
    out = out + np.random.default_rng(seed).normal(0.0, noise, out.shape)
    sigma = np.full(len(inputs), noise) if noise else None
    return CalibrationRun(inputs, out, sigma)


def test_table1_from_the_clean_run_to_1e9():
    fit = fit_run(_clean_run())
    assert np.max(np.abs(fit.coefficients_dph - BETA)) < 1e-9
    assert fit.result.rank == 14
    assert fit.result.parameter_names[:14] == BASE_NAMES


def test_base_fit_is_the_plain_calibration_of_eq6():
    run = _clean_run(noise=0.002, seed=3)
    fit = fit_run(run)
    plain = calibrate(run.inputs, run.outputs_dph[:, 0], run.outputs_dph[:, 1], run.sigma_dph)
    np.testing.assert_allclose(fit.coefficients_dph[0], plain.x.coefficients_dph, atol=1e-10)
    np.testing.assert_allclose(fit.coefficients_dph[1], plain.y.coefficients_dph, atol=1e-10)
    np.testing.assert_allclose(fit.residuals_dph[:, 0], plain.x.residuals_dph, atol=1e-10)
    stds = fit.result.parameter_table()
    assert stds["Dxx"]["std"] == pytest.approx(plain.x.standard_errors_dph[1], rel=1e-9)
    np.testing.assert_allclose(reference_coefficients(run), fit.coefficients_dph, atol=1e-10)


def test_a_masked_output_is_left_out_of_the_fit():
    run = _clean_run(noise=0.002, seed=4)
    bad = run.outputs_dph.copy()
    bad[5, 1] += 1.0
    run = run.replace(outputs_dph=bad)
    mask = np.ones((run.n_positions, 2), bool)
    mask[5, 1] = False
    fit = fit_run(run, mask=mask)
    assert np.isnan(fit.residuals_dph[5, 1])
    assert fit.result.n_obs == 2 * run.n_positions - 1
    assert np.max(np.abs(fit.coefficients_dph - BETA)) < 0.01


@pytest.mark.parametrize(
    "effect, values",
    [
        ("bias_drift", (0.004, -0.003)),
        ("instrument_tilt", (60.0, -40.0)),
        ("g_squared_terms", (0.03, 0.0, 0.0, -0.02)),
    ],
)
def test_an_effect_in_the_data_comes_back_with_its_values(effect, values):
    run = _clean_run()
    n = run.n_positions
    run = run.replace(time_s=np.arange(n) * 120.0)
    (e,) = resolve_run_effects([effect])
    base = fit_run(run)
    scale = np.array([s.per_user_unit for s in e.parameters(run)])
    shift = np.einsum("ncp,p->nc", e.columns(base.model.context), np.array(values) * scale)
    moved = run.replace(outputs_dph=run.outputs_dph + shift)
    fit = fit_run(moved, [e])
    table = fit.result.parameter_table()
    got = [table[f"{effect}.{s.name}"]["value"] for s in e.parameters(run)]
    np.testing.assert_allclose(got, values, rtol=1e-6, atol=1e-9)
    assert fit.result.rss < 1e-20

"""The rate sensitivity (eqs. 8-13 to first order) against finite differences of the exact
outputs at a rotated payload, and the drift gradient against the regressor."""

from __future__ import annotations

import numpy as np
import pytest

from turntable_pin.calibration.gyrowheel import AXES, GyroWheelModel, regressor_matrix
from turntable_pin.calibration.positions import PositionSet, position_inputs
from turntable_pin.calibration.rate_error import orientation_error_rotation
from turntable_pin.instrument.sensitivity import (
    drift_gradient,
    drift_regressor,
    rate_sensitivity_dph,
)


def _exact_outputs(inputs, beta, angles_rad):
    """Eq. 1 at the payload turned by the exact rotation of (dpsi, dtheta, dgamma)."""
    dR = orientation_error_rotation(*angles_rad, exact=True)
    a = inputs.specific_force_g @ dR
    w = inputs.earth_rate_dph @ dR
    return np.stack(
        [w[:, c] + regressor_matrix(axis, a) @ beta[c] for c, axis in enumerate(AXES)], axis=1
    )


@pytest.mark.parametrize("seed", range(4))
def test_sensitivity_equals_central_differences_of_the_exact_outputs(seed):
    rng = np.random.default_rng(seed)
    positions = PositionSet(rng.uniform(-np.pi, np.pi, (40, 2)))
    inputs = position_inputs(positions, rng.uniform(-1.2, 1.2))
    beta = rng.uniform(-100, 100, (2, 7))
    sensitivity = rate_sensitivity_dph(inputs, beta)
    h = 1e-6
    for k in range(3):
        step = np.zeros(3)
        step[k] = h
        diff = (_exact_outputs(inputs, beta, step) - _exact_outputs(inputs, beta, -step)) / (2 * h)
        scale = np.max(np.abs(diff))
        assert np.max(np.abs(sensitivity[:, :, k] - diff)) <= 1e-7 * scale


def test_table1_sensitivity_agrees_with_the_nominal_model():
    """At Table 1, the sensitivity is the derivative of GyroWheelModel.outputs_dph."""
    model = GyroWheelModel.nominal()
    inputs = position_inputs(PositionSet.grid(30), 0.8)
    beta = np.stack([model.x.as_array(), model.y.as_array()])
    sensitivity = rate_sensitivity_dph(inputs, beta)
    r = np.array([2e-6, -1e-6, 3e-6])  # (dpsi, dtheta, dgamma), rad
    dR = orientation_error_rotation(*r, exact=True)
    moved = model.outputs_dph(inputs.specific_force_g @ dR, inputs.earth_rate_dph @ dR)
    still = model.outputs_dph(inputs.specific_force_g, inputs.earth_rate_dph)
    first = sensitivity @ r
    assert np.max(np.abs(moved - still - first)) < 1e-9


def test_drift_gradient_is_the_derivative_of_the_regressor():
    rng = np.random.default_rng(3)
    a = rng.normal(size=(25, 3))
    for axis in AXES:
        beta = rng.normal(size=7)
        grad = drift_gradient(axis, a, beta)
        h = 1e-6
        for k in range(3):
            e = np.zeros(3)
            e[k] = h
            diff = regressor_matrix(axis, a + e) @ beta - regressor_matrix(axis, a - e) @ beta
            np.testing.assert_allclose(grad[:, k], diff / (2 * h), atol=1e-8)


def test_drift_regressor_puts_each_axis_on_its_output():
    a = np.random.default_rng(4).normal(size=(6, 3))
    design = drift_regressor(a)
    np.testing.assert_array_equal(design[:, 0, :7], regressor_matrix("x", a))
    np.testing.assert_array_equal(design[:, 1, 7:], regressor_matrix("y", a))
    assert not design[:, 0, 7:].any() and not design[:, 1, :7].any()

"""The exact chain model: equal to the foundation's batch path; Jacobian = finite differences."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from turntable_pin import OrientationErrorField, small_angle_orientation_error
from turntable_pin.measurement.effect_model import OrientationModel
from turntable_pin.measurement.effects import EFFECTS, PositionVariables


def _grid_variables(seed=0, n=60):
    rng = np.random.default_rng(seed)
    return PositionVariables.of(
        rng.uniform(0, 2 * np.pi, n), rng.uniform(0, 2 * np.pi, n), time_s=rng.uniform(0, 9000, n),
        dirs=(rng.choice([-1.0, 1.0], n), rng.choice([-1.0, 1.0], n)),
    )  # fmt: skip


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000))
def test_base_model_equals_the_batch_path(seed):
    rng = np.random.default_rng(seed)
    v = _grid_variables(seed)
    errors = rng.normal(0, 1e-3, 8)  # large: the exact chain, not its small-angle form
    expected = OrientationErrorField.from_error_values(np.append(errors, 0.0)[None]).angles(
        v.phi1_rad, v.phi2_rad
    )[0]
    np.testing.assert_allclose(OrientationModel(v).predict(errors), expected, atol=1e-15)


def test_zero_parameter_jacobian_is_the_small_angle_matrix(rng):
    v = _grid_variables(1)
    jac = OrientationModel(v).jacobian(np.zeros(8))
    for k in range(8):
        unit = np.eye(8)[k]
        np.testing.assert_allclose(
            jac[:, :, k], small_angle_orientation_error(unit, v.phi2_rad), atol=1e-15
        )


@settings(max_examples=10, deadline=None)
@given(st.integers(0, 10_000))
def test_jacobian_matches_finite_differences_for_all_effects(seed):
    rng = np.random.default_rng(seed)
    v = _grid_variables(seed, n=25)
    model = OrientationModel(v, list(EFFECTS.values()))
    scale = np.where(np.array([u == "arcsec/h" for u in model.parameter_units]), 1e-7, 1e-3)
    p = rng.normal(0, 1, model.n_params) * scale
    jac = model.jacobian(p)
    for k in range(model.n_params):
        h = 1e-2 * scale[k]  # an angle step of ~1e-5 rad: truncation ~1e-10, rounding ~1e-11
        step = np.zeros(model.n_params)
        step[k] = h
        fd = (model.predict(p + step) - model.predict(p - step)) / (2 * h)
        tol = 1e-8 * max(1.0, np.abs(fd).max())
        np.testing.assert_allclose(jac[:, :, k], fd, atol=tol, err_msg=model.parameter_names[k])

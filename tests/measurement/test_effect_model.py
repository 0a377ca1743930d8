"""The exact chain model: equal to the foundation's batch path; Jacobian = finite differences."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from rounding import chain_rounding, error_factors
from turntable_pin import OrientationErrorField, small_angle_orientation_error
from turntable_pin.calibration.positions import PositionSet
from turntable_pin.measurement.effect_model import OrientationModel
from turntable_pin.measurement.effects import EFFECTS, PositionVariables
from turntable_pin.model.paper_table import paper_table


def _grid_variables(seed=0, n=60):
    rng = np.random.default_rng(seed)
    return PositionVariables.of(
        PositionSet(
            rng.uniform(0, 2 * np.pi, n),
            rng.uniform(0, 2 * np.pi, n),
            time_s=rng.uniform(0, 9000, n),
            dirs=(rng.choice([-1.0, 1.0], n), rng.choice([-1.0, 1.0], n)),
        )
    )


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000))
def test_base_model_equals_the_batch_path(seed):
    rng = np.random.default_rng(seed)
    v = _grid_variables(seed)
    errors = rng.normal(0, 1e-3, 8)  # large: the exact chain, not its small-angle form
    values = np.append(errors, 0.0)[None]
    expected = OrientationErrorField.from_chain(paper_table().chain, values).angles(
        v.joint_rad[:, 0], v.joint_rad[:, 1]
    )[0]
    np.testing.assert_allclose(OrientationModel(v).predict(errors), expected, atol=1e-15)


def test_zero_parameter_jacobian_is_the_small_angle_matrix(rng):
    v = _grid_variables(1)
    model = OrientationModel(v)
    jac = model.jacobian(np.zeros(8))
    # The chain's products against one rotation's sines and cosines: both round absolutely.
    rounding = chain_rounding(error_factors(model.table)) + chain_rounding(1)
    for k in range(8):
        unit = np.eye(8)[k]
        np.testing.assert_allclose(
            jac[:, :, k],
            small_angle_orientation_error(unit, v.joint_rad[:, 1]),
            rtol=0,
            atol=rounding,
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


@settings(max_examples=10, deadline=None)
@given(st.integers(0, 10_000))
def test_rows_without_the_roll_predict_the_boresight_and_their_jacobian_is_fd(seed):
    # a row whose dgamma is not measured sees the x axis' direction: dpsi = -dR[2, 0] (the
    # swing of dR), with the roll anywhere; other rows keep dR[0, 2]
    rng = np.random.default_rng(seed)
    v = _grid_variables(seed, n=25)
    rows = rng.random(v.n) < 0.5
    swing = PositionVariables(v.joint_rad, v.time_s, v.dirs, boresight_only=rows)
    whole = OrientationModel(v, list(EFFECTS.values()))
    model = OrientationModel(swing, list(EFFECTS.values()))
    scale = np.where(np.array([u == "arcsec/h" for u in model.parameter_units]), 1e-7, 1e-3)
    p = rng.normal(0, 1, model.n_params) * scale
    d_r = whole.rotation_error(p)
    predicted, expected = model.predict(p), whole.predict(p)
    np.testing.assert_array_equal(predicted[~rows], expected[~rows])
    np.testing.assert_allclose(predicted[rows, 0], -d_r[rows, 2, 0], atol=1e-17)
    np.testing.assert_array_equal(predicted[rows, 1:], expected[rows, 1:])
    jac = model.jacobian(p)
    for k in range(model.n_params):
        h = 1e-2 * scale[k]
        step = np.zeros(model.n_params)
        step[k] = h
        fd = (model.predict(p + step) - model.predict(p - step)) / (2 * h)
        tol = 1e-8 * max(1.0, np.abs(fd).max())
        np.testing.assert_allclose(jac[:, :, k], fd, atol=tol, err_msg=model.parameter_names[k])


def _reference_jacobian(model, params):
    """The Jacobian from prefix and suffix products of the chain's (N, 3, 3) matrices:
    ``d dR = P_f [a]x S_f`` for every rotation, the gains dense (the straightforward way)."""
    from turntable_pin.core.rotations import axis_rotation
    from turntable_pin.model.chain import skew

    n = model.variables.n
    mats, generators, gains = [], [], []
    for f in model._factors:
        if f.fixed is not None:
            mats.append(np.broadcast_to(np.moveaxis(f.fixed, -1, 0), (n, 3, 3)))
            generators.append(None)
            gains.append(None)
            continue
        angle = np.broadcast_to(f.angle(params), (n,))
        mats.append(axis_rotation(f.axis, angle))
        axis = np.eye(3)["xyz".index(f.axis)] if isinstance(f.axis, str) else f.axis
        generators.append(skew(axis))
        gain = np.zeros((n, model.n_params))
        for column, weight in zip(f.columns, f.weights, strict=True):
            gain[:, column] += np.broadcast_to(weight, (n,))
        gains.append(gain)
    prefix = [np.moveaxis(model._rd, -1, 0)]
    for m in mats:
        prefix.append(prefix[-1] @ m)
    suffix = [np.broadcast_to(np.eye(3), (n, 3, 3))]
    for m in reversed(mats):
        suffix.append(m @ suffix[-1])
    suffix = suffix[::-1]
    jac = np.zeros((n, 3, model.n_params))
    for f, (generator, gain) in enumerate(zip(generators, gains, strict=True)):
        if generator is None:
            continue
        d = prefix[f + 1] @ generator @ suffix[f + 1]
        entries = np.stack([d[:, 0, 2], d[:, 1, 0], d[:, 2, 1]], axis=1)
        jac += entries[:, :, None] * gain[:, None, :]
    return prefix[-1], jac


def test_one_pass_jacobian_equals_prefix_suffix_products_for_every_effect():
    """The fast Jacobian (``[P a]x dR``, one forward pass, sparse gains) against the
    straightforward prefix/suffix products with dense gains, at large parameters."""
    rng = np.random.default_rng(3)
    v = _grid_variables(3, n=40)
    for effects in [[], *([e] for e in EFFECTS.values()), list(EFFECTS.values())]:
        model = OrientationModel(v, effects)
        p = rng.normal(0, 1e-3, model.n_params)
        predicted, jac = model.predict_and_jacobian(p)
        rotation, expected = _reference_jacobian(model, p)
        np.testing.assert_allclose(jac, expected, atol=1e-14)
        np.testing.assert_allclose(model.rotation_error(p), rotation, atol=1e-15)
        np.testing.assert_allclose(
            predicted, np.stack([rotation[:, 0, 2], rotation[:, 1, 0], rotation[:, 2, 1]], 1),
            atol=1e-15,
        )  # fmt: skip
        np.testing.assert_array_equal(model.jacobian(p), jac)


def test_blocks_of_positions_equal_the_whole():
    v = _grid_variables(4, n=50)
    model = OrientationModel(v, list(EFFECTS.values()))
    p = np.random.default_rng(4).normal(0, 1e-4, model.n_params)
    predicted, jac = model.predict_and_jacobian(p)
    for rows in (slice(0, 17), slice(17, 50), slice(49, 50)):
        part_predicted, part_jac = model.predict_and_jacobian(p, rows)
        np.testing.assert_allclose(part_predicted, predicted[rows], atol=1e-16)
        np.testing.assert_allclose(part_jac, jac[rows], atol=1e-16)


def test_models_of_the_same_positions_share_the_table_matrices():
    v = _grid_variables(5, n=30)
    a = OrientationModel(v)
    b = OrientationModel(
        PositionVariables(v.joint_rad.copy(), v.time_s, v.dirs), list(EFFECTS.values())
    )
    assert a._rd is b._rd
    other = OrientationModel(_grid_variables(6, n=30))
    assert other._rd is not a._rd
    assert not np.allclose(other.predict(np.full(8, 1e-4)), a.predict(np.full(8, 1e-4)))


def test_models_on_one_data_set_share_their_gains_and_predict_as_models_built_alone():
    """Models built on one PositionVariables (the base and the candidates of a diagnosis) share
    the stacked gains of the same effect terms while a model holds them; each predicts and
    differentiates exactly as a model built on variables of its own."""
    v = _grid_variables(3)
    encoder, wobble = EFFECTS["inner_encoder_harmonics"], EFFECTS["outer_wobble_harmonics"]
    a = OrientationModel(v, [encoder])
    b = OrientationModel(v, [wobble, encoder])

    def gains(model):
        return {id(f.weights) for f in model._factors if f.weights is not None}

    assert gains(a) < gains(b)  # every factor of a is b's too; b has the wobble's besides
    alone = PositionVariables(v.joint_rad, v.time_s, v.dirs, dict(v.extra))
    rng = np.random.default_rng(4)
    for model, effects in ((a, [encoder]), (b, [wobble, encoder])):
        fresh = OrientationModel(alone, effects)
        assert not gains(fresh) & gains(model)
        params = rng.normal(0, 1e-4, model.n_params)
        np.testing.assert_array_equal(model.predict(params), fresh.predict(params))
        np.testing.assert_array_equal(model.jacobian(params), fresh.jacobian(params))
        alone = PositionVariables(v.joint_rad, v.time_s, v.dirs, dict(v.extra))


def test_variables_and_data_pickle_and_copy_without_their_memo():
    import copy
    import pickle

    from turntable_pin.measurement.simulation import simulate_measurements

    data = simulate_measurements(None, seed=1).data
    v = data.variables()
    OrientationModel(v, [EFFECTS["backlash"]])  # fills the memo (weak references)
    for clone in (pickle.loads(pickle.dumps(data)), copy.deepcopy(data), copy.copy(data)):
        np.testing.assert_array_equal(clone.angles_rad, data.angles_rad)
        assert clone.variables() is not v
    w = pickle.loads(pickle.dumps(v))
    np.testing.assert_array_equal(w.joint_rad, v.joint_rad)
    assert "_memo" not in w.__dict__

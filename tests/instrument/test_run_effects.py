"""Each run effect's columns against an independent construction: finite differences of the
exact outputs (the table's exact chain, the instrument's exact rotation) or the closed form."""

from __future__ import annotations

import numpy as np
import pytest

from turntable_pin.calibration.gyrowheel import AXES, GyroWheelModel, regressor_matrix
from turntable_pin.calibration.positions import PositionSet, position_inputs
from turntable_pin.calibration.rate_error import orientation_error_rotation
from turntable_pin.calibration.run import CalibrationRun
from turntable_pin.core.exceptions import InputError
from turntable_pin.core.resources import models_dir
from turntable_pin.instrument.effects import resolve_run_effects, run_catalogue
from turntable_pin.instrument.effects.table_side import TableErrors
from turntable_pin.instrument.model import run_context
from turntable_pin.measurement.table import measured_table
from turntable_pin.model.generic_table import GenericTable
from turntable_pin.model.paper_table import paper_table


def _run(table=None, n=30, seed=0):
    rng = np.random.default_rng(seed)
    table = table or paper_table()
    angles = rng.uniform(-np.pi, np.pi, (n, len(table.joint_names)))
    inputs = position_inputs(PositionSet(angles, table=table), 0.8)
    model = GyroWheelModel.nominal()
    out = model.outputs_dph(inputs.specific_force_g, inputs.earth_rate_dph)
    t = np.arange(n) * 100.0
    return CalibrationRun(inputs, out, None, t, {"temperature_c": 20 + 0.01 * t})


def _outputs(run, dR, mount=None):
    """Eq. 1 with Table 1 at the payload turned by dR (N, 3, 3) and the instrument by mount."""
    model = GyroWheelModel.nominal()
    mount = np.eye(3) if mount is None else mount
    a = np.einsum("ni,nij->nj", run.inputs.specific_force_g, dR) @ mount
    w = np.einsum("ni,nij->nj", run.inputs.earth_rate_dph, dR) @ mount
    return np.stack(
        [w[:, c] + regressor_matrix(axis, a) @ model.axis(axis).as_array()
         for c, axis in enumerate(AXES)], axis=1,
    )  # fmt: skip


@pytest.mark.parametrize(
    "urdf", [None, "two_axis_vertical_outer.urdf", "three_axis_imu_table.urdf"]
)
def test_table_errors_columns_equal_differences_of_the_exact_chain(urdf):
    table = paper_table() if urdf is None else GenericTable(models_dir() / urdf)
    run = _run(table)
    # At Table 1's coefficients: on the vertical-outer table the run leaves Dxx, Dxxx... (gravity
    # never along x) undetermined, and its minimum-norm reference would be another linearisation.
    model = GyroWheelModel.nominal()
    context = run_context(run, np.stack([model.x.as_array(), model.y.as_array()]))
    measured = measured_table(table)
    columns = TableErrors(measured).columns(context)
    q = list(run.joint_rad.T)
    h = 1e-7
    for k, name in enumerate(measured.base_names):
        values = np.zeros(len(table.parameter_names))
        values[table.parameter_names.index(name)] = h
        plus = _outputs(run, table.rotation_error(values, q))
        minus = _outputs(run, table.rotation_error(-values, q))
        diff = (plus - minus) / (2 * h)
        assert np.max(np.abs(columns[:, :, k] - diff)) <= 1e-6 * max(np.max(np.abs(diff)), 1.0)


def test_tilt_and_heading_equal_differences_of_the_exact_mount_rotation():
    run = _run()
    context = run_context(run)
    tilt, heading = resolve_run_effects(["instrument_tilt", "instrument_heading"])
    columns = np.concatenate([tilt.columns(context), heading.columns(context)], axis=2)
    eye = np.broadcast_to(np.eye(3), (run.n_positions, 3, 3))
    h = 1e-7
    for k in range(3):  # rotation about payload x, y, z: r = (gamma, psi, theta)
        r = np.zeros(3)
        r[k] = h
        angles = (r[1], r[2], r[0])
        plus = _outputs(run, eye, orientation_error_rotation(*angles, exact=True))
        minus = _outputs(run, eye, orientation_error_rotation(*(-v for v in angles), exact=True))
        np.testing.assert_allclose(columns[:, :, k], (plus - minus) / (2 * h), atol=2e-5)


def test_instrument_effects_closed_forms():
    run = _run()
    context = run_context(run)
    drift, temperature, scale, g2 = resolve_run_effects(
        ["bias_drift", "temperature_coefficient", "earth_rate_scale", "g_squared_terms"]
    )
    t = run.time_s
    np.testing.assert_array_equal(drift.columns(context)[:, 0, 0], t)
    np.testing.assert_array_equal(drift.columns(context)[:, 1, 0], 0.0)
    temp = run.extra["temperature_c"]
    np.testing.assert_allclose(temperature.columns(context)[:, 1, 1], temp - temp.mean())
    w = run.inputs.earth_rate_dph
    np.testing.assert_array_equal(scale.columns(context)[:, 0, 0], w[:, 0])
    a = run.inputs.specific_force_g
    cols = g2.columns(context)
    np.testing.assert_allclose(cols[:, 0, 0], a[:, 0] * a[:, 2])
    np.testing.assert_allclose(cols[:, 1, 3], a[:, 1] * a[:, 2])
    # user units: deg/h per hour, ppm
    assert drift.parameters(run)[0].per_user_unit == pytest.approx(1 / 3600)
    assert scale.parameters(run)[0].per_user_unit == pytest.approx(1e-6)


def test_a_table_catalogue_effect_is_its_orientation_jacobian_through_the_sensitivity():
    from turntable_pin.measurement.effect_model import OrientationModel

    run = _run(n=40, seed=2)
    context = run_context(run)
    (wobble,) = resolve_run_effects(["inner_wobble_harmonics"])
    cols = wobble.columns(context)
    model = OrientationModel(context.variables, (wobble.effect,), None)
    n_base = len(model.base_names)
    h = 1e-7
    for k in range(cols.shape[2]):
        p = np.zeros(model.n_params)
        p[n_base + k] = h
        dplus = model.predict(p)
        dminus = model.predict(-p)
        rot = [orientation_error_rotation(*d.T, exact=True) for d in (dplus, dminus)]
        diff = (_outputs(run, rot[0]) - _outputs(run, rot[1])) / (2 * h)
        assert np.max(np.abs(cols[:, :, k] - diff)) <= 1e-6 * max(np.max(np.abs(diff)), 1.0)


def test_output_terms_and_unknown_names():
    run = _run()
    context = run_context(run)
    (term,) = resolve_run_effects(["out_y~h2(phi1)"])
    cols = term.columns(context)
    np.testing.assert_allclose(cols[:, 1, 0], np.cos(2 * run.joint_rad[:, 0]))
    np.testing.assert_allclose(cols[:, 1, 1], np.sin(2 * run.joint_rad[:, 0]))
    assert not cols[:, 0].any()
    assert [s.unit for s in term.parameters(run)] == ["deg/h", "deg/h"]
    (orientation_term,) = resolve_run_effects(["dpsi~h1(phi2)"])
    assert orientation_term.side == "table"
    with pytest.raises(InputError, match="unknown run effect 'nonsense'"):
        resolve_run_effects(["nonsense"])


def test_catalogue_sides_and_names():
    names = {e.name: e.side for e in run_catalogue()}
    assert names["table:deps_x"] == "table"
    assert names["instrument_tilt"] == "instrument"
    assert "table:payload_mount" not in names  # the instrument's tilt and heading are it
    for effect in run_catalogue():
        story = effect.describe()
        assert story["title"] and story["explanation"] and story["confirm"]


def test_every_run_candidate_of_the_catalogue_carries_a_turntable_scale():
    """Issue 29: table errors, table effects (their orientation scale) and the instrument's
    effects (any machine) judge their fitted amplitudes; inline terms do not."""
    from turntable_pin.instrument.effects import run_catalogue, run_term
    from turntable_pin.measurement.effects.base import TURNTABLE
    from turntable_pin.measurement.table import measured_table

    for effect in run_catalogue():
        assert effect.plausibility, effect.name
        assert all(g.limit(TURNTABLE) is not None for g in effect.plausibility), effect.name
    assert run_term("out_x~h2(phi1)", measured_table(None)).plausibility == ()
    by_name = {e.name: e for e in run_catalogue()}
    assert by_name["table:deps_x"].implausibility({"value": 60.0}, TURNTABLE) is None
    assert "orthogonality" in by_name["table:deps_x"].implausibility({"value": 3600.0}, TURNTABLE)
    assert by_name["g_squared_terms"].implausibility({"x_xz": 0.03}, TURNTABLE) is None

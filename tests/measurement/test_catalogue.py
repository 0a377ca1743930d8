"""Every bundled table's catalogue: per-joint effects by their generic names, the paper's aliases,
the compliance K and the base rotation reduced to what orientation data determine, and the whole
loop (simulate, fit to the noise, diagnose a planted per-joint effect by its generic name)."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import REPO_DIR
from rounding import chain_rounding, error_factors
from turntable_pin.core.exceptions import InputError
from turntable_pin.core.units import ARCSEC_PER_RAD
from turntable_pin.measurement.catalogue import catalogue, resolve_effect
from turntable_pin.measurement.diagnosis import diagnose_measurements
from turntable_pin.measurement.effect_model import OrientationModel
from turntable_pin.measurement.effects import EFFECTS
from turntable_pin.measurement.effects.base import PositionVariables
from turntable_pin.measurement.effects.gravity_compliance import GravityCompliance
from turntable_pin.measurement.fit import fit_orientation
from turntable_pin.measurement.simulation import Schedule, simulate_measurements
from turntable_pin.measurement.table import measured_table
from turntable_pin.model.generic_table import GenericTable

MODELS = REPO_DIR / "models"
# Each table with a schedule dense enough for 2/rev terms and a planted per-joint effect.
CASES = {
    "two_axis_vertical_outer": (Schedule(30, 30), "encoder_harmonics@tilt_axis"),
    "three_axis_imu_table": (
        Schedule(60, 60, 60, repeats=1),
        "wobble_harmonics@middle_gimbal",
    ),
    "single_axis_rate_table": (Schedule(10, repeats=3), "encoder_harmonics@spindle"),
}


@pytest.fixture(scope="module", params=sorted(CASES))
def table(request):
    return request.param, GenericTable(MODELS / f"{request.param}.urdf")


def _random_errors(table: GenericTable, rng) -> np.ndarray:
    values = rng.normal(0.0, 10.0, len(table.parameter_names)) / ARCSEC_PER_RAD
    values[[table.parameter_names.index(n) for n in table.length_names]] = 0.0
    return values


def test_catalogue_names_per_joint_and_table_wide_effects(table):
    _, t = table
    names = [e.name for e in catalogue(t)]
    for joint in t.joint_names:
        for kind in ("encoder_harmonics", "wobble_harmonics", "backlash"):
            assert f"{kind}@{joint}" in names
    for wide in ("gravity_sag", "base_tilt", "thermal_drift", "payload_mount"):
        assert wide in names
    assert not set(names) & {"outer_encoder_harmonics", "inner_wobble_harmonics"}
    with pytest.raises(InputError, match="unknown effect 'outer_encoder_harmonics'"):
        resolve_effect("outer_encoder_harmonics", t)
    with pytest.raises(InputError, match="unknown joint 'nope'"):
        resolve_effect("encoder_harmonics@nope", t)


def test_base_model_equals_the_generic_chain(table):
    """OrientationModel (effect layer, analytic chain) equals GenericTable.rotation_error."""
    _, t = table
    rng = np.random.default_rng(5)
    q = rng.uniform(-np.pi, np.pi, (40, len(t.joint_names)))
    errors = rng.normal(0, 2e-4, len(t.parameter_names))  # large: the exact chain
    model = OrientationModel(PositionVariables(q), (), t)
    values = dict(zip(t.parameter_names, errors, strict=True))
    p = model.parameter_vector({n: values[n] for n in model.base_names})
    dr = t.rotation_error(errors, list(q.T))
    expected = np.stack([dr[:, 0, 2], dr[:, 1, 0], dr[:, 2, 1]], axis=1)  # model.md eq. 24
    np.testing.assert_allclose(model.predict(p), expected, atol=1e-13)
    # The analytic Jacobian against central differences.
    jac = model.jacobian(p)
    # dR's rounding over the step h = 1e-7, and the truncation h^2 |f3| / 6
    # (f3, a third derivative of unit-size rotation entries, is at most 1).
    fd_tolerance = chain_rounding(error_factors(t)) / 1e-7 + 1e-14 / 6
    for k in range(model.n_params):
        step = np.zeros(model.n_params)
        step[k] = 1e-7
        fd = (model.predict(p + step) - model.predict(p - step)) / 2e-7
        np.testing.assert_allclose(jac[:, :, k], fd, rtol=0, atol=fd_tolerance)


def test_clean_data_fit_to_the_noise_and_recover_the_errors(table):
    name, t = table
    rng = np.random.default_rng(11)
    truth = _random_errors(t, rng)
    sim = simulate_measurements(truth, schedule=CASES[name][0], seed=3, turntable=t)
    fit = fit_orientation(sim.data, turntable=t)
    assert 0.7 < fit.result.chi2_reduced < 1.3
    # Every determined combination equals the truth's value within 5 standard errors.
    truth_by_name = dict(zip(t.parameter_names, truth * ARCSEC_PER_RAD, strict=True))
    for c in fit.result.combinations():
        value = sum(
            coef * truth_by_name[p] for p, coef in c["coefficients"].items() if p in truth_by_name
        )
        assert abs(c["value"] - value) < 5 * c["std"] + 1e-9, c["name"]


def test_a_planted_per_joint_effect_is_named_by_its_generic_name(table):
    name, t = table
    schedule, effect = CASES[name]
    params = {"c1": 4.0, "s2": -3.0} if "encoder" in effect else {"a_c2": 4.0, "b_s2": -3.0}
    for seed in (1, 2):
        sim = simulate_measurements(
            _random_errors(t, np.random.default_rng(seed)), {effect: params},
            schedule=schedule, seed=seed, turntable=t,
        )  # fmt: skip
        d = diagnose_measurements(sim.data, turntable=t).to_dict()
        assert d["verdict"]["missing_effect"] == effect, d["verdict"]
        assert not d["verdict"]["unexplained"]
        clean = simulate_measurements(schedule=schedule, seed=seed, turntable=t)
        assert diagnose_measurements(clean.data, turntable=t).missing_effect is None


def test_paper_aliases_are_the_paper_effects():
    for alias, name in (
        ("encoder_harmonics@outer_axis", "outer_encoder_harmonics"),
        ("encoder_harmonics@inner_axis", "inner_encoder_harmonics"),
        ("wobble_harmonics@outer_axis", "outer_wobble_harmonics"),
        ("wobble_harmonics@inner_axis", "inner_wobble_harmonics"),
    ):
        assert resolve_effect(alias) is EFFECTS[name]
    assert resolve_effect("backlash@inner_axis").required_columns == ("dir2",)
    assert [e.name for e in catalogue()] == list(EFFECTS)


def test_generic_gravity_sag_contains_the_papers():
    """The paper's sag Rx(-k ay) Ry(k ax) is K with k_xy = -k, k_yx = k."""
    paper = measured_table()
    rng = np.random.default_rng(2)
    v = PositionVariables(rng.uniform(-np.pi, np.pi, (30, 2)))
    ours = OrientationModel(v, [GravityCompliance(paper.rotation, ("k_xy", "k_yx"))], paper)
    theirs = OrientationModel(v, [EFFECTS["gravity_sag"]], paper)
    k = 7.0 / ARCSEC_PER_RAD
    p_ours = ours.parameter_vector({"gravity_sag.k_xy": -k, "gravity_sag.k_yx": k})
    p_theirs = theirs.parameter_vector({"gravity_sag.k": k})
    np.testing.assert_allclose(ours.predict(p_ours), theirs.predict(p_theirs), atol=1e-15)


def test_compliance_and_base_rotation_keep_what_the_data_determine():
    vertical = GenericTable(MODELS / "single_axis_rate_table.urdf")
    by_name = {e.name: e for e in catalogue(vertical)}
    # A vertical spindle keeps gravity along the payload's axis: K a is constant, the mount
    # absorbs it, and nothing of K is determined (the whole K is kept to be reported absorbed).
    fit = fit_orientation(
        simulate_measurements(schedule=Schedule(30), seed=1, turntable=vertical).data,
        [by_name["gravity_sag"]], turntable=vertical,
    )  # fmt: skip
    base = fit_orientation(fit.data, turntable=vertical)
    assert fit.result.rank == base.result.rank
    two_axis = GenericTable(MODELS / "two_axis_vertical_outer.urdf")
    sag = {e.name: e for e in catalogue(two_axis)}["gravity_sag"]
    assert 0 < len(sag.entries) < 9
    # Each kept entry adds a direction the base errors do not span (rank grows by their count).
    sim = simulate_measurements(schedule=Schedule(30, 30), seed=1, turntable=two_axis)
    with_sag = fit_orientation(sim.data, [sag], turntable=two_axis)
    plain = fit_orientation(sim.data, turntable=two_axis)
    assert with_sag.result.rank - plain.result.rank == len(sag.entries)


@pytest.mark.parametrize("urdf", [None, "altaz_mount", "german_equatorial_mount"])
def test_every_catalogued_effect_carries_the_scale_of_its_parameters_on_its_machine(urdf):
    """Issue 29: each effect of a table's catalogue judges its amplitude on a turntable and on a
    telescope mount (data of the effect, docs/plausibility.md), over parameters it has."""
    from turntable_pin.measurement.effects.base import MOUNT, TURNTABLE, angle_words

    table = measured_table(GenericTable(REPO_DIR / "models" / f"{urdf}.urdf") if urdf else None)
    machine = MOUNT if table.telescope_mount else TURNTABLE
    variables = PositionVariables(np.zeros((3, table.n_joints)), np.zeros(3),
                                  (np.ones(3),) * table.n_joints)  # fmt: skip
    for effect in catalogue(table):
        names = {spec.name for spec in effect.parameters(variables)}
        assert effect.plausibility, effect.name
        for group in effect.plausibility:
            assert group.limit(machine) is not None and set(group.parameters) <= names
            assert "{amplitude}" in group.belief
            # this group alone far beyond its scale: its own sentence, ending with the scale
            huge = {name: 1e6 for name in group.parameters or names}
            scale = angle_words(group.limit(machine), group.unit)
            belief = effect.implausibility(huge, machine)
            assert belief.endswith(f"(where a {machine} reaches about {scale})")
            assert belief.startswith(group.belief.split("{amplitude}")[0])
    assert angle_words(3730.0, "arcsec") == "1.04 deg" and angle_words(90, "arcsec/g") == (
        "1.5 arcmin/g"
    )


def test_an_encoder_disc_a_degree_off_centre_is_implausible_on_a_mount_not_sixty_arcsec():
    table = measured_table(GenericTable(REPO_DIR / "models" / "german_equatorial_mount.urdf"))
    [encoder] = [e for e in catalogue(table) if e.name == "encoder_harmonics@declination"]
    belief = encoder.implausibility({"c1": -3730.0, "s1": 0.0}, "telescope mount")
    assert belief.startswith("an encoder disc of declination so far off centre that it reads "
                             "1.04 deg wrong once per turn")  # fmt: skip
    assert encoder.implausibility({"c1": 60.0, "s1": 0.0}, "telescope mount") is None

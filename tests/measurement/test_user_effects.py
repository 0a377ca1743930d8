"""Effects the user writes: effect files equal to catalogued effects, inline terms for every shape
the structure search reports, modules of Effect subclasses named by the diagnosis, entry points."""

import re

import numpy as np
import pytest

from conftest import write_file
from turntable_pin.core.exceptions import InputError
from turntable_pin.core.units import ARCSEC_PER_RAD
from turntable_pin.measurement.diagnosis import OrientationFamily, diagnose_measurements
from turntable_pin.measurement.effect_model import OrientationModel
from turntable_pin.measurement.effects import EFFECTS
from turntable_pin.measurement.effects.base import ChainTerm, Effect, ParameterSpec
from turntable_pin.measurement.fit import fit_orientation
from turntable_pin.measurement.simulation import simulate_measurements
from turntable_pin.measurement.user_effects import (
    check_user_effects,
    inline_effect,
    installed_effects,
    load_effects_module,
    read_effect_file,
    resolve_effects,
)
from turntable_pin.report.diagnosis_text import diagnosis_lines

ARCSEC = 1.0 / ARCSEC_PER_RAD

INNER_ENCODER_FILE = """\
format: 1
name: my_inner_encoder
title: inner encoder disc off-centre and elliptical
explanation: The inner encoder disc sits off the axis and is slightly elliptical.
confirm: Compare the inner encoder with a polygon and an autocollimator.
terms:
  - site: dphi_z2
    harmonics: 1..2
    of: phi2
"""

WOBBLE_FILE = """\
name: my_outer_wobble
terms:
  - {site: dalpha_x1, harmonics: [1, 2], of: phi1, prefix: x_}
  - site: dalpha_z1
    harmonics: "1..2"
    of: phi1
    prefix: z_
"""

INLINE_FILE = """\
name: encoder_in_one_line
terms: ["dphi_z2~h1..2(phi2)"]
"""


def _plant(data, spec: str, values: dict[str, float]):
    """``data`` with the inline term ``spec`` added at ``values`` (arcsec)."""
    effect = inline_effect(spec)
    model = OrientationModel(data.variables(), [effect])
    p = model.parameter_vector({f"{effect.name}.{k}": v * ARCSEC for k, v in values.items()})
    return data.replace(angles_rad=data.angles_rad + model.predict(p))


@pytest.fixture(scope="module")
def encoder_data():
    sim = simulate_measurements(None, {"inner_encoder_harmonics": {"c1": 3, "s2": -2}}, seed=5)
    return sim.data


@pytest.mark.parametrize(
    "text, catalogued",
    [
        (INNER_ENCODER_FILE, "inner_encoder_harmonics"),
        (WOBBLE_FILE, "outer_wobble_harmonics"),
        (INLINE_FILE, "inner_encoder_harmonics"),
    ],
)
def test_an_effect_file_fits_exactly_like_the_catalogued_effect(
    tmp_path, encoder_data, text, catalogued
):
    effect = read_effect_file(write_file(tmp_path, text, "effect.yaml"))
    mine = fit_orientation(encoder_data, [effect]).result
    theirs = fit_orientation(encoder_data, [EFFECTS[catalogued]]).result
    assert mine.rss == pytest.approx(theirs.rss, rel=1e-9, abs=1e-12)
    np.testing.assert_allclose(mine.params, theirs.params, rtol=0, atol=1e-9 * ARCSEC)
    assert [n.split(".", 1)[1] for n in mine.parameter_names[8:]] == [
        n.split(".", 1)[1] for n in theirs.parameter_names[8:]
    ]


def test_the_inline_term_is_the_catalogued_harmonics_too(encoder_data):
    (effect,) = resolve_effects(["dphi_z2~h1..2(phi2)"])
    mine = fit_orientation(encoder_data, [effect]).result
    theirs = fit_orientation(encoder_data, [EFFECTS["inner_encoder_harmonics"]]).result
    assert mine.rss == pytest.approx(theirs.rss, rel=1e-9, abs=1e-12)
    np.testing.assert_allclose(mine.params, theirs.params, rtol=0, atol=1e-9 * ARCSEC)
    assert effect.definition == (
        "dphi_z2 += c1 cos(phi2) + s1 sin(phi2) + c2 cos(2 phi2) + s2 sin(2 phi2)"
    )


def test_a_term_on_a_measured_angle_adds_exactly_to_that_angle(encoder_data):
    effect = inline_effect("dtheta~h2(phi1+phi2)")
    model = OrientationModel(encoder_data.variables(), [effect])
    base = OrientationModel(encoder_data.variables())
    p = model.parameter_vector({"dtheta~h2(phi1+phi2).s2": 2 * ARCSEC, "dphi_y1": 5 * ARCSEC})
    added = model.predict(p) - base.predict(p[: base.n_params])
    s = encoder_data.joint_rad.sum(axis=1)
    np.testing.assert_allclose(added[:, 1], 2 * ARCSEC * np.sin(2 * s), atol=1e-18)
    assert np.abs(added[:, [0, 2]]).max() < 1e-18
    # the Jacobian is exact: a finite difference agrees
    jac = model.jacobian(p)
    step = np.zeros_like(p)
    step[-1] = 1e-7
    numeric = (model.predict(p + step) - model.predict(p - step)) / 2e-7
    np.testing.assert_allclose(jac[:, :, -1], numeric, atol=1e-9)


def _with_temperature(data, seed=1):
    rng = np.random.default_rng(seed)
    temperature = np.round(20 + 5 * rng.random(data.n_positions), 3)
    return data.replace(extra={"temperature_c": temperature})


def test_every_probe_of_the_structure_search_has_an_effect_spec_that_fit_accepts(encoder_data):
    data = _with_temperature(encoder_data)
    family = OrientationFamily(data)
    probes = family.probes(fit_orientation(data))
    specs = [p.effect_spec for p in probes]
    assert all(specs)
    # One spec, one shape: probes share a spec only when their errors enter the measured angles
    # alike (dphi_y1 and deps_y on this table), and then their columns span the same shape,
    # named after the most physical error (an encoder's k/rev term, not an orthogonality's).
    for spec in set(specs):
        twins = [p.matrix() for p in probes if p.effect_spec == spec]
        joined = np.concatenate(twins, axis=1)
        # alike to first order: at the fitted errors they differ by a part 1e-7 of their size
        tol = 1e-6 * np.linalg.norm(joined, 2)
        assert np.linalg.matrix_rank(joined, tol=tol) == np.linalg.matrix_rank(twins[0]), spec
    shapes = {s.split("~")[1].split("(")[0] for s in specs}
    assert {"h1", "h5", "poly2", "sign"} <= shapes
    assert {"dpsi~h1(phi1+phi2)", "dgamma~h2(phi1-phi2)", "dtheta~poly2(time_s)",
            "dpsi~sign(dir2)", "dalpha_x1~poly2(temperature_c)",
            "dgamma~poly2(temperature_c)", "dphi_y1~h3(phi1)"} <= set(specs)  # fmt: skip
    assert "deps_y~h3(phi1)" not in specs
    for probe in probes:
        (effect,) = resolve_effects([probe.effect_spec])
        assert effect.name == probe.effect_spec
        # the effect spans the probe's shape: its Jacobian columns, weighted like the residuals,
        # and the probe's columns differ by a part the base model absorbs
        model = OrientationModel(data.variables(), [effect])
        jac = model.jacobian(np.zeros(model.n_params)).reshape(-1, model.n_params)
        cols = probe.matrix()
        q, _ = np.linalg.qr(jac)
        left = cols - q @ (q.T @ cols)
        assert np.linalg.norm(left) < 1e-6 * np.linalg.norm(cols), probe.name


@pytest.mark.parametrize(
    "spec, values, found",
    [
        # dphi_z2 turns the payload about its own z axis: the search may name it as dalpha_z1 or
        # dtheta itself, shapes the same on orientation data
        ("dphi_z2~h3(phi2)", {"c3": 3.0, "s3": -2.0}, "~h3(phi2)"),
        ("dalpha_x1~poly1(temperature_c)", {"p1": 1.5}, "~poly2(temperature_c)"),
    ],
)
def test_effect_spec_round_trip_a_planted_term_falls_to_the_noise(encoder_data, spec, values,
                                                                   found):  # fmt: skip
    data = _plant(_with_temperature(encoder_data), spec, values)
    catalogued = fit_orientation(data, [EFFECTS["inner_encoder_harmonics"]])
    diagnosis = diagnose_measurements(data)
    out = diagnosis.to_dict()
    assert out["verdict"]["missing_effect"] == "inner_encoder_harmonics"
    terms = out["verdict"]["remaining_structure"]
    assert terms and terms[0]["effect_spec"].endswith(found)
    effects = resolve_effects(["inner_encoder_harmonics", terms[0]["effect_spec"]])
    after = fit_orientation(data, effects).to_dict()
    assert catalogued.to_dict()["chi2_reduced"] > 2
    assert 0.75 < after["chi2_reduced"] < 1.25
    assert after["p_value"] > 0.001
    text = "\n".join(diagnosis_lines(out, data="run.csv"))
    assert (  # from Python, the Python call (the command line prints its shell command)
        "fit('run.csv', effects='inner_encoder_harmonics,"
        f"{','.join(t['effect_spec'] for t in terms)}')"
    ) in text


TILT_MODULE = '''\
"""A tilt of the outer axis that grows with the temperature of the room."""
from turntable_pin.measurement.effects.base import ARCSEC, ChainTerm, Effect, ParameterSpec


class TemperatureTilt(Effect):
    name = "temperature_tilt"
    title = "outer axis tilts as the room warms"
    definition = "dalpha_x1 += k (temperature_c - 20)"
    explanation = "The base plate bends as it warms."
    confirm = "Log a level on the base plate while the room warms."
    required_columns = ("temperature_c",)

    def parameters(self, variables):
        return (ParameterSpec("k", "arcsec/degC", ARCSEC, "tilt per degree"),)

    def chain_terms(self, variables):
        t = variables.column("temperature_c") - 20.0
        return (ChainTerm("dalpha_x1", None, {"k": t}),)
'''


class Settling(Effect):
    """A user's effect passed as an object: the payload settles about z once, at dir1 = -1."""

    name = "settling"
    title = "payload settles on reversal"
    definition = "Rt -> Rt Rz(a (1 - dir1) / 2)"
    explanation = "A loose fixture."
    confirm = "Tighten the fixture."
    required_columns = ("dir1",)

    def parameters(self, variables):
        return (ParameterSpec("a", "arcsec", ARCSEC, "settling"),)

    def chain_terms(self, variables):
        return (ChainTerm("post", "z", {"a": (1 - variables.dirs[0]) / 2}),)


def test_a_module_effect_is_fitted_and_named_by_the_diagnosis(tmp_path, encoder_data):
    (effect,) = load_effects_module(write_file(tmp_path, TILT_MODULE, "tilt.py"))
    assert effect.name == "temperature_tilt"
    data = _with_temperature(encoder_data, seed=2)
    model = OrientationModel(data.variables(), [effect])
    data = data.replace(angles_rad=data.angles_rad + model.predict(
        model.parameter_vector({"temperature_tilt.k": 2 * ARCSEC})))  # fmt: skip
    fit = fit_orientation(data, [EFFECTS["inner_encoder_harmonics"], effect])
    assert fit.to_dict()["params"]["temperature_tilt.k"]["value"] == pytest.approx(2, abs=0.2)
    catalogue = (*EFFECTS.values(), effect)
    out = diagnose_measurements(data, catalogue=catalogue, until_explained=True).to_dict()
    assert set(out["verdict"]["missing_effects"]) == {"temperature_tilt", "inner_encoder_harmonics"}
    assert not out["verdict"]["unexplained"]


def test_a_user_effect_object_reaches_the_reports_without_a_global_registry(encoder_data):
    data = encoder_data.replace(angles_rad=encoder_data.angles_rad.copy())
    model = OrientationModel(data.variables(), [Settling()])
    data = data.replace(angles_rad=data.angles_rad + model.predict(
        model.parameter_vector({"settling.a": 6 * ARCSEC})))  # fmt: skip
    out = diagnose_measurements(data, catalogue=(Settling(),)).to_dict()
    assert out["verdict"]["missing_effect"] == "settling"
    assert out["verdict"]["effect_story"]["title"] == "payload settles on reversal"
    text = "\n".join(diagnosis_lines(out))
    assert "settling (payload settles on reversal)" in text  # a partial explanation here


def test_user_effects_may_not_take_a_catalogue_name_or_each_others(tmp_path):
    clash = write_file(tmp_path, INNER_ENCODER_FILE.replace("my_inner_encoder", "backlash"),
                       "clash.yaml")  # fmt: skip
    with pytest.raises(InputError, match="already in the catalogue"):
        check_user_effects([read_effect_file(clash)])
    twice = read_effect_file(write_file(tmp_path, INNER_ENCODER_FILE, "a.yaml"))
    with pytest.raises(InputError, match="also defined by"):
        check_user_effects([twice, twice])
    with pytest.raises(InputError, match="listed twice"):
        resolve_effects(["dphi_z2~h3(phi2)", "dphi_z2~h3(phi2)"])


@pytest.mark.parametrize(
    "text, message",
    [
        ("dphi_z2~h3", "expected SITE~hK(VAR)"),
        ("dphi_q~h3(phi2)", "unknown site 'dphi_q'"),
        ("dphi_z2~h3(phi3)", "expected a joint angle (phi1, phi2)"),
        ("dphi_z2~h0(phi2)", "harmonic orders [0]"),
        ("dphi_z2~h3..1(phi2)", "is empty"),
        ("dpsi~poly0(time_s)", "degree 0"),
        ("dpsi~poly1(phi1)", "use harmonics for a joint angle"),
        ("dpsi~sign(time_s)", "expected an approach direction"),
        ("dpsi~sign1(dir1)", "sign takes no order"),
        ("post.w~h1(phi1)", "unknown site 'post.w'"),
    ],
)
def test_bad_inline_terms_are_refused_in_one_line(text, message):
    with pytest.raises(InputError, match=message.replace("(", r"\(").replace(")", r"\)")
                       .replace("[", r"\[").replace("]", r"\]")) as exc:  # fmt: skip
        resolve_effects([text])
    assert "\n" not in str(exc.value) and text in str(exc.value)


def test_no_installed_effects_here_and_entry_points_are_read_only_when_asked(monkeypatch):
    import importlib.metadata

    calls = []

    class Entry:
        name, value = "settling", "tests:Settling"

        def load(self):
            calls.append(1)
            return Settling

    def entry_points(group):
        return [Entry()] if group == "turntable_pin.effects" else []

    monkeypatch.setattr(importlib.metadata, "entry_points", entry_points)
    resolve_effects(["inner_encoder_harmonics"])
    assert calls == []
    (effect,) = resolve_effects(["settling"])
    assert isinstance(effect, Settling) and calls == [1]
    assert [e.name for e in installed_effects()] == ["settling"]


def test_the_user_effect_api_is_the_catalogues(encoder_data):
    # Effect, ChainTerm and ParameterSpec are the ones the catalogue uses: nothing else to learn.
    assert isinstance(inline_effect("dpsi~h1(phi1)"), Effect)
    assert ChainTerm("post", "z").weights == {}
    assert ParameterSpec("k", "arcsec", ARCSEC, "").per_user_unit == ARCSEC


PLAUSIBLE_FILE = (
    INNER_ENCODER_FILE
    + """\
plausible:
  turntable: 20
  telescope_mount: 120
  belief: an inner encoder disc reading {amplitude} wrong
"""
)


def test_an_effect_file_declares_its_plausible_scale_and_the_diagnosis_uses_it(
    tmp_path, encoder_data
):
    """Issue 29: the ``plausible`` key; a fit beyond it is marked implausible and not named."""
    effect = read_effect_file(write_file(tmp_path, PLAUSIBLE_FILE, "effect.yaml"))
    (group,) = effect.plausibility
    assert group.scale == {"turntable": 20.0, "telescope mount": 120.0} and group.unit == "arcsec"
    assert effect.implausibility({"c1": 30.0}, "turntable") == (
        "an inner encoder disc reading 30 arcsec wrong (where a turntable reaches about 20 arcsec)"
    )
    assert effect.implausibility({"c1": 30.0}, "telescope mount") is None
    model = OrientationModel(encoder_data.variables(), [effect])
    planted = model.predict(model.parameter_vector({f"{effect.name}.c1": 25.0 * ARCSEC}))
    strong = encoder_data.replace(angles_rad=encoder_data.angles_rad + planted)
    tight = diagnose_measurements(strong, catalogue=(effect,))
    assert tight.missing_effect is None and tight.to_dict()["verdict"]["implausible"]
    loose = read_effect_file(write_file(tmp_path, INNER_ENCODER_FILE, "loose.yaml"))
    assert diagnose_measurements(strong, catalogue=(loose,)).missing_effect == loose.name


@pytest.mark.parametrize(
    "extra, words",
    [
        ("plausible: 20\n", "plausible: expected a mapping of turntable, telescope_mount, any"),
        ("plausible: {table: 20}\n", "plausible.table: unknown key"),
        ("plausible: {turntable: -1}\n", "plausible.turntable: expected a number > 0"),
        ("plausible: {belief: 'x {amplitude}'}\n", "plausible: no scale given"),
        ("plausible: {turntable: 5, belief: 'no amplitude'}\n", "plausible.belief: expected"),
    ],
)
def test_a_bad_plausible_key_is_refused_naming_it(tmp_path, extra, words):
    with pytest.raises(InputError, match=re.escape(words)):
        read_effect_file(write_file(tmp_path, INNER_ENCODER_FILE + extra, "effect.yaml"))

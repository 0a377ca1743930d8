"""The paper's nine effect names are the generic effects on the paper's joints: each one predicts
the same orientation error, with the same Jacobian, as the generic effect(s) it names (parameters
mapped as the paper ties them), and every name and per-joint alias resolves to it."""

from __future__ import annotations

import numpy as np
import pytest

from rounding import chain_factors, chain_rounding
from turntable_pin.calibration.positions import PositionSet
from turntable_pin.measurement.catalogue import _determined, catalogue, joint_effect, resolve_effect
from turntable_pin.measurement.effect_model import OrientationModel
from turntable_pin.measurement.effects import EFFECT_NAMES, EFFECTS, PositionVariables, get_effect
from turntable_pin.measurement.effects.base_rotation import BaseRotation
from turntable_pin.measurement.effects.gravity_compliance import GravityCompliance
from turntable_pin.measurement.effects.payload_mount import PayloadMount
from turntable_pin.measurement.effects.thermal_drift import ThermalDrift
from turntable_pin.measurement.table import measured_table
from turntable_pin.model.paper_table import PAPER_EFFECTS

PAPER = measured_table()
OUTER, INNER = PAPER.joints


def _harmonics(prefix_from: str, prefix_to: str) -> dict[str, tuple[str, float]]:
    return {f"{prefix_from}{c}": (f"{prefix_to}{c}", 1.0) for c in ("c1", "s1", "c2", "s2")}


# Each paper effect: the generic effects it is, and {generic parameter: (paper parameter, coef)}.
GENERIC = {
    "outer_encoder_harmonics": (
        [joint_effect("encoder_harmonics", OUTER)], _harmonics("encoder_harmonics@outer_axis.", "")
    ),
    "inner_encoder_harmonics": (
        [joint_effect("encoder_harmonics", INNER)], _harmonics("encoder_harmonics@inner_axis.", "")
    ),
    "outer_wobble_harmonics": (
        [joint_effect("wobble_harmonics", OUTER)],
        _harmonics("wobble_harmonics@outer_axis.a_", "x_")
        | _harmonics("wobble_harmonics@outer_axis.b_", "z_"),
    ),
    "inner_wobble_harmonics": (
        [joint_effect("wobble_harmonics", INNER)],
        _harmonics("wobble_harmonics@inner_axis.a_", "x_")
        | _harmonics("wobble_harmonics@inner_axis.b_", "y_"),
    ),
    "gravity_sag": (
        [GravityCompliance(PAPER.rotation, ("k_xy", "k_yx"))],
        {"gravity_sag.k_xy": ("k", -1.0), "gravity_sag.k_yx": ("k", 1.0)},
    ),
    "base_tilt": (
        [BaseRotation(("x", "z"))], {"base_tilt.tx": ("tx", 1.0), "base_tilt.tz": ("tz", 1.0)}
    ),
    "thermal_drift": (
        [ThermalDrift()], {f"thermal_drift.r{a}": (f"r{a}", 1.0) for a in "xyz"}
    ),
    "backlash": (
        [joint_effect("backlash", OUTER), joint_effect("backlash", INNER)],
        {"backlash@outer_axis.b": ("b1", 1.0), "backlash@inner_axis.b": ("b2", 1.0)},
    ),
    "payload_mount": (
        [PayloadMount()], {f"payload_mount.m{a}": (f"m{a}", 1.0) for a in "xyz"}
    ),
}  # fmt: skip


def _variables(rng, n=50):
    """Random positions of the two axes, each with a time and both approach directions."""
    phi = rng.uniform(-np.pi, np.pi, (2, n))
    dirs = tuple(rng.choice([-1.0, 1.0], (2, n)))
    return PositionVariables.of(PositionSet(*phi, time_s=rng.uniform(0, 7200, n), dirs=dirs))


@pytest.mark.parametrize("name", EFFECT_NAMES)
def test_each_paper_effect_is_the_generic_effect_on_the_papers_joints(name, rng):
    v = _variables(rng)
    generic, mapping = GENERIC[name]
    paper = OrientationModel(v, [EFFECTS[name]], PAPER)
    ours = OrientationModel(v, generic, PAPER)
    n_base = len(PAPER.base_names)
    assert paper.parameter_names[:n_base] == ours.parameter_names[:n_base]
    # Generic parameters = T @ paper parameters (a renaming; the paper's k ties two entries of K).
    t = np.zeros((ours.n_params, paper.n_params))
    t[:n_base, :n_base] = np.eye(n_base)
    for generic_name, (paper_name, coef) in mapping.items():
        t[
            ours.parameter_names.index(generic_name),
            paper.parameter_names.index(f"{name}.{paper_name}"),
        ] = coef
    assert np.all(t.any(axis=0)) and np.all(t.any(axis=1))  # every parameter mapped
    scale = np.array([1e-7 if s.unit == "arcsec/h" else 1e-3 for s in paper.parameter_specs])
    p = rng.normal(0.0, 1.0, paper.n_params) * scale  # large: the exact chain, not first order
    np.testing.assert_allclose(ours.predict(t @ p), paper.predict(p), rtol=0, atol=1e-12)
    np.testing.assert_allclose(ours.jacobian(t @ p) @ t, paper.jacobian(p), rtol=0, atol=1e-12)
    assert [s.unit for s in paper.parameter_specs] == [
        ours.parameter_specs[np.flatnonzero(t[:, k])[0]].unit for k in range(paper.n_params)
    ]


def test_the_generic_gravity_force_is_the_papers(rng):
    """``Rd^T e_z`` on the paper's table is ``ax = -sin(phi1) cos(phi2)``, ``ay = sin(phi1)
    sin(phi2)`` (the paper's lateral specific force, g)."""
    q = rng.uniform(-np.pi, np.pi, (1000, 2))
    force = PAPER.rotation(q)[:, 2, :]
    s1 = np.sin(q[:, 0])
    # Rd, a product of the table's placements and joint rotations, against two rotations' entries.
    rounding = chain_rounding(chain_factors(PAPER)) + chain_rounding(2)
    np.testing.assert_allclose(force[:, 0], -s1 * np.cos(q[:, 1]), rtol=0, atol=rounding)
    np.testing.assert_allclose(force[:, 1], s1 * np.sin(q[:, 1]), rtol=0, atol=rounding)
    np.testing.assert_allclose(force[:, 2], np.cos(q[:, 0]), rtol=0, atol=rounding)


def test_the_papers_base_tilt_axes_are_those_the_generic_rule_keeps():
    assert _determined(PAPER, BaseRotation()) == ("tx", "tz")
    assert EFFECTS["base_tilt"].axes == ("x", "z")


def test_the_papers_names_resolve_to_its_catalogue():
    assert EFFECT_NAMES == tuple(e.name for e in PAPER_EFFECTS) == tuple(EFFECTS)
    assert tuple(e.name for e in catalogue()) == EFFECT_NAMES
    assert tuple(catalogue()) == tuple(EFFECTS.values())
    for name in EFFECT_NAMES:
        assert resolve_effect(name) is EFFECTS[name] is get_effect(f" {name} ")
    for named in PAPER_EFFECTS:  # per-joint names of the paper's single-joint effects
        if len(named.joints) == 1:
            alias = f"{named.kind}@{named.joints[0]}"
            assert resolve_effect(alias) is EFFECTS[named.name], alias
    # The paper's backlash is both joints'; one joint's is its own effect.
    assert EFFECTS["backlash"].joints == ("outer_axis", "inner_axis")
    one = resolve_effect("backlash@outer_axis")
    assert one.name == "backlash@outer_axis" and one.required_columns == ("dir1",)


def test_the_paper_texts_and_parameters_are_the_papers():
    v = _variables(np.random.default_rng(0), 3)
    story = EFFECTS["gravity_sag"].describe()
    assert story["definition"].startswith("Rt -> Rt Rx(-k ay) Ry(k ax)")
    assert [s.name for s in EFFECTS["gravity_sag"].parameters(v)] == ["k"]
    assert [s.name for s in EFFECTS["inner_wobble_harmonics"].parameters(v)][::4] == [
        "x_c1",
        "y_c1",
    ]
    assert [s.description for s in EFFECTS["backlash"].parameters(v)] == [
        "outer-axis backlash",
        "inner-axis backlash",
    ]
    # Other tables tell the generic story, without the paper's error names.
    assert "dalpha_y2" in EFFECTS["payload_mount"].explanation
    assert "dalpha_y2" not in PayloadMount().explanation


def test_tied_compliance_entries_are_checked():
    with pytest.raises(ValueError, match="not entries of K"):
        GravityCompliance(PAPER.rotation, {"k": {"k_xw": 1.0}})
    with pytest.raises(ValueError, match="do not name the parameters"):
        GravityCompliance(PAPER.rotation, {"k": {"k_xy": 1.0}}, labels=(("q", "?"),))

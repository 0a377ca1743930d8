"""The effect catalogue: names of the spec, complete stories, and chain changes as the spec defines.

Each effect's prediction is checked against an independent construction: Pinocchio forward
kinematics of the paper's table per position (errors replaced as the spec says) and the spec's
extra rotation matrices multiplied explicitly.
"""

import numpy as np
import pytest

import spec_reference as ref
from turntable_pin import TurntableErrors
from turntable_pin.calibration.positions import PositionSet
from turntable_pin.core.exceptions import InputError
from turntable_pin.core.rotations import rot_x, rot_y, rot_z
from turntable_pin.measurement.effect_model import OrientationModel
from turntable_pin.measurement.effects import EFFECT_NAMES, EFFECTS, PositionVariables, get_effect
from turntable_pin.model.errors import ANGULAR_ERROR_NAMES
from turntable_pin.model.paper_table import paper_table

SPEC_NAMES = (
    "outer_encoder_harmonics", "inner_encoder_harmonics", "outer_wobble_harmonics",
    "inner_wobble_harmonics", "gravity_sag", "base_tilt", "thermal_drift", "backlash",
    "payload_mount",
)  # fmt: skip


def test_catalogue_has_the_spec_names_and_stories():
    assert set(EFFECT_NAMES) == set(SPEC_NAMES)
    for effect in EFFECTS.values():
        story = effect.describe()
        for key in ("title", "definition", "explanation", "confirm"):
            assert len(story[key]) > 20 or key == "title", (effect.name, key)
    with pytest.raises(InputError, match="catalogued effects"):
        get_effect("gravity_sagg")


def _variables(rng, n=7):
    return PositionVariables.of(
        PositionSet(
            rng.uniform(-np.pi, np.pi, n),
            rng.uniform(-np.pi, np.pi, n),
            time_s=rng.uniform(0, 7200, n),
            dirs=(rng.choice([-1.0, 1.0], n), rng.choice([-1.0, 1.0], n)),
        )
    )


def _independent(effect, v, base, p, i):
    """dpsi, dtheta, dgamma at position i from the spec's words, via per-call Pinocchio."""
    e = dict(zip(ANGULAR_ERROR_NAMES, base, strict=True))
    phi1, phi2 = v.joint_rad[:, 0][i], v.joint_rad[:, 1][i]
    pre, post = np.eye(3), np.eye(3)
    if effect == "outer_encoder_harmonics":
        e["dphi_y1"] += ref.h(phi1, p["c1"], p["s1"], p["c2"], p["s2"])
    elif effect == "inner_encoder_harmonics":
        e["dphi_z2"] += ref.h(phi2, p["c1"], p["s1"], p["c2"], p["s2"])
    elif effect == "outer_wobble_harmonics":
        e["dalpha_x1"] += ref.h(phi1, p["x_c1"], p["x_s1"], p["x_c2"], p["x_s2"])
        e["dalpha_z1"] += ref.h(phi1, p["z_c1"], p["z_s1"], p["z_c2"], p["z_s2"])
    elif effect == "inner_wobble_harmonics":
        e["dalpha_x2"] += ref.h(phi2, p["x_c1"], p["x_s1"], p["x_c2"], p["x_s2"])
        e["dalpha_y2"] += ref.h(phi2, p["y_c1"], p["y_s1"], p["y_c2"], p["y_s2"])
    elif effect == "gravity_sag":
        ax = -np.sin(phi1) * np.cos(phi2)
        ay = np.sin(phi1) * np.sin(phi2)
        post = rot_x(-p["k"] * ay) @ rot_y(p["k"] * ax)
    elif effect == "base_tilt":
        pre = rot_x(p["tx"]) @ rot_z(p["tz"])
    elif effect == "thermal_drift":
        t = v.time_s[i]
        post = rot_z(p["rz"] * t) @ rot_y(p["ry"] * t) @ rot_x(p["rx"] * t)
    elif effect == "backlash":
        e["dphi_y1"] += p["b1"] * v.dirs[0][i] / 2
        e["dphi_z2"] += p["b2"] * v.dirs[1][i] / 2
    elif effect == "payload_mount":
        post = rot_z(p["mz"]) @ rot_y(p["my"]) @ rot_x(p["mx"])
    table = paper_table()
    rt = pre @ table.payload_pose(TurntableErrors(**e).as_array(), (phi1, phi2)).rotation @ post
    rd = table.payload_pose(None, (phi1, phi2)).rotation
    dR = rd.T @ rt
    return np.array([dR[0, 2], dR[1, 0], dR[2, 1]])


@pytest.mark.parametrize("name", SPEC_NAMES)
def test_effect_changes_the_chain_as_the_spec_defines(name, rng):
    v = _variables(rng)
    effect = EFFECTS[name]
    model = OrientationModel(v, [effect])
    base = rng.normal(0, 5e-5, 8)  # ~10 arcsec: second-order terms matter at 1e-9 rad
    specs = effect.parameters(v)
    # Large effect values (1e-3 rad; thermal 1e-7 rad/s) so that the order of factors matters.
    p = {s.name: rng.normal(0, 1e-3 if s.unit != "arcsec/h" else 1e-7) for s in specs}
    params = model.parameter_vector(
        {**dict(zip(ANGULAR_ERROR_NAMES, base, strict=True)),
         **{f"{name}.{k}": val for k, val in p.items()}}
    )  # fmt: skip
    predicted = model.predict(params)
    for i in range(v.n):
        np.testing.assert_allclose(predicted[i], _independent(name, v, base, p, i), atol=1e-14)


def test_effects_needing_columns_say_so():
    v = PositionVariables.of(PositionSet(np.zeros(3), np.zeros(3)))
    assert EFFECTS["thermal_drift"].missing_columns(v) == ("time_s",)
    assert EFFECTS["backlash"].missing_columns(v) == ("dir1", "dir2")
    only_dir2 = PositionVariables.of(PositionSet(np.zeros(3), np.zeros(3), dirs=(None, np.ones(3))))
    assert EFFECTS["backlash"].missing_columns(only_dir2) == ()
    assert [s.name for s in EFFECTS["backlash"].parameters(only_dir2)] == ["b2"]
    with pytest.raises(InputError, match="needs the column"):
        OrientationModel(v, [EFFECTS["thermal_drift"]])

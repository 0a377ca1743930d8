"""Tests of the 3-D setup scene: magnification, marker poses against the paper's chain, and what
meshcat is actually sent (decoded from its static page)."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import assert_triads_at, meshcat_transforms
from turntable_pin import InputError, TurntableErrors
from turntable_pin.core.rotations import rot_x, rot_y, rot_z
from turntable_pin.core.units import arcsec_to_rad
from turntable_pin.model.errors import ANGULAR_ERROR_NAMES
from turntable_pin.viewer.scene import (
    DEFAULT_DISPLAY_ANGLE_RAD,
    DEFAULT_DISPLAY_OFFSET_M,
    Exaggeration,
    SetupScene,
    animation_frames_rad,
    default_positions_deg,
)

EXAMPLE = TurntableErrors.from_arcsec(
    dphi_y1=2.0,
    dphi_z2=-1.5,
    dalpha_x1=3.0,
    dalpha_z1=-2.5,
    dalpha_x2=1.8,
    dalpha_y2=-2.2,
    deps_x=4.0,
    deps_y=-3.0,
    deta_mm=0.2,
)


def _h(rotation=None, translation=(0.0, 0.0, 0.0)):
    out = np.eye(4)
    if rotation is not None:
        out[:3, :3] = rotation
    out[:3, 3] = translation
    return out


def chain_of_table_3(e: TurntableErrors, phi1: float, phi2: float):
    """The paper's chain (spec model.md) written out by hand: inner-axis frame and payload pose."""
    f1 = _h(rot_y(phi1) @ rot_y(e.dphi_y1) @ rot_z(e.dalpha_z1) @ rot_x(e.dalpha_x1))
    f2 = f1 @ _h(translation=(e.deta, 0.0, 0.0)) @ _h(rot_y(e.deps_y) @ rot_x(e.deps_x))
    f3 = f2 @ _h(rot_z(phi2) @ rot_y(e.dalpha_y2) @ rot_z(e.dphi_z2) @ rot_x(e.dalpha_x2))
    return f2, f3


def test_default_magnification_makes_the_largest_angle_three_degrees():
    k = Exaggeration.for_errors(EXAMPLE)
    shown = k.apply(EXAMPLE)
    assert np.max(np.abs(shown.angular_array_rad())) == pytest.approx(DEFAULT_DISPLAY_ANGLE_RAD)
    assert k.angle_factor == pytest.approx(math.radians(3.0) / arcsec_to_rad(4.0))
    # 0.2 mm x 2700 would be 540 mm: deta is capped to the display offset instead.
    assert shown.deta == pytest.approx(DEFAULT_DISPLAY_OFFSET_M)
    for name in ANGULAR_ERROR_NAMES:
        assert getattr(shown, name) == pytest.approx(getattr(EXAMPLE, name) * k.angle_factor)


def test_magnification_of_small_deta_and_of_a_perfect_table():
    tiny = TurntableErrors.from_arcsec(deps_x=4.0, deta_mm=0.001)
    k = Exaggeration.for_errors(tiny)
    assert k.length_factor == pytest.approx(k.angle_factor)  # 2.7 mm: shown with the same factor
    assert Exaggeration.for_errors(TurntableErrors.zero()) == Exaggeration(1.0, 1.0)
    only_deta = Exaggeration.for_errors(TurntableErrors.from_arcsec(deta_mm=0.2))
    assert only_deta.angle_factor == 1.0
    assert only_deta.length_factor == pytest.approx(DEFAULT_DISPLAY_OFFSET_M / 2e-4)
    assert Exaggeration.for_errors(TurntableErrors.from_arcsec(deta_mm=0.2), 1.0).length_factor == 1
    assert Exaggeration.for_errors(EXAMPLE, 10.0, 2.0) == Exaggeration(10.0, 2.0)


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), float("inf")])
def test_magnification_must_be_positive_and_finite(bad):
    with pytest.raises(InputError, match="angle_factor"):
        Exaggeration(bad, 1.0)


@settings(max_examples=25, deadline=None)
@given(
    errors_arcsec=st.lists(st.floats(-20, 20), min_size=8, max_size=8),
    deta_mm=st.floats(-0.5, 0.5),
    phi1=st.floats(-2 * np.pi, 2 * np.pi),
    phi2=st.floats(-2 * np.pi, 2 * np.pi),
    factor=st.floats(1.0, 5000.0),
)
def test_marker_poses_follow_the_magnified_chain_of_table_3(
    errors_arcsec, deta_mm, phi1, phi2, factor
):
    errors = TurntableErrors.from_arcsec(
        deta_mm=deta_mm, **dict(zip(ANGULAR_ERROR_NAMES, errors_arcsec, strict=True))
    )
    scene = SetupScene(errors, exaggeration=Exaggeration(factor, factor / 10))
    shown = errors.as_array() * np.r_[np.full(8, factor), factor / 10]
    inner_axis, payload = chain_of_table_3(TurntableErrors.from_array(shown), phi1, phi2)
    poses = scene.poses(phi1, phi2)
    np.testing.assert_allclose(poses.actual_payload, payload, atol=1e-12)
    # The inner joint frame turns with phi2 about its own z, the axis the rod is drawn along.
    np.testing.assert_allclose(poses.actual_inner_axis, inner_axis @ _h(rot_z(phi2)), atol=1e-12)
    ideal = _h(rot_y(phi1) @ rot_z(phi2))
    np.testing.assert_allclose(poses.ideal_payload, ideal, atol=1e-12)
    np.testing.assert_allclose(poses.ideal_inner_axis, ideal, atol=1e-12)


def test_payload_visual_rides_on_the_actual_payload_frame():
    scene = SetupScene(EXAMPLE)
    model = scene.model.model
    data = model.createData()
    geom_data = scene.visual_model.createData()
    phi1, phi2 = 0.4, -1.1
    q = np.zeros(model.nq)
    q[model.joints[scene.model.outer_joint_id].idx_q] = phi1
    q[model.joints[scene.model.inner_joint_id].idx_q] = phi2
    pin.forwardKinematics(model, data, q)
    pin.updateGeometryPlacements(model, data, scene.visual_model, geom_data)
    names = [g.name for g in scene.visual_model.geometryObjects]
    body = geom_data.oMg[names.index("gyrowheel_0")].homogeneous
    # URDF: the GyroWheel cylinder's origin is 45 mm up the payload frame's z axis.
    expected = scene.poses(phi1, phi2).actual_payload @ _h(translation=(0.0, 0.0, 0.045))
    np.testing.assert_allclose(body, expected, atol=1e-12)


def test_legend_reports_the_true_error_angles():
    scene = SetupScene(EXAMPLE)
    truth = scene._true_model.orientation_error(0.5, 0.8)
    text = "\n".join(scene.legend(0.5, 0.8))
    assert f"dpsi = {truth.dpsi_rad * 206264.80624709636:.2f}" in text
    assert "x2700" in text and "x150" in text


def test_animation_frames_visit_every_position_and_close_the_loop():
    positions = default_positions_deg()
    assert len({tuple(p) for p in positions}) == 16
    frames = animation_frames_rad(positions, frames_per_move=5)
    assert frames.shape == (80, 2)
    np.testing.assert_allclose(np.degrees(frames[::5]), positions)
    steps = np.abs(np.diff(np.degrees(np.vstack([frames, frames[:1]])), axis=0))
    assert steps.max() <= 270.0 / 5 + 1e-9  # linear moves, none skipped
    with pytest.raises(InputError):
        animation_frames_rad(positions, frames_per_move=0)


def test_meshcat_receives_the_poses_of_the_model():
    scene = SetupScene(EXAMPLE)
    phi1, phi2 = 0.7, 2.1
    transforms, pid = meshcat_transforms(scene, phi1, phi2)
    poses = scene.poses(phi1, phi2)
    prefix = assert_triads_at(transforms, poses)
    np.testing.assert_allclose(
        transforms[f"{prefix}/machine/visuals/gyrowheel_0"],
        poses.actual_payload @ _h(translation=(0.0, 0.0, 0.045)),
        atol=1e-7,
    )
    # The triads really part: the magnified dR is a visible rotation (about 3 degrees or more).
    relative = poses.ideal_payload[:3, :3].T @ poses.actual_payload[:3, :3]
    angle_deg = np.degrees(np.arccos((np.trace(relative) - 1) / 2))
    assert angle_deg > 2.0
    from process_watch import alive

    assert not alive(pid)


@pytest.mark.parametrize(
    "entries, axis_tilts, axis_moves, payload_turns",
    [
        ({"deps_x": 4.0}, True, False, True),
        ({"dalpha_x1": 3.0}, True, False, True),
        ({"dphi_y1": 2.0}, True, False, True),
        ({"deta_mm": 0.2}, False, True, False),
        ({"dalpha_y2": -2.2}, False, False, True),
        ({"dphi_z2": -1.5}, False, False, True),
    ],
)
def test_what_each_error_visibly_does(entries, axis_tilts, axis_moves, payload_turns):
    """The statements of the error-effects figure's caption, marker by marker."""
    scene = SetupScene(TurntableErrors.from_arcsec(**entries))
    poses = scene.poses(math.radians(30.0), math.radians(45.0))
    axis_turn = np.linalg.norm(poses.actual_inner_axis[:3, 2] - poses.ideal_inner_axis[:3, 2])
    axis_shift = np.linalg.norm(poses.actual_inner_axis[:3, 3] - poses.ideal_inner_axis[:3, 3])
    payload_turn = np.linalg.norm(poses.actual_payload[:3, :3] - poses.ideal_payload[:3, :3])
    assert (axis_turn > 0.01) == axis_tilts
    assert (axis_shift > 0.01) == axis_moves
    assert (payload_turn > 0.01) == payload_turns

"""Tests of the 3-D setup scene: magnification, marker poses against the paper's chain, and what
meshcat is actually sent (decoded from its static page); the same scene on any table: every
bundled table has primitive visuals, the poses are those of its chain with the magnified errors,
meshcat receives them, a missing mesh becomes a box with a warning, and a snapshot is a real
picture."""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import REPO_DIR, assert_triads_at, meshcat_transforms, needs_chromium
from turntable_pin import InputError, TurntableErrors
from turntable_pin.core.rotations import rot_x, rot_y, rot_z
from turntable_pin.core.units import arcsec_to_rad
from turntable_pin.model.errors import ANGULAR_ERROR_NAMES
from turntable_pin.model.generic_table import GenericTable
from turntable_pin.model.paper_table import INNER_JOINT, OUTER_JOINT, paper_table
from turntable_pin.viewer.scene import (
    DEFAULT_DISPLAY_ANGLE_RAD,
    DEFAULT_DISPLAY_OFFSET_M,
    FALLBACK_BOX_M,
    Exaggeration,
    SetupScene,
    animation_frames_rad,
    default_positions_deg,
    missing_meshes,
    primitive_urdf,
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
    assert Exaggeration.for_errors(TurntableErrors()) == Exaggeration(1.0, 1.0)
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
    model = scene.pin_model
    data = model.createData()
    geom_data = scene.visual_model.createData()
    phi1, phi2 = 0.4, -1.1
    q = np.zeros(model.nq)
    q[model.joints[model.getJointId(OUTER_JOINT)].idx_q] = phi1
    q[model.joints[model.getJointId(INNER_JOINT)].idx_q] = phi2
    pin.forwardKinematics(model, data, q)
    pin.updateGeometryPlacements(model, data, scene.visual_model, geom_data)
    names = [g.name for g in scene.visual_model.geometryObjects]
    body = geom_data.oMg[names.index("gyrowheel_0")].homogeneous
    # URDF: the GyroWheel cylinder's origin is 45 mm up the payload frame's z axis.
    expected = scene.poses(phi1, phi2).actual_payload @ _h(translation=(0.0, 0.0, 0.045))
    np.testing.assert_allclose(body, expected, atol=1e-12)


def test_legend_reports_the_true_error_angles():
    scene = SetupScene(EXAMPLE)
    truth = paper_table().orientation_error(EXAMPLE.as_array(), (0.5, 0.8))
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


@pytest.mark.parametrize("n_joints", [1, 2, 3])
def test_the_default_tumble_turns_one_joint_per_move(n_joints):
    positions = default_positions_deg(n_joints)
    assert positions.shape == (4**n_joints, n_joints)
    assert len({tuple(p) for p in positions}) == 4**n_joints
    assert set(positions.ravel()) == {0.0, 90.0, 180.0, 270.0}
    moves = np.diff(positions, axis=0)
    assert np.all(np.count_nonzero(moves, axis=1) == 1)  # serpentine: one joint at a time
    assert np.abs(moves).max() == 90.0


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


# ---- any table ---------------------------------------------------------------------------------
MODELS = REPO_DIR / "models"
TABLES = [
    "turntable.urdf",
    "single_axis_rate_table.urdf",
    "two_axis_vertical_outer.urdf",
    "three_axis_imu_table.urdf",
]
PRIMITIVES = {"box", "cylinder", "sphere"}


@pytest.mark.parametrize("urdf", TABLES)
def test_every_bundled_table_has_primitive_visuals_on_every_moving_link(urdf):
    root = ET.parse(MODELS / urdf).getroot()
    table = GenericTable(MODELS / urdf)
    with_visuals = {
        link.get("name")
        for link in root.iter("link")
        if any(g.tag in PRIMITIVES for v in link.iter("visual") for g in v.find("geometry"))
    }
    children = {j.get("name"): j.find("child").get("link") for j in root.iter("joint")}
    for joint in table.joint_names:
        assert children[joint] in with_visuals
    assert table.payload_frame in with_visuals
    assert missing_meshes(MODELS / urdf) == []


def _errors(table):
    entries = {f"{table.joint_names[-1]}.tilt_a": 4.0, f"{table.mount}.rot_z": -3.0}
    return table.errors_from_user_units(entries)


@pytest.mark.parametrize("urdf", TABLES[1:])
def test_poses_are_the_chain_with_the_magnified_errors(urdf):
    table = GenericTable(MODELS / urdf)
    values = _errors(table)
    scene = SetupScene(values, table=table)
    k = scene.exaggeration.angle_factor
    assert k == pytest.approx(math.radians(3.0) / arcsec_to_rad(4.0))
    angles = [0.3, -1.1, 2.0][: len(table.joint_names)]
    poses = scene.poses(*angles)
    np.testing.assert_allclose(
        poses.ideal_payload[:3, :3].T @ poses.actual_payload[:3, :3],
        table.rotation_error(values * k, angles),
        atol=1e-12,
    )
    np.testing.assert_allclose(
        poses.actual_payload[:3, 3], table.payload_origin_m(values * k, angles), atol=1e-12
    )
    # The rods lie along the last joint's axis (a meshcat cylinder along y, turned onto z).
    axis = table.chain.joints[-1].axis
    ideal_joint = poses.ideal_inner_axis[:3, :3] @ [0.0, 0.0, 1.0]
    # Independent: the nominal last joint's frame times its axis.
    import pinocchio as pin

    model = table.nominal_pin_model
    data = model.createData()
    pin.forwardKinematics(model, data, table.chain.joint_vector(*angles))
    expected = data.oMi[model.getJointId(table.joint_names[-1])].rotation @ axis
    np.testing.assert_allclose(ideal_joint, expected / np.linalg.norm(expected), atol=1e-12)
    legend = scene.legend(*angles)
    assert table.joint_names[0] in legend[0] and "dgamma" in legend[2]


def test_exaggeration_of_offsets_and_of_a_perfect_table():
    table = GenericTable(MODELS / "three_axis_imu_table.urdf")
    assert Exaggeration.for_errors(table.values(), table=table).angle_factor == 1.0
    only_offset = table.errors_from_user_units({"inner_gimbal.offset_a_mm": 0.1})
    assert Exaggeration.for_errors(only_offset, table=table).length_factor == pytest.approx(300.0)
    both = table.errors_from_user_units({"inner_gimbal.offset_a_mm": 0.1, "imu_mount.rot_x": 1})
    k = Exaggeration.for_errors(both, table=table)
    assert k.length_factor == pytest.approx(min(k.angle_factor, 300.0))


def test_meshcat_receives_the_poses_of_a_three_axis_table():
    from process_watch import alive

    table = GenericTable(MODELS / "three_axis_imu_table.urdf")
    scene = SetupScene(_errors(table), table=table)
    angles = (0.4, -0.8, 1.3)
    transforms, pid = meshcat_transforms(scene, *angles)
    prefix = assert_triads_at(transforms, scene.poses(*angles))
    assert any(p.startswith(f"{prefix}/machine/visuals/") for p in transforms)
    assert not alive(pid)


def test_a_missing_mesh_is_drawn_as_a_box_with_a_warning(tmp_path):
    text = (MODELS / "single_axis_rate_table.urdf").read_text()
    first_box = re.search(r'<box size="[^"]*"/>', text).group(0)
    urdf = tmp_path / "meshy.urdf"
    urdf.write_text(text.replace(first_box, '<mesh filename="parts/housing.stl"/>', 1))
    assert missing_meshes(urdf) == ["parts/housing.stl"]
    scene = SetupScene(table=GenericTable(urdf))
    assert len(scene.warnings) == 1 and "parts/housing.stl" in scene.warnings[0]
    reference = SetupScene(table=GenericTable(MODELS / "single_axis_rate_table.urdf"))
    assert len(scene.visual_model.geometryObjects) == len(reference.visual_model.geometryObjects)
    written = primitive_urdf(urdf, tmp_path / "boxes.urdf")
    assert f'<box size="{FALLBACK_BOX_M:g} {FALLBACK_BOX_M:g} {FALLBACK_BOX_M:g}"' in (
        written.read_text()
    )
    # A mesh that exists is kept, with its absolute path.
    (tmp_path / "parts").mkdir()
    (tmp_path / "parts" / "housing.stl").write_text("solid x\nendsolid x\n")
    assert missing_meshes(urdf) == []


@pytest.mark.slow
@needs_chromium
def test_a_snapshot_of_the_three_axis_table_is_a_real_picture(tmp_path):
    pytest.importorskip("meshcat")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.image as mimage

    from turntable_pin.viewer.snapshot import render_snapshot

    table = GenericTable(MODELS / "three_axis_imu_table.urdf")
    scene = SetupScene(_errors(table), table=table)
    result = render_snapshot(scene, np.radians([30, 45, 60]), tmp_path / "t.png")
    rgb = mimage.imread(result.path)[..., :3]
    assert rgb.shape == (600, 800, 3)
    assert len(np.unique((rgb * 255).round().astype(np.uint8).reshape(-1, 3), axis=0)) > 500
    # The outer ring's blue (rgba 0.15 0.35 0.75) is in the picture.
    blue = np.all(np.abs(rgb - [0.15, 0.35, 0.75]) < 0.25, axis=-1) & (
        rgb[..., 2] > rgb[..., 0] + 0.3
    )
    assert blue.sum() > 500
    assert result.to_dict()["angles_deg"] == {
        "outer_gimbal": 30.0, "middle_gimbal": 45.0, "inner_gimbal": 60.0,
    }  # fmt: skip


def test_the_paper_table_gets_the_any_table_features(tmp_path):
    """The paper's table is the same scene: a mesh missing from a URDF with its joints is drawn
    as a box with a warning too, and the scene's table keeps the paper's names."""
    from turntable_pin.model.paper_table import paper_table

    text = (MODELS / "turntable.urdf").read_text()
    first_box = re.search(r'<box size="[^"]*"/>', text).group(0)
    urdf = tmp_path / "paper_meshy.urdf"
    urdf.write_text(text.replace(first_box, '<mesh filename="base.stl"/>', 1))
    scene = SetupScene(EXAMPLE, table=paper_table(urdf))
    assert scene.table.parameter_names[-1] == "deta" and len(scene.warnings) == 1
    assert len(scene.visual_model.geometryObjects) == len(
        SetupScene(EXAMPLE).visual_model.geometryObjects
    )
    np.testing.assert_allclose(
        scene.poses(0.3, 1.2).actual_payload, SetupScene(EXAMPLE).poses(0.3, 1.2).actual_payload,
        atol=1e-15,
    )  # fmt: skip
    assert scene.to_dict()["errors"] == EXAMPLE.to_user_units()

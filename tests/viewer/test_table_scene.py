"""The 3-D scene of any table: every bundled table has primitive visuals, the poses are those of
its chain with the magnified errors, meshcat receives them, a missing mesh becomes a box with a
warning, and a snapshot is a real picture."""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from conftest import REPO_DIR, assert_triads_at, meshcat_transforms, needs_chromium
from turntable_pin.core.units import arcsec_to_rad
from turntable_pin.model.generic_table import GenericTable
from turntable_pin.viewer.table_scene import (
    FALLBACK_BOX_M,
    TableScene,
    missing_meshes,
    primitive_urdf,
    table_exaggeration,
)

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
    scene = TableScene(table, values)
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
    assert table_exaggeration(table, table.values()).angle_factor == 1.0
    only_offset = table.errors_from_user_units({"inner_gimbal.offset_a_mm": 0.1})
    assert table_exaggeration(table, only_offset).length_factor == pytest.approx(300.0)
    both = table.errors_from_user_units({"inner_gimbal.offset_a_mm": 0.1, "imu_mount.rot_x": 1})
    k = table_exaggeration(table, both)
    assert k.length_factor == pytest.approx(min(k.angle_factor, 300.0))


def test_meshcat_receives_the_poses_of_a_three_axis_table():
    from process_watch import alive

    table = GenericTable(MODELS / "three_axis_imu_table.urdf")
    scene = TableScene(table, _errors(table))
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
    scene = TableScene(GenericTable(urdf))
    assert len(scene.warnings) == 1 and "parts/housing.stl" in scene.warnings[0]
    reference = TableScene(GenericTable(MODELS / "single_axis_rate_table.urdf"))
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

    from turntable_pin.viewer.snapshot import render_table_snapshot

    table = GenericTable(MODELS / "three_axis_imu_table.urdf")
    scene = TableScene(table, _errors(table))
    result = render_table_snapshot(scene, np.radians([30, 45, 60]), tmp_path / "t.png")
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

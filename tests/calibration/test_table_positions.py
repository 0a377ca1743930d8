"""The calibration layer on any table: positions over every joint, gravity and earth rate in the
payload frame against an independent numpy rotation product read straight from the URDF text, the
paper's table through the generic path equal to its own path, runs of other tables calibrated,
and tables whose positions cannot determine the coefficients refused."""

import xml.etree.ElementTree as ET

import numpy as np
import pytest

from conftest import REPO_DIR, write_file
from turntable_pin.calibration.drift_fit import calibrate_run, write_simulated_run
from turntable_pin.calibration.gyrowheel import GyroWheelModel
from turntable_pin.calibration.positions import EARTH_RATE_DPH, PositionSet, position_inputs
from turntable_pin.calibration.requirement import orientation_requirement
from turntable_pin.calibration.table_positions import JointPositions
from turntable_pin.core.exceptions import IdentifiabilityError, InputError
from turntable_pin.model.generic_table import GenericTable

MODELS = REPO_DIR / "models"
OTHER_TABLES = [
    "single_axis_rate_table.urdf",
    "two_axis_vertical_outer.urdf",
    "three_axis_imu_table.urdf",
]


def _rot(axis, angle):
    """Rotation by ``angle`` about the unit ``axis`` (Rodrigues), written out here."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def _rpy(r, p, y):
    return _rot([0, 0, 1], y) @ _rot([0, 1, 0], p) @ _rot([1, 0, 0], r)


def independent_payload_rotation(urdf, payload, angles_rad):
    """``Rd`` of a chain read from the URDF text: the product of origin rpy and joint rotations
    from the root to ``payload`` (no Pinocchio, no package code)."""
    root = ET.parse(urdf).getroot()
    by_child = {j.find("child").get("link"): j for j in root.iter("joint")}
    chain = []
    link = payload
    while link in by_child:
        chain.append(by_child[link])
        link = by_child[link].find("parent").get("link")
    rotation = np.eye(3)
    angles = iter(angles_rad)
    for joint in reversed(chain):
        origin = joint.find("origin")
        rpy = (
            [float(v) for v in origin.get("rpy", "0 0 0").split()]
            if origin is not None
            else [0] * 3
        )
        rotation = rotation @ _rpy(*rpy)
        if joint.get("type") in ("revolute", "continuous"):
            axis = [float(v) for v in joint.find("axis").get("xyz").split()]
            rotation = rotation @ _rot(axis, next(angles))
    return rotation


@pytest.mark.parametrize("urdf", OTHER_TABLES)
def test_gravity_and_earth_rate_in_the_payload_frame_match_an_independent_chain(urdf, rng):
    table = GenericTable(MODELS / urdf)
    n = len(table.joint_names)
    angles = rng.uniform(-np.pi, np.pi, (7, n))
    positions = JointPositions(angles, table, "random")
    latitude = 0.7
    inputs = position_inputs(positions, latitude)
    # The payload link of the URDF text: the child of the mount joint (the leaf).
    for k, q in enumerate(angles):
        rd = independent_payload_rotation(MODELS / urdf, table.payload_frame, q)
        np.testing.assert_allclose(inputs.specific_force_g[k], rd.T @ [0, 0, 1], atol=1e-14)
        rate = EARTH_RATE_DPH * np.array([np.cos(latitude), 0.0, np.sin(latitude)])
        np.testing.assert_allclose(inputs.earth_rate_dph[k], rd.T @ rate, atol=1e-12)


@pytest.mark.parametrize(
    "urdf, spec, count",
    [
        ("single_axis_rate_table.urdf", "grid:30", 12),
        ("two_axis_vertical_outer.urdf", "grid:30", 144),
        ("three_axis_imu_table.urdf", "grid:30", 1728),
        ("three_axis_imu_table.urdf", "grid:90x45x120", 4 * 8 * 3),
        ("two_axis_vertical_outer.urdf", "grid:90 x 45", 32),
    ],
)
def test_a_grid_covers_every_joint(urdf, spec, count):
    table = GenericTable(MODELS / urdf)
    positions = JointPositions.parse(table, spec)
    assert len(positions) == count == positions.distinct_count()
    assert positions.angles_rad.shape == (count, len(table.joint_names))
    steps = [float(s) for s in spec.split(":")[1].replace(" ", "").split("x")]
    steps = steps * len(table.joint_names) if len(steps) == 1 else steps
    for column, step in zip(np.degrees(positions.angles_rad).T, steps, strict=True):
        np.testing.assert_allclose(np.unique(column), np.arange(0.0, 360.0 - 1e-9, step))


@pytest.mark.parametrize("spec, fragment", [
    ("grid:30x30", "2 steps for a table of 3 joint(s)"),
    ("grid:0", "grid step must be in (0, 360]"),
    ("grid:1", "positions"),
    ("grid:a", "expected grid:STEP"),
    ("nowhere.csv", "neither a scheme"),
])  # fmt: skip
def test_bad_position_schemes_are_named(spec, fragment):
    table = GenericTable(MODELS / "three_axis_imu_table.urdf")
    with pytest.raises(InputError, match=None) as info:
        JointPositions.parse(table, spec)
    assert fragment in str(info.value)


def test_csv_positions_by_number_or_by_joint_name(tmp_path):
    table = GenericTable(MODELS / "three_axis_imu_table.urdf")
    numbered = write_file(tmp_path, "phi1_deg,phi2_deg,phi3_deg\n0,10,20\n30,40,50\n", "a.csv")
    named = write_file(
        tmp_path,
        "inner_gimbal_deg,outer_gimbal_deg,middle_gimbal_deg\n20,0,10\n50,30,40\n",
        "b.csv",
    )
    a, b = JointPositions.parse(table, str(numbered)), JointPositions.parse(table, str(named))
    np.testing.assert_allclose(a.angles_rad, b.angles_rad)
    np.testing.assert_allclose(np.degrees(a.angles_rad), [[0, 10, 20], [30, 40, 50]])
    partial = write_file(tmp_path, "phi1_deg,phi2_deg\n0,10\n", "c.csv")
    with pytest.raises(InputError, match="'phi3_deg' or 'inner_gimbal_deg'") as missing:
        JointPositions.parse(table, str(partial))
    assert missing.value.row == 1
    # The rule of the measurement files: a joint with both spellings is refused, at the header's
    # row (here after two comment lines), never resolved by a silent preference.
    both = write_file(
        tmp_path,
        "# a campaign\n# two lines\nphi1_deg,phi2_deg,phi3_deg,outer_gimbal_deg\n0,1,2,0\n",
        "d.csv",
    )
    with pytest.raises(InputError, match="joint 1 has two angle columns") as twice:
        JointPositions.parse(table, str(both))
    assert twice.value.row == 3


def test_the_paper_table_through_the_generic_path_equals_its_own_path():
    table = GenericTable(MODELS / "turntable.urdf")
    generic = position_inputs(JointPositions.parse(table, "grid:30"), 0.8)
    paper = position_inputs(PositionSet.parse("grid:30"), 0.8)
    np.testing.assert_allclose(generic.specific_force_g, paper.specific_force_g, atol=1e-15)
    np.testing.assert_allclose(generic.earth_rate_dph, paper.earth_rate_dph, atol=1e-13)
    a = orientation_requirement(0.01, JointPositions.parse(table, "grid:45"), 0.8)
    b = orientation_requirement(0.01, PositionSet.parse("grid:45"), 0.8)
    np.testing.assert_allclose(a.limits_rad, b.limits_rad, rtol=1e-9)


def test_a_run_of_the_three_axis_table_is_calibrated(tmp_path):
    table = GenericTable(MODELS / "three_axis_imu_table.urdf")
    inputs = position_inputs(JointPositions.parse(table, "grid:90x45x45"), 0.8)
    truth = GyroWheelModel.nominal()
    run = write_simulated_run(tmp_path / "run.csv", truth, inputs, noise_dph=0.0, seed=3)
    assert run.read_text().splitlines()[1].startswith("phi1_deg,phi2_deg,phi3_deg,")
    result = calibrate_run(run, 0.8, table)
    np.testing.assert_allclose(result.x.coefficients_dph, truth.x.as_array(), atol=1e-9)
    np.testing.assert_allclose(result.y.coefficients_dph, truth.y.as_array(), atol=1e-9)
    report = result.to_dict()
    assert set(report["residuals"][0]) >= {"outer_gimbal_deg", "inner_gimbal_deg"}
    assert "inner_gimbal_deg" in result.report()


@pytest.mark.parametrize(
    "urdf, fragment",
    [
        ("single_axis_rate_table.urdf", "too few distinct gravity directions"),
        ("two_axis_vertical_outer.urdf", "rank 4 < 7"),
    ],
)
def test_tables_whose_positions_cannot_determine_the_coefficients_are_refused(urdf, fragment):
    table = GenericTable(MODELS / urdf)
    with pytest.raises(IdentifiabilityError, match=fragment):
        orientation_requirement(0.01, JointPositions.parse(table, "grid:30"), 0.8)

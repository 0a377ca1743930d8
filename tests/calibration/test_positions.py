"""Test positions and the inputs at each: on the paper's table Pinocchio's payload orientation
against eq. 3; on any table positions over every joint, gravity and earth rate in the payload frame
against an independent numpy rotation product read straight from the URDF text, the paper's URDF
under the generic layout equal to the paper's table, runs of other tables calibrated, and tables
whose positions cannot determine the coefficients refused."""

import xml.etree.ElementTree as ET

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import REPO_DIR, write_file
from turntable_pin import InputError
from turntable_pin.calibration.drift_fit import calibrate_run, write_simulated_run
from turntable_pin.calibration.gyrowheel import GyroWheelModel
from turntable_pin.calibration.positions import (
    EARTH_RATE_DPH,
    PositionSet,
    position_inputs,
)
from turntable_pin.calibration.requirement import orientation_requirement
from turntable_pin.core.exceptions import IdentifiabilityError
from turntable_pin.model.generic_table import GenericTable


def eq3(phi1, phi2, lat):
    """Paper eq. 3 as printed (north-west-up initial orientation)."""
    s1, c1, s2, c2 = np.sin(phi1), np.cos(phi1), np.sin(phi2), np.cos(phi2)
    a = np.stack([-s1 * c2, s1 * s2, c1], -1)
    we = 15.041067
    w = np.stack(
        [
            we * c2 * (c1 * np.cos(lat) - s1 * np.sin(lat)),
            we * s2 * (-c1 * np.cos(lat) + s1 * np.sin(lat)),
            we * (s1 * np.cos(lat) + c1 * np.sin(lat)),
        ],
        -1,
    )
    return a, w


@given(
    phi=st.lists(st.floats(-720, 720, allow_nan=False), min_size=2, max_size=2),
    lat=st.floats(-90, 90, allow_nan=False),
)
@settings(max_examples=40, deadline=None)
def test_inputs_from_pinocchio_match_eq_3(phi, lat):
    positions = PositionSet(np.radians([phi[0]]), np.radians([phi[1]]))
    inputs = position_inputs(positions, np.radians(lat))
    a, w = eq3(np.radians(phi[0]), np.radians(phi[1]), np.radians(lat))
    np.testing.assert_allclose(inputs.specific_force_g[0], a, atol=1e-14)
    np.testing.assert_allclose(inputs.earth_rate_dph[0], w, atol=1e-12)


def test_grid_inputs_match_eq_3_and_have_unit_norm():
    positions = PositionSet.parse("grid:30")
    inputs = position_inputs(positions, np.radians(45.75))
    a, w = eq3(positions.joint_rad(1), positions.joint_rad(2), np.radians(45.75))
    np.testing.assert_allclose(inputs.specific_force_g, a, atol=1e-14)
    np.testing.assert_allclose(inputs.earth_rate_dph, w, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(inputs.earth_rate_dph, axis=1), EARTH_RATE_DPH)


def test_home_position_reads_up_and_north_components():
    # At phi1 = phi2 = 0 the payload is north-west-up: 1 g along z, we cos(lat) north, none west.
    inputs = position_inputs(PositionSet([0.0], [0.0]), np.radians(30))
    np.testing.assert_allclose(inputs.specific_force_g[0], [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(
        inputs.earth_rate_dph[0], EARTH_RATE_DPH * np.array([np.cos(np.radians(30)), 0, 0.5])
    )


def test_grid_schemes():
    grid = PositionSet.parse("grid:30")
    assert len(grid) == 144 and grid.name == "grid:30"
    assert set(np.round(np.degrees(grid.joint_rad(1)), 9)) == set(range(0, 360, 30))
    pairs = {(round(a), round(b)) for a, b in np.degrees(grid.angles_rad)}
    assert len(pairs) == 144
    mixed = PositionSet.parse("grid:90x45")
    assert len(mixed) == 4 * 8
    assert len(PositionSet.parse("grid:360")) == 1


def test_positions_from_csv_and_distinct_count(tmp_path):
    path = tmp_path / "pos.csv"
    path.write_text("phi1_deg,phi2_deg,note\n0,0,1\n360,0,2\n90,45,3\n-270,405,4\n")
    positions = PositionSet.parse(str(path))
    assert len(positions) == 4
    assert positions.distinct_count() == 2  # 360 = 0 and -270 = 90, 405 = 45


@pytest.mark.parametrize(
    "spec, fragment",
    [
        ("grid:0", "grid step must be in [1e-06, 360]"),
        ("grid:abc", "expected grid:STEP"),
        ("grid:500", "grid step must be in [1e-06, 360]"),
        ("nothing.csv", "neither a scheme (grid:STEP) nor an existing CSV file"),
        ("grid:30x30x30", "3 steps for the paper's table of 2 joints"),
        ("grid:30x", "expected grid:STEP"),
    ],
)
def test_bad_position_specs(spec, fragment):
    with pytest.raises(InputError) as info:
        PositionSet.parse(spec)
    assert fragment in str(info.value)


def test_csv_missing_column_is_named(tmp_path):
    path = tmp_path / "pos.csv"
    path.write_text("phi1_deg,phi_2\n0,0\n")
    with pytest.raises(InputError, match="missing required column.*phi2_deg"):
        PositionSet.parse(str(path))


def test_latitude_is_checked():
    with pytest.raises(InputError, match="latitude"):
        position_inputs(PositionSet([0.0], [0.0]), np.radians(95))


@pytest.mark.parametrize("spec", ["grid:30", "grid:30x45", "grid:45x30", "grid: 60 x 90"])
def test_the_paper_grid_is_the_generic_grid_of_the_paper_urdf(spec):
    paper = PositionSet.parse(spec)
    generic = PositionSet.parse(spec, GenericTable(REPO_DIR / "models" / "turntable.urdf"))
    np.testing.assert_array_equal(generic.angles_rad, paper.angles_rad)
    assert paper.name == generic.name


def test_positions_of_a_given_table_by_spec_grid_and_angles():
    table = GenericTable(REPO_DIR / "models" / "three_axis_imu_table.urdf")
    a = PositionSet.parse("grid:90x45x120", table)
    b = PositionSet.grid(90, 45, 120, table=table)
    np.testing.assert_array_equal(a.angles_rad, b.angles_rad)
    assert PositionSet(b.angles_rad, table=table, name="b").table is table


# --- any table ----------------------------------------------------------------------------------
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
    positions = PositionSet(angles, table=table, name="random")
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
    positions = PositionSet.parse(spec, table)
    assert len(positions) == count == positions.distinct_count()
    assert positions.angles_rad.shape == (count, len(table.joint_names))
    steps = [float(s) for s in spec.split(":")[1].replace(" ", "").split("x")]
    steps = steps * len(table.joint_names) if len(steps) == 1 else steps
    for column, step in zip(np.degrees(positions.angles_rad).T, steps, strict=True):
        np.testing.assert_allclose(np.unique(column), np.arange(0.0, 360.0 - 1e-9, step))


@pytest.mark.parametrize("spec, fragment", [
    ("grid:30x30", "2 steps for three_axis_imu_table.urdf of 3 joints"),
    ("grid:0", "grid step must be in [1e-06, 360]"),
    ("grid:1", "positions"),
    ("grid:a", "expected grid:STEP"),
    ("nowhere.csv", "neither a scheme"),
])  # fmt: skip
def test_bad_position_schemes_are_named(spec, fragment):
    table = GenericTable(MODELS / "three_axis_imu_table.urdf")
    with pytest.raises(InputError, match=None) as info:
        PositionSet.parse(spec, table)
    assert fragment in str(info.value)


def test_csv_positions_by_number_or_by_joint_name(tmp_path):
    table = GenericTable(MODELS / "three_axis_imu_table.urdf")
    numbered = write_file(tmp_path, "phi1_deg,phi2_deg,phi3_deg\n0,10,20\n30,40,50\n", "a.csv")
    named = write_file(
        tmp_path,
        "inner_gimbal_deg,outer_gimbal_deg,middle_gimbal_deg\n20,0,10\n50,30,40\n",
        "b.csv",
    )
    a, b = PositionSet.parse(str(numbered), table), PositionSet.parse(str(named), table)
    np.testing.assert_allclose(a.angles_rad, b.angles_rad)
    np.testing.assert_allclose(np.degrees(a.angles_rad), [[0, 10, 20], [30, 40, 50]])
    partial = write_file(tmp_path, "phi1_deg,phi2_deg\n0,10\n", "c.csv")
    with pytest.raises(InputError, match="'phi3_deg' or 'inner_gimbal_deg'") as missing:
        PositionSet.parse(str(partial), table)
    assert missing.value.row == 1
    # The rule of the measurement files: a joint with both spellings is refused, at the header's
    # row (here after two comment lines), never resolved by a silent preference.
    both = write_file(
        tmp_path,
        "# a campaign\n# two lines\nphi1_deg,phi2_deg,phi3_deg,outer_gimbal_deg\n0,1,2,0\n",
        "d.csv",
    )
    with pytest.raises(InputError, match="joint 1 has two angle columns") as twice:
        PositionSet.parse(str(both), table)
    assert twice.value.row == 3


def test_the_paper_table_through_the_generic_path_equals_its_own_path():
    table = GenericTable(MODELS / "turntable.urdf")
    generic = position_inputs(PositionSet.parse("grid:30", table), 0.8)
    paper = position_inputs(PositionSet.parse("grid:30"), 0.8)
    np.testing.assert_allclose(generic.specific_force_g, paper.specific_force_g, atol=1e-15)
    np.testing.assert_allclose(generic.earth_rate_dph, paper.earth_rate_dph, atol=1e-13)
    a = orientation_requirement(0.01, PositionSet.parse("grid:45", table), 0.8)
    b = orientation_requirement(0.01, PositionSet.parse("grid:45"), 0.8)
    np.testing.assert_allclose(a.limits_rad, b.limits_rad, rtol=1e-9)


def test_a_run_of_the_three_axis_table_is_calibrated(tmp_path):
    table = GenericTable(MODELS / "three_axis_imu_table.urdf")
    inputs = position_inputs(PositionSet.parse("grid:90x45x45", table), 0.8)
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
        orientation_requirement(0.01, PositionSet.parse("grid:30", table), 0.8)


def test_positions_carry_times_and_approach_directions():
    positions = PositionSet(
        [0.0, 0.5, 1.0], [0.0, 0.0, 0.2], time_s=[0, 60, 120], dirs=([1, -1, 1],)
    )
    assert positions.time_s.tolist() == [0.0, 60.0, 120.0]
    assert positions.dirs[0].tolist() == [1.0, -1.0, 1.0] and positions.dirs[1] is None
    assert not positions.time_s.flags.writeable
    plain = PositionSet([0.0, 0.5], [0.0, 0.0])
    assert plain.time_s is None and plain.dirs == (None, None)


@pytest.mark.parametrize(
    ("given", "fragment"),
    [
        ({"time_s": [0, 60]}, "time_s needs 3 times in [0, "),
        ({"time_s": [0, -1, 5]}, "time_s needs 3 times"),
        ({"time_s": [0, np.nan, 5]}, "time_s needs 3 times"),
        ({"dirs": ([1, 0, 1],)}, "dirs of joint 1 needs 3 values, each +1 or -1"),
        ({"dirs": (None, [1, 1])}, "dirs of joint 2 needs 3 values"),
        ({"dirs": ([1, 1, 1],) * 3}, "dirs of 3 joints, the table has 2"),
    ],
)
def test_times_and_directions_are_checked_naming_the_argument(given, fragment):
    with pytest.raises(InputError, match="positions: ") as caught:
        PositionSet([0.0, 0.5, 1.0], [0.0, 0.0, 0.2], **given)
    assert fragment in str(caught.value)


def test_random_positions_are_seeded_and_cover_every_turn():
    a, b = PositionSet.random(50, seed=4), PositionSet.random(50, seed=4)
    assert np.array_equal(a.angles_rad, b.angles_rad) and a.name == "random:50"
    assert np.all((a.angles_rad >= 0) & (a.angles_rad < 2 * np.pi))
    with pytest.raises(InputError, match="expected N >= 1"):
        PositionSet.random(0)

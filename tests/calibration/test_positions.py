"""Test positions and the inputs at each: Pinocchio's payload orientation against eq. 3."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from turntable_pin import InputError
from turntable_pin.calibration.positions import EARTH_RATE_DPH, PositionSet, position_inputs


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
    a, w = eq3(positions.phi1_rad, positions.phi2_rad, np.radians(45.75))
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
    assert set(np.round(np.degrees(grid.phi1_rad), 9)) == set(range(0, 360, 30))
    pairs = {(round(a), round(b)) for a, b in np.degrees(np.c_[grid.phi1_rad, grid.phi2_rad])}
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
        ("grid:0", "grid step must be in (0, 360]"),
        ("grid:abc", "expected grid:STEP"),
        ("grid:500", "grid step must be in (0, 360]"),
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
    from conftest import REPO_DIR
    from turntable_pin.calibration.table_positions import JointPositions
    from turntable_pin.model.generic_table import GenericTable

    paper = PositionSet.parse(spec)
    generic = JointPositions.parse(GenericTable(REPO_DIR / "models" / "turntable.urdf"), spec)
    np.testing.assert_array_equal(generic.angles_rad, np.stack([paper.phi1_rad, paper.phi2_rad], 1))
    assert paper.name == generic.name

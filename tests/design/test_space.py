"""The design space: joints' limits (URDF, --limits-deg), the grid and candidates within them."""

import numpy as np
import pytest

from turntable_pin.core.exceptions import InputError
from turntable_pin.design.space import (
    GRID_STEP_DEG,
    design_space,
    joint_ranges,
    parse_limits_deg,
)
from turntable_pin.measurement.user_effects import resolve_effects
from turntable_pin.model.paper_table import table_of


@pytest.fixture(scope="module")
def altaz():
    return table_of(_model("altaz_mount.urdf"))


def _model(name):
    from conftest import REPO_DIR

    return REPO_DIR / "models" / name


def test_limits_are_read_by_joint_name_or_angle_label():
    names = ("azimuth", "elevation")
    assert parse_limits_deg("elevation=15:90", names) == {2: (15.0, 90.0)}
    assert parse_limits_deg(" phi1 = -30:30 , phi2=0:45", names) == {1: (-30.0, 30.0),
                                                                      2: (0.0, 45.0)}  # fmt: skip


@pytest.mark.parametrize(
    "text, message",
    [
        ("elevation", "expected JOINT=LO:HI"),
        ("tilt=0:10", "unknown joint 'tilt'"),
        ("phi3=0:10", "unknown joint 'phi3'"),
        ("elevation=a:10", "must be numbers"),
        ("elevation=0:inf", "finite"),
        ("elevation=50:10", "leaves no position"),
        ("elevation=0:10,phi2=0:20", "limited twice"),
    ],
)
def test_bad_limits_are_refused_in_one_line(text, message):
    with pytest.raises(InputError, match=message) as info:
        parse_limits_deg(text, ("azimuth", "elevation"))
    assert "\n" not in str(info.value)


def test_the_urdf_limits_and_the_given_ones_meet(altaz):
    azimuth, elevation = joint_ranges(altaz)
    assert azimuth.full_turn and azimuth.source == "continuous"
    assert (elevation.low_deg, elevation.high_deg, elevation.full_turn) == (0.0, 90.0, False)
    assert elevation.source == "urdf"
    _, narrowed = joint_ranges(altaz, "elevation=15:120")  # beyond the URDF: cut to it
    assert (narrowed.low_deg, narrowed.high_deg) == (15.0, 90.0)
    with pytest.raises(InputError, match="leaves no position: the URDF limits elevation to 0"):
        joint_ranges(altaz, "elevation=100:120")
    azimuth, _ = joint_ranges(altaz, {"azimuth": (-45, 45)})
    assert (azimuth.low_deg, azimuth.high_deg, azimuth.full_turn) == (-45.0, 45.0, False)


def test_the_grid_holds_the_multiples_of_30_degrees_within_the_limits(altaz):
    azimuth, elevation = joint_ranges(altaz)
    assert np.array_equal(azimuth.grid_deg(), np.arange(0.0, 360.0, GRID_STEP_DEG))
    assert np.array_equal(elevation.grid_deg(), [0.0, 30.0, 60.0, 90.0])
    _, narrow = joint_ranges(altaz, "elevation=40:50")  # no multiple of 30 within: the ends
    assert np.array_equal(narrow.grid_deg(), [40.0, 50.0])
    _, held = joint_ranges(altaz, "elevation=45:45")
    assert np.array_equal(held.grid_deg(), [45.0])


def test_candidates_are_seeded_within_the_limits_and_hold_the_grid(altaz):
    space = design_space(altaz, limits_deg="elevation=15:90", candidates=500, seed=3)
    again = design_space(altaz, limits_deg="elevation=15:90", candidates=500, seed=3)
    other = design_space(altaz, limits_deg="elevation=15:90", candidates=500, seed=4)
    assert np.array_equal(space.candidates_deg, again.candidates_deg)
    assert not np.array_equal(space.candidates_deg, other.candidates_deg)
    elevation = space.candidates_deg[:, 1]
    assert elevation.min() >= 15.0 and elevation.max() <= 90.0
    assert np.all((space.candidates_deg[:, 0] >= 0) & (space.candidates_deg[:, 0] < 360))
    assert space.grid_deg.shape == (12 * 3, 2)  # 12 azimuths x (30, 60, 90)
    assert np.array_equal(space.candidates_deg[-36:], space.grid_deg)
    assert space.to_dict()["seed"] == 3 and space.to_dict()["n_candidates"] == 536


def test_the_effects_say_whether_the_run_needs_time_and_directions():
    table = table_of(None)
    plain = design_space(table, resolve_effects(["inner_encoder_harmonics"], table), candidates=10)
    assert not plain.needs_time and not plain.needs_dirs and plain.visits.count == 1
    both = design_space(table, resolve_effects(["thermal_drift,backlash"], table), candidates=10)
    assert both.needs_time and both.needs_dirs and both.visits.count == 2
    assert np.all((both.visits.early_fraction >= 0) & (both.visits.early_fraction < 0.5))
    assert set(np.unique(both.visits.sides)) == {-1.0, 1.0}


def test_an_effect_needing_a_column_a_design_cannot_set_is_refused():
    table = table_of(None)
    effects = resolve_effects(["dpsi~poly1(temperature_c)"], table)
    with pytest.raises(InputError, match="needs the column temperature_c, which a design cannot"):
        design_space(table, effects, candidates=10)

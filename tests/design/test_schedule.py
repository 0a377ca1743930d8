"""The chosen positions as a run (issue 19, item 3): repeats early and late for time-driven
effects, both approach sides for backlash, and a CSV that ``simulate --positions`` reads back."""

import numpy as np
import pytest

from turntable_pin.design.schedule import Visits, plan_measurements
from turntable_pin.measurement.simulation import Schedule, read_positions, simulate_measurements

POSITIONS = np.array([[90.0, 30.0], [0.0, 60.0], [45.5, 300.25], [270.0, 0.0], [180.0, 120.0]])


def test_without_time_or_direction_each_position_once_in_the_order_of_the_angles():
    plan = plan_measurements(POSITIONS)
    assert plan.n_rows == 5 and plan.rows.time_s is None and plan.rows.dirs == (None, None)
    assert np.array_equal(plan.rows.angles_deg()[:, 0], np.sort(POSITIONS[:, 0]))
    assert list(plan.rows.columns()) == ["phi1_deg", "phi2_deg"]


def test_a_time_driven_effect_measures_each_position_early_and_late():
    plan = plan_measurements(POSITIONS, needs_time=True, dwell_s=30.0, seed=2, start_s=100.0)
    assert plan.n_rows == 10 and plan.rows.dirs == (None, None)
    assert np.array_equal(plan.rows.time_s, 100.0 + 30.0 * np.arange(10))
    # A random pass, then the same pass backwards: every position's two times average to the
    # run's middle, so a drift linear in time is orthogonal to anything fixed at a position.
    assert np.array_equal(plan.position[5:], plan.position[:5][::-1])
    mean_time = [plan.rows.time_s[plan.position == p].mean() for p in range(5)]
    assert np.allclose(mean_time, plan.rows.time_s.mean())
    assert not np.array_equal(plan.position[:5], np.arange(5))  # seeded random order
    assert plan_measurements(POSITIONS, needs_time=True, seed=2).position.tolist() == (
        plan.position.tolist()
    )


def test_backlash_approaches_each_position_from_both_sides():
    plan = plan_measurements(POSITIONS, needs_dirs=True, seed=1)
    assert plan.n_rows == 10 and plan.rows.time_s is None
    for p in range(5):
        rows = plan.position == p
        assert rows.sum() == 2
        assert np.all(
            np.stack(plan.rows.dirs, axis=1)[rows].sum(axis=0) == 0
        )  # +1 and -1 for every joint
    assert set(np.unique(np.stack(plan.rows.dirs, axis=1))) == {-1.0, 1.0}


def test_both_repeat_early_and_late_from_opposite_sides_in_the_designs_order():
    visits = Visits(
        2, early_fraction=np.array([0.4, 0.1, 0.3, 0.2, 0.0]),
        sides=np.array([[1, -1], [1, 1], [-1, -1], [-1, 1], [1, 1]], dtype=float),
    )  # fmt: skip
    plan = plan_measurements(POSITIONS, needs_time=True, needs_dirs=True, visits=visits)
    assert plan.position[:5].tolist() == [4, 1, 3, 2, 0]  # by the early times chosen
    assert np.array_equal(np.stack(plan.rows.dirs, axis=1)[:5], visits.sides[plan.position[:5]])
    assert np.array_equal(
        np.stack(plan.rows.dirs, axis=1)[5:], -np.stack(plan.rows.dirs, axis=1)[:5][::-1]
    )


@pytest.mark.parametrize("time, dirs", [(False, False), (True, False), (False, True), (True, True)])
def test_the_csv_round_trips_through_the_simulator(tmp_path, time, dirs):
    plan = plan_measurements(POSITIONS, needs_time=time, needs_dirs=dirs, dwell_s=45.0, seed=5)
    path = plan.write_csv(tmp_path / "plan.csv", comment="designed for a test\nseed=5")
    assert path.read_text().startswith("# designed for a test\n# seed=5\nphi1_deg,phi2_deg")
    schedule = Schedule(**read_positions(path))
    sim = simulate_measurements(None, {"thermal_drift": {"rz": 3.0}} if time else {},
                                schedule=schedule, seed=1)  # fmt: skip
    assert np.allclose(np.degrees(sim.data.joint_rad), plan.rows.angles_deg())
    if time:
        assert np.array_equal(sim.data.time_s, plan.rows.time_s)
    for k in (0, 1):
        if dirs:
            assert np.array_equal(sim.data.dirs[k], plan.rows.dirs[k])

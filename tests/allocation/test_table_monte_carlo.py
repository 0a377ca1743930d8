"""Monte Carlo on any table: the draws stay inside the box with both signs and no offsets, each
table's worst angles equal a direct evaluation of its exact chain, and a run depends on its seed
only (not on the number of workers)."""

import numpy as np
import pytest

from conftest import REPO_DIR
from turntable_pin.allocation.solver import OrientationLimits
from turntable_pin.allocation.table_allocation import (
    allocate_table_tolerances,
    angular_names,
    grid_angles_rad,
)
from turntable_pin.allocation.monte_carlo import run_table_monte_carlo, sample_table_errors
from turntable_pin.core.exceptions import InputError
from turntable_pin.model.angles import ANGLE_ENTRIES
from turntable_pin.model.generic_table import GenericTable

MODELS = REPO_DIR / "models"
LIMITS = OrientationLimits.from_arcmin(0.6, 0.25, 0.45)


@pytest.mark.parametrize(
    "urdf",
    ["single_axis_rate_table.urdf", "two_axis_vertical_outer.urdf", "three_axis_imu_table.urdf"],
)
def test_draws_stay_within_their_bounds(urdf, rng):
    table = GenericTable(MODELS / urdf)
    names = angular_names(table)
    upper = rng.uniform(1e-5, 1e-4, len(names))
    lower = upper * rng.uniform(0.0, 0.9, len(names))
    values = sample_table_errors(table, rng, 4000, upper, lower)
    columns = [table.parameter_names.index(n) for n in names]
    drawn = np.abs(values[:, columns])
    assert np.all(drawn >= lower) and np.all(drawn <= upper)
    assert np.all((values[:, columns] > 0).mean(axis=0) > 0.4)  # both signs
    offsets = [table.parameter_names.index(n) for n in table.length_names]
    assert np.all(values[:, offsets] == 0.0)


def test_each_tables_worst_angles_equal_its_exact_chain():
    table = GenericTable(MODELS / "two_axis_vertical_outer.urdf")
    allocation = allocate_table_tolerances(table, LIMITS, grid_step_deg=30.0)
    result = run_table_monte_carlo(
        table, allocation.upper_bounds_rad, LIMITS, 5, seed=11, grid_step_deg=30.0, progress=False
    )
    # Redraw the same tables (chunk seeds as the run spawns them) and evaluate rotation_error.
    seed_seq = np.random.SeedSequence(11).spawn(1)[0]
    values = sample_table_errors(
        table, np.random.default_rng(seed_seq), 5, allocation.upper_bounds_rad, np.zeros(9)
    )
    grid = grid_angles_rad(table, 30.0)
    for k in range(5):
        d_r = table.rotation_error(values[k], grid)  # (N, 3, 3)
        angles = np.stack([d_r[:, i, j] for i, j in ANGLE_ENTRIES], axis=1)
        np.testing.assert_allclose(result.worst_rad[k], np.abs(angles).max(axis=0), atol=1e-15)
    assert result.all_within
    assert np.all(result.max_abs_rad <= allocation.worst_case_rad * (1 + 1e-3))
    assert set(result.to_dict()["upper_bounds_arcmin"]) == set(angular_names(table))


def test_a_run_depends_on_its_seed_only():
    table = GenericTable(MODELS / "single_axis_rate_table.urdf")
    upper = np.full(len(angular_names(table)), 2e-5)
    runs = [
        run_table_monte_carlo(table, upper, LIMITS, 1200, seed=5, workers=w, progress=False)
        for w in (1, 2)
    ]
    np.testing.assert_array_equal(runs[0].worst_rad, runs[1].worst_rad)
    other = run_table_monte_carlo(table, upper, LIMITS, 1200, seed=6, progress=False)
    assert not np.array_equal(other.worst_rad, runs[0].worst_rad)


def test_bad_bounds_are_refused():
    table = GenericTable(MODELS / "single_axis_rate_table.urdf")
    with pytest.raises(InputError, match="expected 6 upper and lower bounds"):
        run_table_monte_carlo(table, np.ones(8) * 1e-5, LIMITS, 10, 0, progress=False)
    with pytest.raises(InputError, match="between 0 and its upper bound"):
        run_table_monte_carlo(
            table, np.full(6, 1e-5), LIMITS, 10, 0, lower_bounds_rad=np.full(6, 2e-5),
            progress=False,
        )  # fmt: skip

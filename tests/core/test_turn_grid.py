"""The one full-turn grid and random draw (core.turn_grid) against independent constructions."""

import itertools

import numpy as np
import pytest

from turntable_pin.core.exceptions import InputError
from turntable_pin.core.turn_grid import (
    every_combination,
    full_turn_grid_deg,
    random_turn_positions_deg,
)


def test_full_turn_grid_is_every_combination_of_whole_turns_last_joint_fastest():
    grid = full_turn_grid_deg(90.0, 120.0, starts_deg=(10.0, -30.0))
    expected = [(a, b) for a, b in itertools.product([10, 100, 190, 280], [-30, 90, 210])]
    np.testing.assert_array_equal(grid, np.array(expected, dtype=float))


@pytest.mark.parametrize("step", [0.7, 1.0, 7.0, 15.0, 45.0, 360.0 / 7, 359.0, 360.0])
def test_one_joint_axis_is_the_numpy_half_open_turn(step):
    axis = full_turn_grid_deg(step)[:, 0]
    np.testing.assert_array_equal(axis, np.arange(0.0, 360.0 - 1e-9, step))


def test_three_joints_and_a_refused_step():
    assert full_turn_grid_deg(180.0, 120.0, 90.0).shape == (2 * 3 * 4, 3)
    with pytest.raises(InputError, match="grid step"):
        full_turn_grid_deg(0.0)
    with pytest.raises(ValueError, match="starts_deg"):
        full_turn_grid_deg(30.0, starts_deg=(0.0, 0.0))


def test_every_combination_keeps_any_axes():
    rows = every_combination([np.array([1.0, 2.0]), np.array([5.0])])
    np.testing.assert_array_equal(rows, [[1.0, 5.0], [2.0, 5.0]])


def test_random_positions_are_one_uniform_draw_rounded_and_shifted():
    drawn = random_turn_positions_deg(np.random.default_rng(4), 50, 3, starts_deg=(0.0, 90.0, -5.0))
    raw = np.random.default_rng(4).uniform(0.0, 360.0, (50, 3))
    np.testing.assert_array_equal(drawn, np.round(np.array([0.0, 90.0, -5.0]) + raw, 6))
    assert drawn.shape == (50, 3)
    plain = random_turn_positions_deg(np.random.default_rng(4), 50, 3)
    assert ((plain >= 0.0) & (plain <= 360.0)).all()

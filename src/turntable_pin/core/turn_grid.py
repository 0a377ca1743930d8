"""Positions over whole turns of any number of joints, in degrees: the one full-turn grid and the
one uniform random draw every layer builds its positions from (every combination of the axes,
the first joint varying slowest).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .sizes import turn_grid_count

__all__ = ["every_combination", "full_turn_grid_deg", "random_turn_positions_deg"]

RANDOM_ROUND_DECIMALS = 6
"""Random angles are rounded to 1e-6 deg (they are written to CSV files and read back)."""


def every_combination(axes: Sequence[np.ndarray]) -> np.ndarray:
    """Every combination of one angle per joint from ``axes`` (one 1-D array per joint, any
    unit): an (N, J) array, N the product of the axes' sizes, the last joint varying fastest."""
    mesh = np.meshgrid(*axes, indexing="ij")
    return np.stack([m.ravel() for m in mesh], axis=1)


def full_turn_grid_deg(*steps_deg: float, starts_deg: Sequence[float] | None = None) -> np.ndarray:
    """The full-turn grid of one or more joints, degrees: joint ``k`` takes ``start_k + i *
    step_k`` over ``[start_k, start_k + 360)`` (``starts_deg`` default 0), every combination, an
    (N, J) array (the last joint fastest). :class:`InputError` for a step below
    ``MIN_GRID_STEP_DEG``; the caller checks N against its own limit first."""
    starts = (0.0,) * len(steps_deg) if starts_deg is None else tuple(starts_deg)
    if len(starts) != len(steps_deg):
        raise ValueError(f"starts_deg: {len(starts)} starts for {len(steps_deg)} steps")
    axes = [
        start + np.arange(turn_grid_count(step)) * float(step)
        for start, step in zip(starts, steps_deg, strict=True)
    ]
    return every_combination(axes)


def random_turn_positions_deg(
    rng: np.random.Generator, count: int, n_joints: int, starts_deg: Sequence[float] | None = None
) -> np.ndarray:
    """``count`` positions (checked by the caller) of ``n_joints`` joints drawn from ``rng``
    uniformly over each whole turn ``[start, start + 360)`` degrees (one ``uniform`` draw of shape
    ``(count, n_joints)``; ``starts_deg`` default 0), rounded to 1e-6 deg."""
    draws = rng.uniform(0.0, 360.0, (int(count), int(n_joints)))
    if starts_deg is not None:
        draws = np.asarray(starts_deg, dtype=float) + draws
    return np.round(draws, RANDOM_ROUND_DECIMALS)

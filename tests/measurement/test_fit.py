"""Fitting with angles not measured: only what was measured counts, and what it cannot
determine is named."""

from __future__ import annotations

import numpy as np

from conftest import random_errors
from turntable_pin.measurement.fit import fit_orientation
from turntable_pin.measurement.simulation import simulate_measurements


def _blank(data, mask):
    angles = data.angles_rad.copy()
    angles[mask] = np.nan
    return data.replace(angles_rad=angles)


def test_without_dtheta_the_inner_position_combination_is_not_observed():
    sim = simulate_measurements(random_errors(np.random.default_rng(1)), seed=1)
    mask = np.zeros(sim.data.angles_rad.shape, bool)
    mask[:, 1] = True
    fit = fit_orientation(_blank(sim.data, mask))
    full = fit_orientation(sim.data)
    assert fit.result.n_obs == 2 * sim.data.n_positions
    assert fit.result.rank == full.result.rank - 1
    assert fit.unobserved_combinations() == ["dphi_z2 + dalpha_z1"]
    assert full.unobserved_combinations() == []
    assert {"dphi_z2", "dalpha_z1"} <= set(fit.result.undetermined_combinations())
    assert np.isnan(fit.residuals_rad[:, 1]).all() and np.isfinite(fit.residuals_rad[:, 0]).all()


def test_filling_the_empty_cells_with_the_fit_changes_nothing():
    """A property of least squares: cells not measured do not count, so filling them with the
    fitted values of the fit without them leaves that fit unchanged."""
    for seed in range(3):
        rng = np.random.default_rng(seed)
        sim = simulate_measurements(random_errors(rng), seed=seed)
        mask = rng.random(sim.data.angles_rad.shape) < 0.3
        mask[mask.all(axis=1), 0] = False  # a row needs one measured angle
        partial = fit_orientation(_blank(sim.data, mask))
        filled = sim.data.angles_rad.copy()
        filled[mask] = partial.fitted_rad()[mask]
        refit = fit_orientation(sim.data.replace(angles_rad=filled))
        np.testing.assert_allclose(refit.fitted_rad(), partial.fitted_rad(), atol=1e-13)
        assert refit.result.rss == np.float64(partial.result.rss) or np.isclose(
            refit.result.rss, partial.result.rss, rtol=1e-9
        )

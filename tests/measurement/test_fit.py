"""Fitting with angles not measured: only what was measured counts, and what it cannot
determine is named."""

from __future__ import annotations

import numpy as np
import pytest

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
        # a row without its roll measures a direction (its dpsi is the swing's); filling its
        # dgamma would change what its dpsi means, so those rows keep their dgamma here
        mask[~mask[:, 0], 2] = False
        partial = fit_orientation(_blank(sim.data, mask))
        filled = sim.data.angles_rad.copy()
        filled[mask] = partial.fitted_rad()[mask]
        refit = fit_orientation(sim.data.replace(angles_rad=filled))
        np.testing.assert_allclose(refit.fitted_rad(), partial.fitted_rad(), atol=1e-13)
        assert refit.result.rss == np.float64(partial.result.rss) or np.isclose(
            refit.result.rss, partial.result.rss, rtol=1e-9
        )


# ---- large constant offsets (a telescope mount not synced) -------------------------------------
def _gem_run(offset_deg: float, noise_arcsec: float = 1.0, seed: int = 5):
    """A German-equatorial run: hour-angle index ``offset_deg`` off, small errors, no roll."""
    from conftest import REPO_DIR
    from turntable_pin.measurement.data import OrientationMeasurements
    from turntable_pin.measurement.effect_model import OrientationModel
    from turntable_pin.measurement.effects.base import PositionVariables
    from turntable_pin.model.generic_table import GenericTable

    table = GenericTable(REPO_DIR / "models" / "german_equatorial_mount.urdf")
    rng = np.random.default_rng(seed)
    joints = np.stack([rng.uniform(-np.pi, np.pi, 200), rng.uniform(-1.2, 1.4, 200)], axis=1)
    # no roll measured: each row sees the boresight's direction (dpsi = -dR[2,0])
    no_roll = np.ones(200, dtype=bool)
    model = OrientationModel(PositionVariables(joints, boresight_only=no_roll), [], table)
    errors = {"hour_angle.position": np.radians(offset_deg), "declination.tilt_a": 1e-4}
    truth = model.parameter_vector({**errors, "tube_mount.rot_y": 7e-5})
    sigma = noise_arcsec / 206264.806
    angles = model.predict(truth) + rng.normal(0.0, sigma, (200, 3))
    angles[:, 2] = np.nan
    return table, OrientationMeasurements(joints, angles, np.full(200, sigma))


def test_gauss_newton_from_zero_converges_with_a_large_constant_offset(monkeypatch):
    import turntable_pin.stats.least_squares as least_squares

    def refuse(*args, **kwargs):
        raise AssertionError("the fit fell back to Levenberg-Marquardt")

    monkeypatch.setattr(least_squares, "_levenberg_marquardt", refuse)
    for offset_deg, most_evaluations in ((0.0, 4), (5.7, 5), (10.0, 6)):
        table, data = _gem_run(offset_deg)
        fit = fit_orientation(data, turntable=table)
        assert fit.result.chi2_reduced == pytest.approx(1.0, abs=0.25)
        assert fit.result.n_function_evaluations <= most_evaluations
        position = fit.result.params[0] - fit.result.params[5]  # hour_angle.position - dec.tilt_b
        assert position == pytest.approx(np.radians(offset_deg), abs=1e-5)


def test_a_fit_with_effects_starts_from_the_base_solution_when_offsets_are_large(monkeypatch):
    from turntable_pin.measurement import fit as fit_module
    from turntable_pin.measurement.catalogue import resolve_effect
    from turntable_pin.measurement.table import measured_table

    table, data = _gem_run(1.0)
    wobble = resolve_effect("wobble_harmonics@declination", measured_table(table), ())
    base = fit_orientation(data, turntable=table)
    with_effect = fit_orientation(data, [wobble], turntable=table)
    assert with_effect.result.rss <= base.result.rss  # it nests the base model
    # From zero alone, the minimum-norm split of the offset over the wobble's harmonics is no
    # solution: the fit ends far above the base fit it contains.
    monkeypatch.setattr(fit_module, "RELINEARISE_RAD", np.inf)
    from_zero = fit_orientation(data, [wobble], turntable=table)
    assert from_zero.result.rss > 2.0 * base.result.rss


def test_residuals_beyond_five_degrees_are_refused_naming_the_rows():
    from turntable_pin.core.exceptions import InputError

    table, data = _gem_run(5.7)
    angles = data.angles_rad.copy()
    angles[[7, 30], 1] += np.radians(12.0)  # another star
    with pytest.raises(InputError, match=r"row\(s\) 9, 32 of the data: the best fit of the "):
        fit_orientation(data.replace(angles_rad=angles), turntable=table)


def test_the_same_shape_given_twice_is_refused_naming_both():
    # Issue 21: a catalogue name and an inline term of the same shape showed a lower rank silently.
    from conftest import EXAMPLES_DIR
    from turntable_pin.core.exceptions import InputError
    from turntable_pin.measurement.data import read_measurements
    from turntable_pin.measurement.fit import refuse_repeated_shapes
    from turntable_pin.measurement.user_effects import resolve_effects

    data = read_measurements(EXAMPLES_DIR / "measurements_example.csv")
    twice = resolve_effects(["inner_encoder_harmonics", "dphi_z2~h1(phi2)"])
    with pytest.raises(InputError, match="dphi_z2~h1\\(phi2\\).*inner_encoder_harmonics"):
        refuse_repeated_shapes(data, twice)
    refuse_repeated_shapes(data, resolve_effects(["inner_encoder_harmonics", "dphi_z2~h3(phi2)"]))
    refuse_repeated_shapes(data, resolve_effects(["inner_encoder_harmonics", "backlash"]))

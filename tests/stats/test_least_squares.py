"""The generic weighted fit: against numpy on a linear toy problem, and on orientation data."""

import numpy as np
import pytest

from turntable_pin import IdentifiabilityError, TurntableErrors
from turntable_pin.measurement.effects import EFFECTS
from turntable_pin.measurement.fit import fit_orientation
from turntable_pin.measurement.simulation import simulate_measurements
from turntable_pin.stats.least_squares import combination_name, fit_least_squares


class LinearToy:
    """y = a + b x + c x + d x^2: b and c only enter as b + c."""

    parameter_names = ("a", "b", "c", "d")
    parameter_units = ("u",) * 4
    per_user_unit = np.ones(4)
    user_unit_scale = 1.0

    def __init__(self, x, y, sigma):
        self.x, self.observed, self.sigma = x, y, sigma
        self.design = np.stack([np.ones_like(x), x, x, x**2], axis=1)

    def predict(self, p):
        return self.design @ p

    def jacobian(self, p):
        return self.design


def test_linear_toy_against_numpy(rng):
    x = np.linspace(-1, 1, 40)
    sigma = rng.uniform(0.5, 2.0, x.size)
    y = 1.0 + 3.0 * x - 0.5 * x**2 + rng.normal(0, sigma)
    result = fit_least_squares(LinearToy(x, y, sigma))
    assert result.rank == 3 and result.dof == 37
    names = [c["name"] for c in result.combinations()]
    assert names == ["a", "b + c", "d"]
    assert result.undetermined_combinations() == ["b - c"]
    # numpy on the reduced design [1, x, x^2], weighted
    design = np.stack([np.ones_like(x), x, x**2], axis=1) / sigma[:, None]
    coef, rss, *_ = np.linalg.lstsq(design, y / sigma, rcond=None)
    values = [c["value"] for c in result.combinations()]
    np.testing.assert_allclose(values, coef, rtol=1e-9)
    # scipy's cost is 0.5 sum f^2: rss must be the plain sum of squares, not cost or cost^2
    assert result.rss == pytest.approx(float(rss[0]), rel=1e-9)
    assert result.rss == pytest.approx(np.sum((result.residuals * result.weights) ** 2), rel=1e-12)
    cov = np.linalg.inv(design.T @ design)
    np.testing.assert_allclose(
        [c["std"] for c in result.combinations()], np.sqrt(np.diag(cov)), rtol=1e-6
    )
    assert result.chi2_reduced == pytest.approx(float(rss[0]) / 37)
    assert 0 < result.p_value < 1
    # unknown sigma: unit weights, variance estimated, chi2_reduced 1 by construction, no p-value
    unknown = fit_least_squares(LinearToy(x, y, None))
    assert unknown.chi2_reduced == pytest.approx(1.0) and unknown.p_value is None


def test_combination_names():
    names = ("p", "q", "r")
    assert combination_name(np.array([1.0, -1.0, 0.0]), names) == "p - q"
    assert combination_name(np.array([0.0, 1.0, 0.5]), names) == "q + 0.5 r"


def test_too_few_observations():
    x = np.array([0.0, 1.0])
    with pytest.raises(IdentifiabilityError, match="degree of freedom"):
        fit_least_squares(LinearToy(x, np.array([1.0, 2.0]), None))


BASE_COMBINATIONS = [
    "dphi_y1 + deps_y", "dphi_z2 + dalpha_z1", "dalpha_x1 + deps_x", "dalpha_x2", "dalpha_y2",
]  # fmt: skip


def test_orientation_data_determine_five_combinations_of_the_eight_errors():
    fit = fit_orientation(simulate_measurements(seed=0).data)
    assert fit.result.rank == 5 and fit.result.n_params == 8
    assert [c["name"] for c in fit.result.combinations()] == BASE_COMBINATIONS
    assert fit.result.undetermined_combinations() == [
        "dphi_y1 - deps_y", "dphi_z2 - dalpha_z1", "dalpha_x1 - deps_x",
    ]  # fmt: skip
    table = fit.to_dict()
    for key in ("rms_arcsec", "chi2_reduced", "params", "identifiable", "p_value"):
        assert key in table
    assert table["params"]["dalpha_x2"]["determined_alone"]
    assert not table["params"]["deps_x"]["determined_alone"]


def test_fit_recovers_the_identifiable_combinations_within_their_standard_errors():
    from conftest import random_errors

    rng = np.random.default_rng(42)
    z = []
    effect = EFFECTS["inner_encoder_harmonics"]
    for seed in range(25):
        errors = random_errors(rng)
        truth = {"c1": rng.uniform(-3, 3), "s1": rng.uniform(-3, 3), "c2": 1.0, "s2": -2.0}
        sim = simulate_measurements(errors, {effect.name: truth}, seed=seed)
        fit = fit_orientation(sim.data, [effect])
        p_true = fit.model.parameter_vector(
            {**dict(zip(fit.model.parameter_names[:8], errors.angular_array_rad(), strict=True)),
             **{f"{effect.name}.{k}": v / 206264.80624709636 for k, v in truth.items()}}
        )  # fmt: skip
        res = fit.result
        for row, combo in zip(res.identifiability.determined, res.combinations(), strict=True):
            pivot = np.flatnonzero(row)[0]
            true_value = row @ p_true / res.per_user_unit[pivot]
            z.append((combo["value"] - true_value) / combo["std"])
    z = np.asarray(z)
    assert z.size == 25 * 9
    assert np.all(np.abs(z) < 4.5)
    assert 0.7 < np.mean(z**2) < 1.35  # the standard errors are the real scatter
    assert abs(np.mean(z)) < 0.25


def test_sigma_estimated_when_absent():
    sim = simulate_measurements(TurntableErrors.from_arcsec(dalpha_y2=5), noise_arcsec=2.0, seed=3)
    fit = fit_orientation(sim.data.without_sigma())
    assert fit.result.chi2_reduced == pytest.approx(1.0)
    assert np.median(fit.sigma_rad) * 206264.8 == pytest.approx(2.0, rel=0.1)
    assert fit.to_dict()["p_value"] is None and fit.to_dict()["sigma_source"] == "estimated"

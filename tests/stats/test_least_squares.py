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


def _simulated(effects=None, n_step=30.0):
    from turntable_pin.measurement.simulation import Schedule

    errors = TurntableErrors.from_arcsec(dphi_y1=5, dalpha_x2=-6, deps_x=7, dalpha_z1=4)
    schedule = Schedule(n_step, n_step, order="random")
    return simulate_measurements(errors, effects or {}, schedule=schedule, seed=4).data


def test_gauss_newton_and_chord_steps_reach_the_levenberg_marquardt_solution(monkeypatch):
    """The fast iteration (one Jacobian per fit) against scipy's LM from the same start."""
    import turntable_pin.stats.least_squares as ls

    data = _simulated({"inner_encoder_harmonics": {"c1": 3.0, "s2": -2.0}})
    for effects in ([], [EFFECTS["inner_encoder_harmonics"]], [EFFECTS["outer_wobble_harmonics"]]):
        fast = fit_orientation(data, effects).result
        with monkeypatch.context() as patch:
            patch.setattr(ls, "_iterate", lambda *args: None)
            slow = fit_orientation(data, effects).result
        assert fast.rank == slow.rank
        assert fast.rss == pytest.approx(slow.rss, rel=1e-9)
        std = np.sqrt(np.diag(slow.covariance))
        determined = slow.individually_determined()
        assert np.all(np.abs(fast.params - slow.params)[determined] <= 1e-5 * std[determined])
        scale = np.abs(slow.covariance).max()
        np.testing.assert_allclose(fast.covariance, slow.covariance, rtol=0, atol=1e-6 * scale)


def test_a_shared_zero_point_gives_the_same_fits():
    from turntable_pin.measurement.fit import orientation_zero_point

    data = _simulated({"gravity_sag": {"k": 3.0}})
    shared = orientation_zero_point(data, list(EFFECTS.values()))
    for effects in ([], [EFFECTS["gravity_sag"]], [EFFECTS["backlash"], EFFECTS["base_tilt"]]):
        direct = fit_orientation(data, effects).result
        reused = fit_orientation(data, effects, zero_point=shared).result
        assert reused.weights is shared.weights
        assert reused.rank == direct.rank
        assert reused.rss == pytest.approx(direct.rss, rel=1e-10)
        np.testing.assert_allclose(
            reused.identifiability.determined, direct.identifiability.determined, atol=1e-9
        )
        np.testing.assert_allclose(reused.params, direct.params, rtol=1e-6, atol=1e-14)


def test_blocked_r_factor_equals_one_qr():
    from turntable_pin.stats.least_squares import tall_r_factor

    rng = np.random.default_rng(0)
    for m in (3000, 5000 + 17):
        a = rng.normal(size=(m, 7)) * np.array([1, 10, 1e-3, 1, 5, 1, 1])
        r = tall_r_factor(a)
        np.testing.assert_allclose(r.T @ r, a.T @ a, rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(
            np.abs(np.diag(r)), np.abs(np.diag(np.linalg.qr(a, mode="r"))), rtol=1e-12
        )


def test_identifiability_of_a_tall_jacobian_equals_the_direct_svd():
    """Long data go through the blocked R factor; the rank and combinations are the same."""
    import turntable_pin.stats.least_squares as ls

    rng = np.random.default_rng(1)
    base = rng.normal(size=(4000, 4))
    jac = np.column_stack([base, base[:, 1] + 2 * base[:, 2], np.zeros(4000)])  # flat, dead
    names = tuple("abcdef")
    tall = ls.analyse_identifiability(jac, names)
    _, s, vt = np.linalg.svd(jac / np.where(np.linalg.norm(jac, axis=0) > 0,
                                            np.linalg.norm(jac, axis=0), 1.0))  # fmt: skip
    assert tall.rank == 4 == int(np.sum(s > ls.RANK_RTOL * s[0]))
    np.testing.assert_allclose(tall.singular_values[:4], s[:4], rtol=1e-12)
    assert tall.unresponsive == ("f",)
    small = ls.analyse_identifiability(jac[:300], names)  # the direct path
    np.testing.assert_allclose(tall.undetermined, small.undetermined, atol=1e-9)
    np.testing.assert_allclose(tall.determined, small.determined, atol=1e-9)


def test_chi2_tail_and_quantile_equal_scipy_stats():
    from scipy import stats

    from turntable_pin.stats.least_squares import chi2_quantile, chi2_sf

    for dof in (1, 2, 4, 8, 431, 299_990):
        for x in (0.3, 5.0, 40.0, 500.0, 3e5):
            assert chi2_sf(x, dof) == pytest.approx(stats.chi2.sf(x, dof), rel=1e-14, abs=0)
        assert chi2_quantile(0.99, dof) == pytest.approx(stats.chi2.ppf(0.99, dof), rel=1e-14)


def test_profiled_rss_is_the_likelihood_with_a_noise_level_per_group(rng):
    # -2 ln L with each group's variance at its maximum (S_g / n_g) is
    # sum_g n_g ln(S_g / n_g) + m (1 + ln 2 pi): the differences of two fits' m ln(profiled_rss)
    # must be the differences of that, computed here from the residuals directly.
    from dataclasses import replace

    x = np.linspace(-1, 1, 60)
    groups = np.repeat([0, 1, 2], 20)
    y = 1.0 + 3.0 * x + rng.normal(0, 1.0, x.size) * np.array([0.5, 2.0, 1.0])[groups]
    results = []
    for truncate in (False, True):
        toy = LinearToy(x, y, None)
        if truncate:  # a worse model: no x^2 and no slope
            toy.design = toy.design[:, :1] * np.ones((1, 4))
        results.append(replace(fit_least_squares(toy), noise_groups=groups))

    def minus_two_log_likelihood(result):
        s = np.array([np.sum(result.residuals[groups == g] ** 2) for g in range(3)])
        return float(np.sum(20 * np.log(s / 20)))

    good, bad = results
    m = x.size
    got = m * (np.log(bad.profiled_rss) - np.log(good.profiled_rss))
    assert got == pytest.approx(minus_two_log_likelihood(bad) - minus_two_log_likelihood(good))
    assert replace(good, noise_groups=None).profiled_rss == good.rss
    assert good.group_rss.sum() == pytest.approx(np.sum(good.residuals**2))

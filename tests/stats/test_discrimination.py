"""Telling two rival linear models apart: the generalised chi-square of a difference of two
fits' rss against simulation, the non-central chi-square of a nested test, the misfit, the
T-optimal exchange against the best subset found by enumeration, the correlation rule."""

import itertools

import numpy as np
import pytest
from scipy import stats

from turntable_pin.stats.discrimination import (
    Direction,
    choice_margin,
    detection_power,
    generalized_chi2_sf,
    misfit,
    noncentral_chi2_sf,
    quadratic_form,
    rss_difference,
    t_optimal_exchange,
    traded_off,
)

SAMPLES = 400_000


def _tail(weights, nc, x, rng):
    z = rng.standard_normal((SAMPLES, len(weights))) + np.sqrt(nc)
    return float(np.mean((z**2 * np.asarray(weights)).sum(axis=1) > x))


@pytest.mark.parametrize(
    "weights, nc, x",
    [
        ([1.0], [4.0], 3.0),
        ([1.0, -1.0], [9.0, 0.5], 2.0),
        ([0.3, -0.2, 0.9, -0.05], [1.0, 2.0, 30.0, 0.0], 5.0),
        ([-1.0, -1.0, -1.0], [0.0, 0.0, 0.0], -12.8),
        ([0.001, 1.0, -0.5], [1e4, 2.0, 3.0], 10.0),
        ([1.0, -1.0], [1e5, 0.0], 1e5 + 300.0),
        ([0.9999, -0.0141], [40.0, 0.2], -12.0),
    ],
)
def test_generalised_chi_square_tail_agrees_with_simulation(weights, nc, x, rng):
    p = _tail(weights, nc, x, rng)
    se = np.sqrt(max(p * (1 - p), 1e-4) / SAMPLES)
    assert abs(generalized_chi2_sf(x, weights, nc) - p) < 4 * se + 1e-4


def test_random_generalised_chi_squares_agree_with_simulation(rng):
    for _ in range(5):
        k = int(rng.integers(1, 12))
        weights = rng.uniform(-1.0, 1.0, k)
        nc = rng.uniform(0.0, 40.0, k)
        x = float(rng.normal(np.sum(weights * (1 + nc)), 3.0))
        p = _tail(weights, nc, x, rng)
        assert abs(generalized_chi2_sf(x, weights, nc) - p) < 4 * np.sqrt(0.25 / SAMPLES) + 1e-4


def test_equal_positive_weights_are_a_non_central_chi_square():
    for dof, nc, x in [(1, 0.0, 3.84), (2, 15.0, 10.0), (4, 2.5, 20.0), (7, 60.0, 50.0)]:
        expected = stats.ncx2.sf(x, dof, nc) if nc else stats.chi2.sf(x, dof)
        split = np.full(dof, nc / dof)  # any split of the non-centrality over the terms
        assert generalized_chi2_sf(x, np.ones(dof), split) == pytest.approx(expected, abs=1e-7)
        assert noncentral_chi2_sf(x, dof, nc) == pytest.approx(expected, abs=1e-12)


def test_degenerate_forms():
    assert generalized_chi2_sf(0.0, [], []) == 0.0  # Q is 0: never above 0
    assert generalized_chi2_sf(-1.0, [], []) == 1.0
    assert generalized_chi2_sf(-1e6, [1.0], [2.0]) == 1.0  # far below the mean
    assert generalized_chi2_sf(1e6, [1.0], [2.0]) == 0.0
    assert noncentral_chi2_sf(-1.0, 3, 0.0) == 1.0


def _two_models(rng, m=60):
    shared = rng.normal(size=(m, 3))
    own_1 = rng.normal(size=(m, 2))
    own_2 = 0.8 * own_1 @ rng.normal(size=(2, 2)) + 0.6 * rng.normal(size=(m, 2))
    return shared, own_1, own_2


def _rss(columns, y):
    coef, *_ = np.linalg.lstsq(columns, y, rcond=None)
    return float(np.sum((y - columns @ coef) ** 2))


def test_rss_difference_is_the_distribution_of_the_two_fits(rng):
    shared, own_1, own_2 = _two_models(rng)
    signal = own_1 @ np.array([0.4, -0.3])
    weights, nc, k_1, k_2 = rss_difference(shared, own_1, own_2, signal)
    assert (k_1, k_2) == (2, 2)
    assert np.all(np.abs(weights) <= 1.0 + 1e-12)
    one, two = np.hstack([shared, own_1]), np.hstack([shared, own_2])
    draws = signal + rng.normal(size=(4000, signal.size))
    d = np.array([_rss(two, y) - _rss(one, y) for y in draws])
    assert np.mean(d) == pytest.approx(
        np.sum(weights * (1 + nc)), abs=4 * np.std(d) / np.sqrt(d.size)
    )
    for x in (-2.0, 0.0, 1.0, 3.0):
        p = np.mean(d > x)
        assert abs(generalized_chi2_sf(x, weights, nc) - p) < 4 * np.sqrt(0.25 / d.size)


def test_a_nested_rival_is_the_non_central_chi_square_of_the_nested_test(rng):
    m = 40
    shared = rng.normal(size=(m, 2))
    small = rng.normal(size=(m, 1))
    large = np.hstack([small, rng.normal(size=(m, 3))])  # contains the small model
    truth = large @ np.array([0.0, 0.5, -0.4, 0.3])
    weights, nc, k_small, k_large = rss_difference(shared, small, large, truth)
    assert (k_small, k_large) == (1, 4)
    np.testing.assert_allclose(weights, -1.0, atol=1e-9)  # D = rss_large - rss_small = -chi2'
    lam = misfit(np.hstack([shared, small]), truth)
    assert np.sum(nc) == pytest.approx(lam, rel=1e-9)
    margin = choice_margin(1, 4, m)
    # the large model is named when rss_small - rss_large > 3 ln m: chi2'(3, lambda)
    assert 1 - generalized_chi2_sf(margin, weights, nc) == pytest.approx(
        noncentral_chi2_sf(-margin, 3, lam), abs=1e-7
    )


def test_quadratic_form_of_a_gain_difference(rng):
    shared, own_1, own_2 = _two_models(rng)
    signal = own_1 @ np.array([0.5, 0.2])
    one, two = np.hstack([shared, own_1]), np.hstack([shared, own_2])
    terms = [(one, 1.0), (shared, 1.0), (two, -2.0)]  # gain_1 - 2 gain_2
    weights, nc = quadratic_form(terms, signal)
    draws = signal + rng.normal(size=(4000, signal.size))
    gains = np.array(
        [(_rss(shared, y) - _rss(one, y)) - 2 * (_rss(shared, y) - _rss(two, y)) for y in draws]
    )
    assert abs(generalized_chi2_sf(0.0, weights, nc) - np.mean(gains > 0)) < 0.03


def test_misfit_is_what_least_squares_leaves(rng):
    columns = rng.normal(size=(30, 4))
    signal = rng.normal(size=30)
    assert misfit(columns, signal) == pytest.approx(_rss(columns, signal), rel=1e-10)
    assert misfit(columns, columns @ np.ones(4)) < 1e-20


def test_detection_power_is_the_acceptance_rule():
    m, added, threshold = 100, 2, -6.0 - 2 * np.log(9)
    cut = added * np.log(m) - threshold
    assert detection_power(0.0, added, m, threshold) == pytest.approx(stats.chi2.sf(cut, added))
    assert detection_power(50.0, added, m, threshold) == pytest.approx(
        stats.ncx2.sf(cut, added, 50.0)
    )


def test_traded_off_columns():
    rng = np.random.default_rng(3)
    shared = rng.normal(size=(50, 3))
    clean = rng.normal(size=(50, 2))
    assert not traded_off(shared, clean)
    leaning = np.hstack([clean[:, :1], shared[:, :1] + 0.05 * rng.normal(size=(50, 1))])
    assert traded_off(shared, leaning)  # one column almost a shared one
    twins = np.hstack([clean[:, :1], clean[:, :1] + 0.02 * rng.normal(size=(50, 1))])
    assert traded_off(shared, twins)  # two own columns almost alike
    assert traded_off(shared, shared[:, :1] * 2.0)  # not seen on its own


def _polynomial_rivals(x: np.ndarray):
    """Model 1: a + b x + c x^2 (truth 0.3 x^2); model 2: a + b x + d sin(3 x) (truth 0.4
    sin 3x); each candidate one observation."""
    shared = np.stack([np.ones_like(x), x], axis=1)[:, None, :]
    quad, sine = (x**2)[:, None, None], np.sin(3 * x)[:, None, None]
    one = Direction(np.concatenate([shared, sine], -1), 0.3 * quad[..., 0] * 10)
    two = Direction(np.concatenate([shared, quad], -1), 0.4 * sine[..., 0] * 10)
    return [one, two]


def test_exchange_finds_the_best_subset_of_a_small_problem():
    x = np.linspace(-1.0, 1.0, 13)
    directions = _polynomial_rivals(x)
    n = 5
    best = max(
        min(d.misfit(np.array(s)) for d in directions)
        for s in itertools.combinations(range(x.size), n)
    )
    found = t_optimal_exchange(directions, n, seed=4)
    assert found.criterion >= 0.999 * best
    assert found.noncentralities == tuple(d.misfit(found.chosen) for d in directions)
    assert len(set(found.chosen.tolist())) == n


def test_exchange_never_ends_below_its_random_start():
    x = np.random.default_rng(5).uniform(-1.0, 1.0, 400)
    directions = _polynomial_rivals(x)
    for seed in range(3):
        start = np.sort(np.random.default_rng(seed).choice(x.size, 8, replace=False))
        found = t_optimal_exchange(directions, 8, seed=seed)
        assert found.criterion >= min(d.misfit(start) for d in directions) - 1e-9
        assert found.swaps >= 1


def test_exchange_counts_the_observations_already_made():
    x = np.linspace(-1.0, 1.0, 41)
    plain = _polynomial_rivals(x)
    made = np.array([0, 20, 40])  # the three already measured
    fixed = [
        Direction(d.fitted, d.signal, d.fitted[made].reshape(3, -1), d.signal[made].reshape(-1))
        for d in plain
    ]
    found = t_optimal_exchange(fixed, 3, seed=1)
    together = np.concatenate([found.chosen, made])
    for d_fixed, d in zip(fixed, plain, strict=True):
        assert d_fixed.misfit(found.chosen) == pytest.approx(d.misfit(together), rel=1e-9)

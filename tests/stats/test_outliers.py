"""The outlier rule: leverages against the hat matrix, the Bonferroni threshold, planted gross
errors found, clean data flagged at the stated rate."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats

from turntable_pin.stats.outliers import (
    OUTLIER_ALPHA,
    leverages,
    outlier_threshold,
    screen_outliers,
)


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000), st.integers(3, 6))
def test_leverages_are_the_hat_matrix_diagonal(seed, n):
    rng = np.random.default_rng(seed)
    j = rng.normal(size=(40, n)) * rng.uniform(0.1, 100, n)  # columns of any scale
    hat = j @ np.linalg.inv(j.T @ j) @ j.T
    np.testing.assert_allclose(leverages(j), np.diag(hat), atol=1e-10)
    assert leverages(j).sum() == pytest.approx(n)


def test_threshold_is_the_two_sided_bonferroni_quantile():
    z = outlier_threshold(432)
    assert 2 * stats.norm.sf(z) * 432 == pytest.approx(OUTLIER_ALPHA)


def test_planted_gross_errors_are_found_worst_first():
    rng = np.random.default_rng(1)
    x = np.linspace(0, 1, 300)
    j = np.stack([np.ones_like(x), x, np.sin(6 * x)], axis=1)
    y = j @ [1.0, -2.0, 0.5] + rng.normal(0, 1, x.size)
    y[[10, 150, 299]] += [12.0, -20.0, 9.0]
    r = y - j @ np.linalg.lstsq(j, y, rcond=None)[0]
    test = screen_outliers(r, j)
    assert test.flagged.tolist() == [150, 10, 299]
    assert test.scale == pytest.approx(1.0, rel=0.15)  # the MAD ignores the three


def test_clean_data_are_flagged_at_about_the_stated_rate():
    rng = np.random.default_rng(2)
    j = np.stack([np.ones(200), np.linspace(-1, 1, 200)], axis=1)
    hits = 0
    for _ in range(400):
        y = rng.normal(0, 3.0, 200)
        r = y - j @ np.linalg.lstsq(j, y, rcond=None)[0]
        hits += screen_outliers(r, j).flagged.size > 0
    assert hits / 400 < 4 * OUTLIER_ALPHA

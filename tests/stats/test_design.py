"""D-optimal exact designs (stats/design.py): a known optimum, the exchange's bookkeeping against
determinants computed afresh, and the property that an exchange never lowers log det."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from turntable_pin.stats.design import (
    d_optimal_design,
    fedorov_exchange,
    greedy_design,
    log_det,
)


def _information(rows, chosen):
    x = rows[chosen].reshape(-1, rows.shape[2])
    return x.T @ x


def test_quadratic_regression_on_an_interval_takes_both_ends_and_the_middle():
    # The D-optimal 3-point design of y = a + b x + c x^2 on [-1, 1] is {-1, 0, 1} (Kiefer).
    x = np.linspace(-1.0, 1.0, 201)
    rows = np.stack([np.ones_like(x), x, x**2], axis=1)
    found = d_optimal_design(rows, 3)
    assert sorted(np.round(x[found.chosen], 9)) == [-1.0, 0.0, 1.0]


def test_linear_regression_puts_the_points_at_the_ends():
    x = np.linspace(-1.0, 1.0, 101)
    rows = np.stack([np.ones_like(x), x], axis=1)
    found = d_optimal_design(rows, 4)
    assert np.all(np.abs(x[found.chosen]) > 0.95)


def _random_problem(seed, c=300, k=3, p=6):
    rng = np.random.default_rng(seed)
    return rng.normal(size=(c, k, p)) * rng.uniform(0.2, 2.0, (c, 1, 1))


@pytest.mark.parametrize("seed", range(4))
def test_the_exchange_bookkeeping_matches_determinants_computed_afresh(seed):
    rows = _random_problem(seed)
    start = greedy_design(rows, 5)
    found = fedorov_exchange(rows, start)
    assert found.log_det == pytest.approx(log_det(_information(rows, found.chosen)), abs=1e-9)
    # The running sum of the exchanges' log det ratios ends where the afresh value is.
    assert found.history[-1] == pytest.approx(found.log_det, abs=1e-7)
    assert len(set(found.chosen.tolist())) == found.chosen.size  # each candidate once


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    k=st.integers(1, 3),
    n=st.integers(3, 9),
    with_start=st.booleans(),
)
def test_an_exchange_never_lowers_log_det(seed, k, n, with_start):
    rng = np.random.default_rng(seed)
    p = 4
    rows = rng.normal(size=(60, k, p))
    start = None
    if with_start:
        a = rng.normal(size=(2, p))
        start = a.T @ a  # singular on its own: the design must bring the rest
    chosen = rng.choice(60, size=n, replace=False)
    if not np.isfinite(log_det(_information(rows, chosen) + (0 if start is None else start))):
        return
    found = fedorov_exchange(rows, chosen, start)
    assert np.all(np.diff(found.history) > 0)
    assert found.log_det >= found.history[0] - 1e-9
    assert found.log_det == pytest.approx(found.history[-1], abs=1e-7)


def test_a_start_of_known_information_is_built_upon():
    rows = _random_problem(7, p=4)
    known = np.diag([1e6, 1e6, 0.0, 0.0])  # two parameters already known very well
    found = d_optimal_design(rows, 2, known)
    alone = d_optimal_design(rows, 2)
    # With the first two known, the design is chosen for the other two.
    m = _information(rows, found.chosen)
    m_alone = _information(rows, alone.chosen)
    assert log_det(m[2:, 2:]) >= log_det(m_alone[2:, 2:]) - 1e-9


def test_too_few_candidates_for_the_parameters_leave_log_det_minus_infinity():
    rows = _random_problem(3, k=1, p=5)
    found = d_optimal_design(rows, 3)  # 3 rows cannot determine 5 parameters
    assert found.log_det == -np.inf


def test_a_singular_start_of_the_exchange_is_refused():
    rows = _random_problem(1, k=1, p=5)
    with pytest.raises(ValueError, match="singular"):
        fedorov_exchange(rows, [0, 1, 2])

"""The model-selection helpers against independent constructions."""

from __future__ import annotations

import numpy as np
import pytest

from turntable_pin.stats.model_selection import _projected_rss, acceptance_threshold


def test_acceptance_threshold_is_the_look_elsewhere_penalty():
    assert acceptance_threshold(1) == -6.0
    assert acceptance_threshold(9) == pytest.approx(-6.0 - 2.0 * np.log(9.0))


def test_projected_rss_equals_a_qr_projection_and_counts_the_rank():
    rng = np.random.default_rng(3)
    a = rng.normal(size=(300, 4)) * [1e-3, 1.0, 50.0, 2.0]  # columns of any scale
    b = np.concatenate([a[:, :1] + a[:, 1:2], rng.normal(size=(300, 2))], axis=1)  # one dependent
    r = rng.normal(size=(300, 3))
    q, _ = np.linalg.qr(np.concatenate([a, b[:, 1:]], axis=1))
    left = r - q @ (q.T @ r)
    rss, rank = _projected_rss(r, [a, b])
    assert rank == 6
    assert rss == pytest.approx(float(np.sum(left**2)), rel=1e-9)
    assert _projected_rss(r[:, 0], [a, b])[0] == pytest.approx(float(left[:, 0] @ left[:, 0]))


class _Polynomial:
    """y = sum_k p_k x^k over x in [lo, hi]: on a short span the powers trade off."""

    per_user_unit = None
    user_unit_scale = 1.0
    observation_unit = ""

    def __init__(self, x, y, degree):
        self.observed, self.sigma = y, np.ones_like(y)
        self.design = np.stack([x**k for k in range(degree + 1)], axis=1)
        self.parameter_names = tuple(f"p{k}" for k in range(degree + 1))
        self.parameter_units = ("u",) * (degree + 1)
        self.per_user_unit = np.ones(degree + 1)

    def predict(self, p):
        return self.design @ p

    def jacobian(self, p):
        return self.design


def test_parameter_determination_is_the_variance_inflation_of_a_full_rank_fit():
    from turntable_pin.stats.least_squares import fit_least_squares
    from turntable_pin.stats.model_selection import parameter_determination

    rng = np.random.default_rng(5)
    x = np.linspace(0.2, 1.0, 60)
    y = 1.0 + 2.0 * x + rng.normal(0, 1.0, x.size)
    result = fit_least_squares(_Polynomial(x, y, 2))
    entries = parameter_determination(result, result.parameter_names, (), 0)
    design = result.jacobian_weighted
    inverse = np.linalg.inv(design.T @ design)
    for i, entry in enumerate(entries):
        # R^2 = 1 - 1/VIF with VIF = (J^T J)^-1_ii |J_i|^2: the textbook multiple correlation.
        vif = inverse[i, i] * float(design[:, i] @ design[:, i])
        assert entry["correlation_all"] == pytest.approx(np.sqrt(1.0 - 1.0 / vif), rel=1e-9)
        assert entry["std"] == pytest.approx(np.sqrt(result.covariance[i, i]), rel=1e-12)
        assert entry["determined"] == (entry["correlation_all"] <= 0.995)


def test_an_effect_is_undetermined_when_traded_off_or_insignificant_absorbed_ones_aside():
    from turntable_pin.stats.model_selection import undetermined_parameters

    def entry(name, value, std, correlation):
        determined = std is not None and correlation <= 0.95
        sigmas = abs(value) / std if std else None
        return {"name": name, "value": value, "std": std, "sigmas": sigmas,
                "correlation": correlation, "correlation_all": correlation,
                "determined": determined}  # fmt: skip

    # a 1/rev eccentricity: c2, s2 determined to be near zero, c1 significant
    assert undetermined_parameters([entry("c1", 3.0, 0.1, 0.2), entry("c2", 0.05, 0.1, 0.2)]) == []
    # traded off against the model (the MMT run's elevation encoder: c1 -57 +- 37)
    assert undetermined_parameters([entry("c1", -57, 37, 0.999), entry("c2", -22, 4, 0.3)]) == [
        "c1"
    ]
    # none reaches 3 sigma
    assert undetermined_parameters([entry("k", 2.0, 1.0, 0.1)]) == ["k"]
    # a parameter the data cannot see (absorbed) counts neither way
    assert undetermined_parameters([entry("k_xx", 0.0, None, 1.0), entry("k", 9, 1, 0.5)]) == []
    # nothing seen at all: undetermined
    assert undetermined_parameters([entry("a", 1.0, None, 1.0)]) == ["a"]


class _Columns:
    """y = the named columns times their parameters (a linear toy of the model family)."""

    user_unit_scale = 1.0
    observation_unit = ""

    def __init__(self, y, columns: dict):
        self.observed, self.sigma = y, np.full(y.size, 0.1)
        self.parameter_names = tuple(columns)
        self.design = np.stack(list(columns.values()), axis=1)
        self.parameter_units = ("u",) * len(columns)
        self.per_user_unit = np.ones(len(columns))

    def predict(self, p):
        return self.design @ p

    def jacobian(self, p):
        return self.design


def _toy_family(x, y, effects: dict):
    from types import SimpleNamespace

    from turntable_pin.stats.least_squares import fit_least_squares

    base = {"base.a": np.ones_like(x)}

    def fit(chosen):
        columns = dict(base)
        for e in chosen:
            columns.update(effects[e.name])
        return SimpleNamespace(result=fit_least_squares(_Columns(y, columns)))

    catalogue = tuple(SimpleNamespace(name=n) for n in effects)
    return SimpleNamespace(fit=fit, untestable_reason=lambda e: None, catalogue=catalogue)


def test_a_determined_effect_with_a_small_gain_is_not_put_before_one_that_explains_much_more():
    # Issue 17: "never headline an effect whose rms gain is negligible while another candidate
    # halves it", even when the better one's parameters trade off against each other.
    from turntable_pin.stats.model_selection import compare_effects

    rng = np.random.default_rng(1)
    x = np.linspace(0.2, 1.0, 200)
    y = 1.0 + 3.0 * x + 0.3 * np.sin(20 * x) + rng.normal(0, 0.1, x.size)
    effects = {
        "small": {"small.s": np.sin(20 * x)},  # real, determined, small
        "big": {"big.b1": x, "big.b2": x + 1e-3 * x**2},  # the slope, in two traded-off columns
    }
    family = _toy_family(x, y, effects)
    ranked = compare_effects(family, [], family.fit([]), family.catalogue)
    by_name = {c.effect: c for c in ranked}
    assert by_name["small"].significant and by_name["small"].determined
    assert by_name["big"].significant and not by_name["big"].determined
    assert ranked[0].effect == "big"
    # with a determined effect explaining most of it, the determined one comes first
    effects["small"] = {"small.s": x}
    family = _toy_family(x, y, effects)
    ranked = compare_effects(family, [], family.fit([]), family.catalogue)
    assert ranked[0].effect == "small" and ranked[0].determined

"""The structure search: finds a planted shape and its size, ignores what the model absorbs."""

import numpy as np
import pytest

from turntable_pin.stats import structure_search
from turntable_pin.stats.structure_search import (
    Probe,
    ProbeFactors,
    delta_bic,
    search_structure,
)


def _probes(x):
    return [
        Probe(f"{k}/rev", f"harmonic {k}", np.stack([np.cos(k * x), np.sin(k * x)], axis=1))
        for k in range(1, 6)
    ]


def test_planted_harmonic_is_found_with_its_amplitude():
    rng = np.random.default_rng(0)
    x = np.linspace(0, 2 * np.pi, 240, endpoint=False)
    r = 0.8 * np.cos(3 * x + 0.5) + rng.normal(0, 0.3, x.size)
    model = np.ones((x.size, 1))  # the model absorbs a constant
    for variance in (0.09, None):
        found = search_structure(r, model, _probes(x), noise_variance=variance)
        assert [t.name for t in found] == ["3/rev"]
        assert found[0].amplitude == pytest.approx(0.8, abs=0.1)


def test_what_the_model_absorbs_is_not_structure_and_noise_is_quiet():
    rng = np.random.default_rng(1)
    x = np.linspace(0, 2 * np.pi, 240, endpoint=False)
    r = 2.0 * np.sin(x) + rng.normal(0, 0.3, x.size)
    model = np.stack([np.cos(x), np.sin(x)], axis=1)
    # the residual of a real fit is orthogonal to the model; project to make it so
    q, _ = np.linalg.qr(model)
    r = r - q @ (q.T @ r)
    assert search_structure(r, model, _probes(x), noise_variance=0.09) == []
    hits = 0
    for seed in range(200):
        noise = np.random.default_rng(seed).normal(0, 1, x.size)
        hits += bool(search_structure(noise, np.zeros((x.size, 0)), _probes(x), noise_variance=1))
    assert hits <= 2  # P(chi2_2 > 2 ln 240 + 6 + 2 ln 5) ~ 1e-4 per probe


def test_delta_bic_forms():
    assert delta_bic(90.0, 100.0, 2, 100, 1.0, 12) == pytest.approx(-10 + 2 * np.log(100))
    # Variance profiled out: weighted by the larger model's residual degrees of freedom, 100 - 12,
    # plus added / 2 - 1 (zero for two added parameters).
    assert delta_bic(90.0, 100.0, 2, 100, None, 12) == pytest.approx(
        88 * np.log(0.9) + 2 * np.log(100)
    )
    assert delta_bic(90.0, 100.0, 4, 100, None, 12) == pytest.approx(
        89 * np.log(0.9) + 4 * np.log(100)
    )


@pytest.mark.parametrize("added", [1, 2, 3, 4, 6, 8])
@pytest.mark.parametrize("dof", [60, 200, 2000])
@pytest.mark.parametrize("tail", [1e-2, 1e-4, 1e-8])
def test_the_profiled_ratio_has_the_tail_of_the_exact_f_test(added, dof, tail):
    """With the noise estimated, the improvement of nested linear models has an exact F
    distribution; the calibrated ratio, read on its chi2(added) reference, gives the same tail
    probability: exactly for two added parameters, within 10 % up to eight once the larger model
    has 60 residual degrees of freedom. The textbook weight m overstates the evidence."""
    stats = pytest.importorskip("scipy.stats")
    rank_new = 10
    m = dof + rank_new
    f_value = stats.f.isf(tail, added, dof)
    ratio = 1.0 / (1.0 + added * f_value / dof)  # rss_new / rss_old at that F
    statistic = -(delta_bic(ratio, 1.0, added, m, None, rank_new) - added * np.log(m))
    assert stats.chi2.sf(statistic, added) == pytest.approx(tail, rel=1e-9 if added == 2 else 0.1)
    textbook = -m * np.log(ratio)
    assert stats.chi2.sf(textbook, added) < stats.chi2.sf(statistic, added)


def test_a_shape_the_model_spans_to_first_order_is_not_new_structure():
    # A probe equal to a model column up to a second-order remainder (1e-5 of it) used to be
    # accepted, its tiny remainder fitted to the residuals with an amplitude of ~1e5 (found on
    # orientation data: "dgamma 1/rev in phi1" next to the wobble terms, 2.6e5 arcsec).
    rng = np.random.default_rng(2)
    x = np.linspace(0, 2 * np.pi, 240, endpoint=False)
    model = np.stack([np.cos(x), np.sin(x)], axis=1)
    wiggle = np.stack([np.cos(7 * x), np.sin(7 * x)], axis=1)
    near_model = Probe("near", "the model's shape plus 1e-5 of a 7/rev", model + 1e-5 * wiggle)
    r = 3.0 * np.cos(7 * x) + rng.normal(0, 0.3, x.size)  # real structure the probe barely has
    found = search_structure(r, model, [near_model, *_probes(x)], noise_variance=0.09)
    assert "near" not in [t.name for t in found]
    assert all(t.amplitude < 10 for t in found)


def _factored_probes(x, direction):
    """k/rev probes on records of two observations, entering along ``direction`` (n, 2)."""
    probes = []
    for k in range(1, 6):

        def functions(v, k=k):
            return np.stack([np.cos(k * v), np.sin(k * v)], axis=-1)

        columns = (direction[:, :, None] * functions(x)[:, None, :]).reshape(-1, 2)
        factors = ProbeFactors("x", x, functions, direction, value_scale=2.0, value_unit="half-x")
        probes.append(Probe(f"{k}/rev", f"harmonic {k}", columns, 10.0, "u", factors))
    return probes


def test_a_found_term_keeps_what_its_plot_needs_and_projects_back_to_its_shape():
    rng = np.random.default_rng(4)
    n = 240
    x = np.linspace(0, 2 * np.pi, n, endpoint=False)
    direction = np.stack([1.0 + 0.5 * np.cos(x), 0.8 * np.sin(2 * x)], axis=1)
    direction[:3] = 0.0  # three records the shape does not reach
    shape = 0.8 * np.cos(3 * x) - 0.5 * np.sin(3 * x)  # internal units: 10x in user units
    noise = 0.3
    r = (direction * shape[:, None]).reshape(-1) + rng.normal(0, noise, 2 * n)
    model = np.ones((2 * n, 1))
    r -= r.mean()  # a fit's residual is orthogonal to the model
    for variance in (noise**2, None):
        [term] = search_structure(r, model, _factored_probes(x, direction), noise_variance=variance)
        assert term.name == "3/rev" and term.unit_scale == 10.0
        assert term.coefficients == pytest.approx((8.0, -5.0), abs=0.5)
        assert term.fitted_weighted.shape == term.residual_weighted.shape == (2 * n,)
        assert term.explained_weighted.shape == (2 * n,)
        estimated = variance is None
        assert term.noise_std_weighted == pytest.approx(noise, rel=0.1 if estimated else 1e-12)
        pr = term.projection()
        assert pr.variable == "x" and pr.value_unit == "half-x" and pr.unit == "u"
        assert np.allclose(pr.values, 2.0 * x)
        assert np.isnan(pr.projected[:3]).all() and np.isnan(pr.noise[:3]).all()
        ok = slice(3, None)
        # the points scatter around the fitted term as the noise says they should
        pulls = (pr.projected[ok] - pr.fitted[ok]) / pr.noise[ok]
        assert abs(pulls.mean()) < 0.3 and np.std(pulls) == pytest.approx(1.0, abs=0.15)
        assert np.allclose(pr.fitted, term.curve(x))
        assert np.allclose(pr.fitted, 10.0 * (0.8 * np.cos(3 * x) - 0.5 * np.sin(3 * x)),
                           atol=1.0)  # fmt: skip
        assert set(term.to_dict()) == {
            "term", "description", "delta_bic", "amplitude", "unit", "coefficients", "effect_spec"
        }  # fmt: skip


def test_a_term_of_a_probe_without_factors_cannot_be_projected():
    rng = np.random.default_rng(0)
    x = np.linspace(0, 2 * np.pi, 240, endpoint=False)
    r = 0.8 * np.cos(3 * x) + rng.normal(0, 0.3, x.size)
    [term] = search_structure(r, np.ones((x.size, 1)), _probes(x), noise_variance=0.09)
    assert term.fitted_weighted is not None and term.factors is None
    with pytest.raises(ValueError, match="no data to project"):
        term.projection()
    with pytest.raises(ValueError, match="no factors"):
        term.curve(x)


def _reference_search(r, model_jac, probes, noise_variance, max_terms=5):
    """The search done the straightforward way: an SVD of every projected probe."""
    import math

    from turntable_pin.stats.structure_search import BIC_THRESHOLD, NEW_FRACTION

    u, s, _ = np.linalg.svd(model_jac, full_matrices=False)
    q = u[:, s > 1e-9 * s[0]]
    r = r.copy()
    remaining = list(probes)
    threshold = BIC_THRESHOLD - 2.0 * math.log(len(remaining))
    found = []
    for _ in range(max_terms):
        rss = float(r @ r)
        best = None
        for probe in remaining:
            columns = probe.matrix()
            t = columns - q @ (q.T @ columns)
            u, s, vt = np.linalg.svd(t, full_matrices=False)
            keep = s > NEW_FRACTION * np.linalg.norm(columns, 2)
            if keep.any():
                basis = u[:, keep]
                reduction = float(np.sum((basis.T @ r) ** 2))
                if best is None or reduction > best[0]:
                    best = (reduction, probe, basis, vt[keep].T / s[keep])
        if best is None:
            break
        reduction, probe, basis, pinv = best
        added = basis.shape[1]
        dbic = delta_bic(rss - reduction, rss, added, r.size, noise_variance, q.shape[1] + added)
        if dbic > threshold:
            break
        found.append((probe.name, dbic, pinv @ (basis.T @ r)))
        r = r - basis @ (basis.T @ r)
        q = np.concatenate([q, basis], axis=1)
        remaining.remove(probe)
    return found


@pytest.mark.parametrize("m", [240, 6000])
def test_small_matrix_scoring_equals_the_svd_of_every_probe(m):
    """Scores from Gram matrices (batched, tall bases from the R factor) against SVDs."""
    rng = np.random.default_rng(2)
    x = np.linspace(0, 2 * np.pi, m, endpoint=False)
    y = rng.uniform(0, 2 * np.pi, m)
    model = np.column_stack([np.ones(m), np.cos(x), np.cos(x), np.sin(y)])  # rank 3
    r = 0.9 * np.cos(3 * x + 0.5) - 0.7 * np.sin(2 * y) + rng.normal(0, 0.3, m)
    probes = _probes(x) + [
        Probe(f"y {k}/rev", "", lambda k=k: np.stack([np.cos(k * y), np.sin(k * y)], axis=1))
        for k in range(1, 4)
    ]
    for variance in (0.09, None):
        found = search_structure(r, model, probes, noise_variance=variance)
        expected = _reference_search(r, model, probes, variance)
        assert [t.name for t in found] == [e[0] for e in expected] != []
        for term, (_, dbic, coef) in zip(found, expected, strict=True):
            assert term.delta_bic == pytest.approx(dbic, rel=1e-9)
            np.testing.assert_allclose(term.coefficients, coef, rtol=1e-8, atol=1e-12)


@pytest.mark.parametrize("observed_fraction", [1.0, 0.8])
def test_probes_scored_from_their_factors_equal_probes_scored_from_their_columns(
    observed_fraction, monkeypatch
):
    """The search scores probes with factors without forming their columns (a direction shared
    by several shapes contracted once); the same probes given by their columns alone give the
    same terms, sizes and delta_bic, with observations left out too."""
    rng = np.random.default_rng(8)
    n, k = 300, 3
    x = rng.uniform(0, 2 * np.pi, n)
    y = rng.uniform(0, 2 * np.pi, n)
    observed = rng.random((n, k)) < observed_fraction
    observed[~observed.any(axis=1), 0] = True
    mask = observed.reshape(-1)
    arrays = [rng.normal(size=(n, k)), rng.normal(size=(n, k)), np.zeros((n, k))]
    arrays[2][:, 0] = 1.0  # a term on one observation alone
    directions = [lambda a=a: a for a in arrays]
    probes = []
    for j, direction in enumerate(directions):
        for var, values in (("x", x), ("y", y)):
            for order in (1, 2, 3):

                def functions(v, order=order):
                    return np.stack([np.cos(order * v), np.sin(order * v)], axis=-1)

                basis = functions(values)
                factors = ProbeFactors(var, values, functions, direction, observed=observed,
                                       basis=basis if order != 2 else None)  # fmt: skip
                columns = (direction()[:, :, None] * basis[:, None, :]).reshape(-1, 2)[mask]
                probes.append(Probe(f"d{j} {order}/rev in {var}", "", columns, 1.0, "", factors))
    model = np.column_stack([np.ones(n * k), rng.normal(size=(n * k, 2))])[mask]
    d0 = directions[0]()
    r = (d0 * (0.7 * np.cos(2 * y) - 0.4 * np.sin(2 * y))[:, None]).reshape(-1)[mask]
    r = r + (directions[2]() * (0.5 * np.sin(3 * x))[:, None]).reshape(-1)[mask]
    r = r + rng.normal(0, 0.2, r.size)
    r -= model @ np.linalg.lstsq(model, r, rcond=None)[0]
    plain = [Probe(p.name, p.description, p.columns) for p in probes]
    by_columns = structure_search._scored_columns
    for variance in (0.04, None):
        expected = search_structure(r, model, plain, noise_variance=variance)
        monkeypatch.setattr(structure_search, "_scored_columns", None)  # not used: all factored
        found = search_structure(r, model, probes, noise_variance=variance)
        monkeypatch.setattr(structure_search, "_scored_columns", by_columns)
        assert [t.name for t in found] == [t.name for t in expected]
        assert {"d0 2/rev in y", "d2 3/rev in x"} <= {t.name for t in found}
        for a, b in zip(found, expected, strict=True):
            assert a.delta_bic == pytest.approx(b.delta_bic, rel=1e-10)
            np.testing.assert_allclose(a.coefficients, b.coefficients, rtol=1e-9, atol=1e-12)

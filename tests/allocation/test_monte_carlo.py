"""Monte Carlo on the exact chain: within the allocated box, beyond it, reproducible, phi1-free."""

import numpy as np
import pytest

from turntable_pin import TurntableErrors, TurntableModel
from turntable_pin.allocation import monte_carlo as mc
from turntable_pin.allocation.capability import ManufacturingCapability
from turntable_pin.allocation.monte_carlo import run_monte_carlo, sample_errors
from turntable_pin.allocation.solver import OrientationLimits, allocate_tolerances
from turntable_pin.core.exceptions import InputError
from turntable_pin.report.allocation_figures import plot_monte_carlo


@pytest.fixture(scope="module")
def allocation():
    return allocate_tolerances(OrientationLimits.from_arcmin(1.4801, 1.56, 1.4801), "paper")


def run(allocation, scale=1.0, n=6000, seed=11, **kw):
    return run_monte_carlo(
        allocation.upper_bounds_rad * scale,
        allocation.limits,
        n,
        seed,
        lower_bounds_rad=allocation.capability.lower_bounds_rad,
        progress=False,
        **kw,
    )


def test_allocated_box_meets_the_limits(allocation):
    result = run(allocation)
    assert result.all_within
    assert np.all(result.max_abs_rad <= allocation.limits.as_array())
    # the box is used: the largest theta error comes within 5 % of its limit
    assert result.max_abs_rad[1] > 0.95 * allocation.limits.theta_rad
    d = result.to_dict()
    assert d["seed"] == 11 and d["n"] == 6000 and d["all_within"] is True
    assert set(d["max_abs_arcmin"]) == {"psi", "theta", "gamma"}


def test_bounds_scaled_by_1_2_exceed_the_limits(allocation):
    result = run(allocation, scale=1.2)
    assert not result.all_within
    assert result.to_dict()["n_exceeding"]["theta"] > 0


def test_same_seed_same_result_and_workers_do_not_matter(allocation):
    a = run(allocation, n=3000, seed=5)
    b = run(allocation, n=3000, seed=5, workers=2)
    c = run(allocation, n=3000, seed=6)
    np.testing.assert_array_equal(a.worst_rad, b.worst_rad)
    assert not np.array_equal(a.worst_rad, c.worst_rad)


def test_samples_lie_in_the_box_with_both_signs(allocation):
    rng = np.random.default_rng(3)
    upper, lower = allocation.upper_bounds_rad, allocation.capability.lower_bounds_rad
    values = sample_errors(rng, 5000, upper, lower)
    magnitudes = np.abs(values[:, :8])
    assert np.all(magnitudes <= upper) and np.all(magnitudes >= lower)
    assert np.all((values[:, :8] > 0).mean(axis=0) > 0.45)
    assert np.all((values[:, :8] < 0).mean(axis=0) > 0.45)
    assert np.all(values[:, 8] == 0.0)


def test_worst_values_match_pinocchio_directly(allocation):
    """Re-draw the first turntables and evaluate them with TurntableModel on the same grid."""
    result = run(allocation, n=4, seed=9, phi2_step_deg=10.0)
    seq = np.random.SeedSequence(9).spawn(1)[0]
    values = sample_errors(
        np.random.default_rng(seq), 4, allocation.upper_bounds_rad,
        allocation.capability.lower_bounds_rad,
    )  # fmt: skip
    grid = np.radians(np.arange(0.0, 360.0, 10.0))
    for k in range(4):
        model = TurntableModel(TurntableErrors.from_array(values[k]))
        phi1 = 1.234  # any phi1: it drops out
        angles = np.array(
            [
                [e.dpsi_rad, e.dtheta_rad, e.dgamma_rad]
                for e in (model.orientation_error(phi1, p) for p in grid)
            ]
        )
        np.testing.assert_allclose(result.worst_rad[k], np.abs(angles).max(axis=0), rtol=1e-12)


def test_phi1_drops_out_and_the_phi1_path_gives_the_same(allocation, monkeypatch):
    plain = run(allocation, n=500, seed=2, phi2_step_deg=5.0)
    assert plain.max_phi1_dependence < 1e-15
    assert plain.phi1_evaluated_deg == (0.0,)
    # Force the phi1 grid (as an angle-dependent effect would): same worst values.
    monkeypatch.setattr(mc, "DEPENDENCE_TOLERANCE", -1.0)
    forced = run(allocation, n=500, seed=2, phi2_step_deg=5.0, phi1_step_deg=30.0)
    assert len(forced.phi1_evaluated_deg) == 12
    np.testing.assert_allclose(forced.worst_rad, plain.worst_rad, rtol=0, atol=1e-15)


@pytest.mark.parametrize(
    "kw, fragment",
    [({"n": 0}, "at least 1"), ({"phi2_step_deg": 0.0}, "phi2 grid step")],
)
def test_bad_arguments(allocation, kw, fragment):
    args = {"n": 10, **kw}
    with pytest.raises(InputError, match=fragment):
        run_monte_carlo(
            allocation.upper_bounds_rad, allocation.limits, args.pop("n"), 1, progress=False,
            **args,
        )  # fmt: skip


def test_lower_above_upper_is_refused(allocation):
    with pytest.raises(InputError, match="lower bound"):
        run_monte_carlo(
            allocation.upper_bounds_rad, allocation.limits, 10, 1,
            lower_bounds_rad=allocation.upper_bounds_rad * 2, progress=False,
        )  # fmt: skip


def test_plot_writes_a_png(allocation, tmp_path):
    result = run(allocation, n=300)
    path = plot_monte_carlo(result, tmp_path / "f9.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_default_capability_is_what_the_allocation_used(allocation):
    np.testing.assert_array_equal(
        allocation.capability.lower_bounds_rad, ManufacturingCapability.default().lower_bounds_rad
    )

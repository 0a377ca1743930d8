"""Monte Carlo on the exact chain of any table: within the allocated box, beyond it, the draws in
the box, each table's worst angles equal to its chain evaluated at every grid position (over
several chunks), reproducible from the seed alone whatever the number of workers; phi1 drops out
on the paper's table, which runs the one path of every table."""

import numpy as np
import pytest

from conftest import REPO_DIR
from rounding import chain_rounding, error_factors
from turntable_pin import TurntableErrors
from turntable_pin.allocation import monte_carlo as mc
from turntable_pin.allocation.capability import ManufacturingCapability
from turntable_pin.allocation.monte_carlo import (
    run_chain_monte_carlo,
    run_monte_carlo,
    sample_errors,
)
from turntable_pin.allocation.solver import (
    OrientationLimits,
    allocate_tolerances,
)
from turntable_pin.core.exceptions import InputError
from turntable_pin.core.turn_grid import full_turn_grid_deg
from turntable_pin.model.angles import ANGLE_ENTRIES
from turntable_pin.model.chain import compose_rotation
from turntable_pin.model.errors import ANGULAR_ERROR_NAMES
from turntable_pin.model.generic_table import GenericTable
from turntable_pin.model.paper_table import paper_table
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
    """Re-draw the first turntables and evaluate them with Pinocchio on the same grid."""
    result = run(allocation, n=4, seed=9, grid_step_deg=10.0)
    seq = np.random.SeedSequence(9).spawn(1)[0]
    values = sample_errors(
        np.random.default_rng(seq), 4, allocation.upper_bounds_rad,
        allocation.capability.lower_bounds_rad,
    )  # fmt: skip
    grid = np.radians(np.arange(0.0, 360.0, 10.0))
    table = paper_table()
    rounding_of_dr = chain_rounding(error_factors(table))
    for k in range(4):
        errors = TurntableErrors.from_array(values[k]).as_array()
        phi1 = 1.234  # any phi1: it drops out
        angles = np.array(
            [
                [e.dpsi_rad, e.dtheta_rad, e.dgamma_rad]
                for e in (table.orientation_error(errors, (phi1, p)) for p in grid)
            ]
        )
        # Both form dR of the chain's 12 rotations (the expansion sums the same products) and read
        # the small angles off its unit-size entries: absolute rounding.
        np.testing.assert_allclose(
            result.worst_rad[k], np.abs(angles).max(axis=0), rtol=0, atol=2 * rounding_of_dr
        )


def test_phi1_drops_out_and_the_phi1_path_gives_the_same(allocation, monkeypatch):
    plain = run(allocation, n=500, seed=2, grid_step_deg=5.0)
    assert plain.max_dependence[0] < 1e-15
    assert plain.evaluated_deg[0] == (0.0,)
    assert plain.to_dict()["held_at_deg"] == {"phi1": 0.0}
    assert plain.to_dict()["max_dependence"]["phi1"] < 1e-15
    # Force the phi1 grid (as an angle-dependent effect would): same worst values.
    monkeypatch.setattr(mc, "DEPENDENCE_TOLERANCE", -1.0)
    forced = run(allocation, n=500, seed=2, grid_step_deg=5.0)
    assert len(forced.evaluated_deg[0]) == 72 and forced.to_dict()["held_at_deg"] == {}
    np.testing.assert_allclose(forced.worst_rad, plain.worst_rad, rtol=0, atol=1e-15)


@pytest.mark.parametrize(
    "kw, fragment",
    [({"n": 0}, "at least 1"), ({"grid_step_deg": 0.0}, "grid step must be in")],
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


# ---- any table -------------------------------------------------------------------------

MODELS = REPO_DIR / "models"
LIMITS = OrientationLimits.from_arcmin(0.6, 0.25, 0.45)


@pytest.mark.parametrize(
    "urdf",
    ["single_axis_rate_table.urdf", "two_axis_vertical_outer.urdf", "three_axis_imu_table.urdf"],
)
def test_draws_stay_within_their_bounds(urdf, rng):
    table = GenericTable(MODELS / urdf)
    names = table.angular_names
    upper = rng.uniform(1e-5, 1e-4, len(names))
    lower = upper * rng.uniform(0.0, 0.9, len(names))
    values = sample_errors(rng, 4000, upper, lower, table.chain.error_names, names)
    columns = [table.parameter_names.index(n) for n in names]
    drawn = np.abs(values[:, columns])
    assert np.all(drawn >= lower) and np.all(drawn <= upper)
    assert np.all((values[:, columns] > 0).mean(axis=0) > 0.4)  # both signs
    offsets = [table.parameter_names.index(n) for n in table.length_names]
    assert np.all(values[:, offsets] == 0.0)


def test_each_tables_worst_angles_equal_its_exact_chain():
    table = GenericTable(MODELS / "two_axis_vertical_outer.urdf")
    allocation = allocate_tolerances(LIMITS, table=table, grid_step_deg=30.0)
    result = run_monte_carlo(
        allocation.upper_bounds_rad, LIMITS, 5, seed=11, table=table, grid_step_deg=30.0,
        progress=False,
    )  # fmt: skip
    # Redraw the same tables (chunk seeds as the run spawns them) and evaluate rotation_error.
    seed_seq = np.random.SeedSequence(11).spawn(1)[0]
    values = sample_errors(
        np.random.default_rng(seed_seq), 5, allocation.upper_bounds_rad, np.zeros(9),
        table.chain.error_names, table.angular_names,
    )  # fmt: skip
    grid = list(np.radians(full_turn_grid_deg(30.0, 30.0)).T)
    for k in range(5):
        d_r = table.rotation_error(values[k], grid)  # (N, 3, 3)
        angles = np.stack([d_r[:, i, j] for i, j in ANGLE_ENTRIES], axis=1)
        np.testing.assert_allclose(result.worst_rad[k], np.abs(angles).max(axis=0), atol=1e-15)
    assert result.all_within
    assert np.all(result.max_abs_rad <= allocation.worst_case_rad * (1 + 1e-3))
    assert set(result.to_dict()["upper_bounds_arcmin"]) == set(table.angular_names)


def test_a_run_depends_on_its_seed_only():
    table = GenericTable(MODELS / "single_axis_rate_table.urdf")
    upper = np.full(len(table.angular_names), 2e-5)
    runs = [
        run_monte_carlo(upper, LIMITS, 1200, seed=5, table=table, workers=w, progress=False)
        for w in (1, 2)
    ]
    np.testing.assert_array_equal(runs[0].worst_rad, runs[1].worst_rad)
    other = run_monte_carlo(upper, LIMITS, 1200, seed=6, table=table, progress=False)
    assert not np.array_equal(other.worst_rad, runs[0].worst_rad)


def test_bad_bounds_are_refused():
    table = GenericTable(MODELS / "single_axis_rate_table.urdf")
    with pytest.raises(InputError, match="expected 6 upper and lower bounds"):
        run_monte_carlo(np.ones(8) * 1e-5, LIMITS, 10, 0, table=table, progress=False)
    with pytest.raises(InputError, match="between 0 and its upper bound"):
        run_monte_carlo(
            np.full(6, 1e-5), LIMITS, 10, 0, table=table, lower_bounds_rad=np.full(6, 2e-5),
            progress=False,
        )  # fmt: skip


def _exact_worst(chain, values, grids_rad) -> np.ndarray:
    """(K, 3) largest |dpsi|, |dtheta|, |dgamma| of each error set over the full grid, the chain
    composed at every grid position (no trigonometric coefficients)."""
    mesh = [m.ravel() for m in np.meshgrid(*grids_rad, indexing="ij")]
    ideal = compose_rotation(chain.placements(), mesh)
    out = []
    for row in values:
        d_r = np.swapaxes(ideal, -1, -2) @ compose_rotation(chain.placements(row), mesh)
        out.append([np.abs(d_r[:, i, j]).max() for i, j in ANGLE_ENTRIES])
    return np.array(out)


def _redraw(chain, names, n, chunk_size, seed, upper, lower) -> np.ndarray:
    """The tables a run draws: one spawned seed per chunk, in order."""
    sizes = [chunk_size] * (n // chunk_size) + ([n % chunk_size] if n % chunk_size else [])
    seeds = np.random.SeedSequence(seed).spawn(len(sizes))
    return np.concatenate(
        [
            sample_errors(np.random.default_rng(s), size, upper, lower, chain.error_names, names)
            for s, size in zip(seeds, sizes, strict=True)
        ]
    )


@pytest.mark.parametrize("workers", [1, 2])
def test_paper_tables_over_several_chunks_equal_their_exact_chain(allocation, workers):
    """Every table of three chunks against its chain composed on the full phi1 x phi2 grid:
    the phi2 grid at phi1 = 0 alone gives the same maxima to 1e-12 rad."""
    chain = paper_table().chain
    upper, lower = allocation.upper_bounds_rad, allocation.capability.lower_bounds_rad
    result = run_chain_monte_carlo(
        chain, ANGULAR_ERROR_NAMES, upper, allocation.limits, 61, 3, grid_steps_deg=(30.0, 5.0),
        lower_bounds_rad=lower, chunk_size=25, workers=workers, progress=False,
    )  # fmt: skip
    assert result.evaluated_deg[0] == (0.0,) and len(result.evaluated_deg[1]) == 72
    values = _redraw(chain, ANGULAR_ERROR_NAMES, 61, 25, 3, upper, lower)
    grids = [np.radians(np.arange(0.0, 360.0, 30.0)), np.radians(np.arange(0.0, 360.0, 5.0))]
    np.testing.assert_allclose(result.worst_rad, _exact_worst(chain, values, grids), atol=1e-12)


def test_three_axis_tables_over_several_chunks_equal_their_exact_chain():
    table = GenericTable(MODELS / "three_axis_imu_table.urdf")
    names = table.angular_names
    upper = np.linspace(1e-5, 3e-4, len(names))
    lower = 0.2 * upper
    result = run_chain_monte_carlo(
        table.chain, names, upper, LIMITS, 23, 8, grid_steps_deg=(45.0, 60.0, 40.0),
        lower_bounds_rad=lower, chunk_size=10, progress=False,
    )  # fmt: skip
    assert all(len(a) > 1 for a in result.evaluated_deg)  # every joint moves dR
    assert result.n_grid_points == 8 * 6 * 9 and result.evaluations == 23 * 8 * 6 * 9
    values = _redraw(table.chain, names, 23, 10, 8, upper, lower)
    grids = [np.radians(np.arange(0.0, 360.0, s)) for s in (45.0, 60.0, 40.0)]
    np.testing.assert_allclose(
        result.worst_rad, _exact_worst(table.chain, values, grids), atol=1e-12
    )


def test_a_three_axis_run_does_not_depend_on_the_number_of_workers():
    table = GenericTable(MODELS / "three_axis_imu_table.urdf")
    upper = np.full(len(table.angular_names), 5e-5)
    runs = [
        run_monte_carlo(
            upper, LIMITS, 1100, seed=2, table=table, grid_step_deg=45.0, workers=w, progress=False
        )
        for w in (1, 2)
    ]
    np.testing.assert_array_equal(runs[0].worst_rad, runs[1].worst_rad)
    assert runs[0].to_dict()["n_grid_points"] == 512 and runs[0].to_dict()["urdf"].endswith("urdf")


def test_the_paper_run_is_the_run_of_the_papers_chain(allocation):
    upper, lower = allocation.upper_bounds_rad, allocation.capability.lower_bounds_rad
    paper = run(allocation, n=300, seed=4, grid_step_deg=2.0)
    chain = run_chain_monte_carlo(
        paper_table().chain, ANGULAR_ERROR_NAMES, upper, allocation.limits, 300, 4,
        grid_steps_deg=(10.0, 2.0), lower_bounds_rad=lower, progress=False,
    )  # fmt: skip
    np.testing.assert_array_equal(paper.worst_rad, chain.worst_rad)
    assert paper.grid_steps_deg == (2.0, 2.0) and paper.to_dict()["grid_step_deg"] == 2.0
    assert paper.to_dict()["urdf"].endswith("turntable.urdf")
    assert chain.to_dict()["grid_step_deg"] == {"outer_axis": 10.0, "inner_axis": 2.0}
    # one schema: the paper's run and a URDF table's have the same keys
    other = run_monte_carlo(
        np.full(6, 1e-5), LIMITS, 10, 0, table=GenericTable(MODELS / "single_axis_rate_table.urdf"),
        progress=False,
    )  # fmt: skip
    assert set(other.to_dict()) == set(paper.to_dict())

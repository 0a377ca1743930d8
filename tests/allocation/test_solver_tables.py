"""Allocation on any table: optimal (against SLSQP on the rows of a much denser grid, a
relaxation of the continuous constraint) and admissible (every point of the continuous domain
within the limits, checked on a much denser grid than the solver's), named by the table's errors;
lower bounds are read in those names; the rows the solver works on are the regressor's."""

import numpy as np
import pytest
from scipy.optimize import minimize

from conftest import REPO_DIR, write_file
from turntable_pin.allocation.capability import ManufacturingCapability
from turntable_pin.allocation.sensitivity import check_grid_step
from turntable_pin.allocation.solver import (
    OrientationLimits,
    allocate_tolerances,
    angle_rows,
)
from turntable_pin.core.exceptions import InfeasibleError, InputError
from turntable_pin.core.units import arcsec_to_rad
from turntable_pin.model.angles import ANGLE_SYMBOLS
from turntable_pin.model.generic_table import GenericTable

MODELS = REPO_DIR / "models"
OTHER_TABLES = [
    "single_axis_rate_table.urdf",
    "two_axis_vertical_outer.urdf",
    "three_axis_imu_table.urdf",
]
LIMITS = OrientationLimits.from_arcmin(0.6, 0.25, 0.45)


def full_grid(table, step_deg: float):
    """Every combination of ``0, step, ... < 360`` degrees per joint, in chunks along the first
    joint: one list of flat radian arrays per chunk."""
    axis = np.radians(np.arange(0.0, 360.0 - 1e-9, step_deg))
    for first in np.array_split(axis, max(1, axis.size ** len(table.joint_names) // 40_000)):
        mesh = np.meshgrid(first, *([axis] * (len(table.joint_names) - 1)), indexing="ij")
        yield [m.ravel() for m in mesh]


def first_order_worst(table, upper_rad, step_deg: float) -> np.ndarray:
    """``max over a full grid of sum_i |C_ki(q)| UB_i`` per angle, from the regressor (3,)."""
    columns = [table.parameter_names.index(n) for n in table.angular_names]
    finite = np.where(np.isfinite(upper_rad), upper_rad, 0.0)
    worst = np.zeros(3)
    for grid in full_grid(table, step_deg):
        c = table.regressor(grid)[:, :, columns]
        worst = np.maximum(worst, (np.abs(c) @ finite).max(axis=0))
    return worst


@pytest.mark.parametrize("urdf", OTHER_TABLES)
def test_the_allocation_is_admissible_and_named_by_the_tables_errors(urdf):
    table = GenericTable(MODELS / urdf)
    allocation = allocate_tolerances(LIMITS, table=table, grid_step_deg=30.0)
    assert allocation.error_names == table.angular_names
    assert set(allocation.to_dict()["upper_bounds_arcmin"]) == set(table.angular_names)
    assert np.all(np.isfinite(allocation.upper_bounds_rad))
    assert np.all(allocation.upper_bounds_rad > 0)
    # Independent check of the worst case: every sign corner at every grid position (first order)
    # is within it, and within the limits.
    worst = first_order_worst(table, allocation.upper_bounds_rad, 30.0)
    assert np.all(worst <= allocation.worst_case_rad * (1 + 1e-12))
    assert np.all(allocation.worst_case_rad <= LIMITS.as_array() * (1 + 1e-9))
    # Each angle's own problem reaches its limit (the bounds are as large as allowed).
    for k, sub in enumerate(allocation.subproblems.values()):
        assert sub.constraint_rad == pytest.approx(LIMITS.as_array()[k], rel=1e-6)
    assert table.urdf_path.name in allocation.report()


@pytest.mark.parametrize(
    "urdf, dense_deg",
    [("single_axis_rate_table.urdf", 0.01), ("two_axis_vertical_outer.urdf", 0.5),
     ("three_axis_imu_table.urdf", 6.0)],
)  # fmt: skip
def test_every_point_of_the_continuous_domain_meets_the_limits(urdf, dense_deg):
    """The constraint is semi-infinite: with the default grids (1, 5, 15 deg) the final bounds
    meet the limits on a much denser grid, and the limits are used up (not conservative)."""
    table = GenericTable(MODELS / urdf)
    allocation = allocate_tolerances(LIMITS, table=table)
    dense = first_order_worst(table, allocation.upper_bounds_rad, dense_deg)
    limits = LIMITS.as_array()
    assert np.all(dense <= limits * (1 + 1e-9))
    assert np.all(dense <= allocation.worst_case_rad * (1 + 1e-12))
    np.testing.assert_allclose(dense, allocation.worst_case_rad, rtol=2e-3)  # grid spacing only
    for k, sub in enumerate(allocation.subproblems.values()):
        upper = np.full(len(allocation.error_names), 0.0)
        upper[[allocation.error_names.index(n) for n in sub.error_names]] = sub.solution_rad
        own = first_order_worst(table, upper, dense_deg)[k]
        assert own <= limits[k] * (1 + 1e-9)  # each sub-problem's solution too
        assert own >= limits[k] * (1 - 2e-3)


@pytest.mark.parametrize("urdf", OTHER_TABLES)
def test_the_solvers_rows_are_the_regressors(urdf, rng):
    """The solver works on each angle's rows as trigonometric polynomials of degree one per joint,
    read off the regressor at three angles of each joint: they equal the regressor anywhere."""
    table = GenericTable(MODELS / urdf)
    rows = angle_rows(table, 30.0)
    points = rng.uniform(-np.pi, np.pi, (20, len(table.joint_names)))
    exact = table.regressor(list(points.T))
    for k, name in enumerate(ANGLE_SYMBOLS):
        columns = [table.parameter_names.index(n) for n in rows[name].error_names]
        np.testing.assert_allclose(rows[name].values(points), exact[:, k, columns], atol=1e-14)
        others = [
            table.parameter_names.index(n)
            for n in table.angular_names
            if n not in rows[name].error_names
        ]
        assert np.all(np.abs(exact[:, k, others]) < 1e-12)  # the errors left out do not move it


@pytest.mark.parametrize(
    "urdf, dense_deg", [("two_axis_vertical_outer.urdf", 2.0), ("three_axis_imu_table.urdf", 10.0)]
)
def test_each_problem_is_solved_to_its_optimum(urdf, dense_deg):
    """SLSQP on every row of a much denser grid solves a relaxation of the continuous problem: its
    optimum is never above ours and only as far below as the grid spacing allows."""
    table = GenericTable(MODELS / urdf)
    allocation = allocate_tolerances(LIMITS, weights="equal", table=table, grid_step_deg=45.0)
    c = np.concatenate([np.abs(table.regressor(grid)) for grid in full_grid(table, dense_deg)])
    for k, sub in enumerate(allocation.subproblems.values()):
        columns = [table.parameter_names.index(n) for n in sub.error_names]
        z = sub.solution_rad / LIMITS.as_array()[k]
        rows = c[:, k, columns]  # sum rows z <= 1 with z = x / limit
        rows = rows[rows @ z >= 0.999]  # fewer rows: still a relaxation
        rows = np.unique(np.round(rows, 6), axis=0)  # and no near-duplicates
        res = minimize(  # SLSQP on every row at once, from a feasible start
            lambda v: float(np.sum(1.0 / v**2)),
            0.99 * z / float(np.max(rows @ z)),
            jac=lambda v: -2.0 / v**3,
            bounds=[(1e-9, None)] * len(columns),
            constraints=[
                {"type": "ineq", "fun": lambda v, r=rows: 1.0 - r @ v, "jac": lambda v, r=rows: -r}
            ],  # fmt: skip
            method="SLSQP",
            options={"ftol": 1e-14, "maxiter": 2000},
        )
        ours = np.sum(1 / z**2)
        assert ours >= res.fun * (1 - 1e-6)  # the relaxation is not above
        assert ours <= res.fun * (1 + 4e-4 * (dense_deg / 2.0) ** 2)  # and close below


def test_lower_bounds_in_the_tables_names(tmp_path):
    table = GenericTable(MODELS / "two_axis_vertical_outer.urdf")
    path = write_file(
        tmp_path,
        "lower_bounds:\n  tilt_axis.tilt_a: 1\n  imu_mount.rot_z_arcmin: 0.01\n",
        "lb.yaml",
    )
    capability = ManufacturingCapability.from_yaml(path, table)
    lower = capability.lower_bounds_rad
    names = table.angular_names
    assert lower[names.index("tilt_axis.tilt_a")] == pytest.approx(arcsec_to_rad(1.0))
    assert lower[names.index("imu_mount.rot_z")] == pytest.approx(arcsec_to_rad(0.6))
    allocation = allocate_tolerances(LIMITS, capability=capability, table=table, grid_step_deg=30)
    assert np.all(allocation.upper_bounds_rad >= lower)
    too_big = write_file(tmp_path, "lower_bounds:\n  tilt_axis.tilt_a_arcmin: 2\n", "big.yaml")
    with pytest.raises(InfeasibleError, match="lower bounds alone"):
        allocate_tolerances(
            LIMITS, capability=ManufacturingCapability.from_yaml(too_big, table), table=table,
            grid_step_deg=30,
        )  # fmt: skip
    for text, fragment in [
        ("lower_bounds:\n  dphi_y1: 1\n", "unknown error name 'dphi_y1'"),
        ("lower_bounds:\n  tilt_axis.offset_a_mm: 1\n", "not an angular error"),
        ("lower_bounds:\n  tilt_axis.tilt_a: -1\n", "negative"),
        ("bounds: {}\n", "lower_bounds"),
    ]:
        with pytest.raises(InputError, match=fragment):
            ManufacturingCapability.from_yaml(write_file(tmp_path, text, "bad.yaml"), table)


def test_bad_grid_and_weights_are_refused():
    table = GenericTable(MODELS / "three_axis_imu_table.urdf")
    with pytest.raises(InputError, match="coarser grid_step_deg"):
        check_grid_step(table, 1.0)
    with pytest.raises(InputError, match=r"\[1e-06, 90\] degrees"):
        check_grid_step(table, 0.0)
    with pytest.raises(InputError, match="choose one of model, paper, equal"):
        allocate_tolerances(LIMITS, weights="figure8", table=table)
    # the paper's Figure 8 rule is one rule: any table takes it
    assert allocate_tolerances(LIMITS, weights="paper", table=table).weights_scheme == "paper"

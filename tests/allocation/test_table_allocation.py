"""Allocation on any table: sensitivities equal central finite differences of the exact chain,
the allocation is optimal (against SLSQP on every grid row) and admissible (first-order worst case
within the limits), is named by the table's errors, and lower bounds are read in those names."""

import numpy as np
import pytest
from scipy.optimize import minimize

from conftest import PAPER_TO_GENERIC, REPO_DIR, write_file
from turntable_pin.allocation.solver import OrientationLimits
from turntable_pin.allocation.table_allocation import (
    allocate_table_tolerances,
    angular_names,
    grid_angles_rad,
    table_lower_bounds,
    table_sensitivities,
)
from turntable_pin.core.exceptions import InfeasibleError, InputError
from turntable_pin.core.units import arcsec_to_rad
from turntable_pin.model.angles import ANGLE_ENTRIES
from turntable_pin.model.generic_table import GenericTable

MODELS = REPO_DIR / "models"
OTHER_TABLES = [
    "single_axis_rate_table.urdf",
    "two_axis_vertical_outer.urdf",
    "three_axis_imu_table.urdf",
]
LIMITS = OrientationLimits.from_arcmin(0.6, 0.25, 0.45)


@pytest.mark.parametrize("urdf", OTHER_TABLES)
def test_sensitivities_equal_central_differences_of_the_exact_chain(urdf, rng):
    table = GenericTable(MODELS / urdf)
    sens = table_sensitivities(table, 60.0)
    names = angular_names(table)
    assert sens.error_names == names and not any(".offset" in n for n in names)
    picks = rng.choice(len(sens.grid_rad[0]), size=4, replace=False)
    step = 1e-6
    for p in picks:
        angles = [g[p] for g in sens.grid_rad]
        for col, name in enumerate(names):
            sides = []
            for sign in (1.0, -1.0):
                values = table.values({name: sign * step})
                d_r = table.rotation_error(values, angles)
                sides.append(np.array([d_r[i, j] for i, j in ANGLE_ENTRIES]))
            fd = (sides[0] - sides[1]) / (2 * step)
            np.testing.assert_allclose(sens.matrices[p, :, col], fd, atol=1e-9)
    np.testing.assert_allclose(sens.values, np.abs(sens.matrices).mean(axis=0))


@pytest.mark.parametrize("urdf", OTHER_TABLES)
def test_the_allocation_is_admissible_and_named_by_the_tables_errors(urdf):
    table = GenericTable(MODELS / urdf)
    allocation = allocate_table_tolerances(table, LIMITS, grid_step_deg=30.0)
    assert allocation.error_names == angular_names(table)
    assert set(allocation.to_dict()["upper_bounds_arcmin"]) == set(angular_names(table))
    assert np.all(np.isfinite(allocation.upper_bounds_rad))
    assert np.all(allocation.upper_bounds_rad > 0)
    # Independent check of the worst case: every sign corner at every grid position (first order).
    c = table_sensitivities(table, 30.0).matrices  # (N, 3, P)
    worst = (np.abs(c) @ allocation.upper_bounds_rad).max(axis=0)
    np.testing.assert_allclose(allocation.worst_case_rad, worst)
    assert np.all(worst <= LIMITS.as_array() * (1 + 1e-9))
    # Each angle's own problem reaches its limit (the bounds are as large as allowed).
    for k, sub in enumerate(allocation.subproblems.values()):
        assert sub.worst_rad == pytest.approx(LIMITS.as_array()[k], rel=1e-6)
    assert table.urdf_path.name in allocation.report()


@pytest.mark.parametrize("urdf", ["two_axis_vertical_outer.urdf", "three_axis_imu_table.urdf"])
def test_each_problem_is_solved_to_its_optimum(urdf):
    table = GenericTable(MODELS / urdf)
    allocation = allocate_table_tolerances(table, LIMITS, weights="equal", grid_step_deg=45.0)
    c = np.abs(table_sensitivities(table, 45.0).matrices)
    for k, sub in enumerate(allocation.subproblems.values()):
        columns = [allocation.error_names.index(n) for n in sub.error_names]
        rows = c[:, k, columns] / LIMITS.as_array()[k]
        res = minimize(  # SLSQP on every row at once, from a feasible start
            lambda z: float(np.sum(1.0 / z**2)),
            np.full(len(columns), 0.5 / rows.sum(axis=1).max()),
            jac=lambda z: -2.0 / z**3,
            bounds=[(1e-9, None)] * len(columns),
            constraints=[{"type": "ineq", "fun": lambda z, r=rows: 1.0 - r @ z}],
            method="SLSQP",
            options={"ftol": 1e-14, "maxiter": 2000},
        )
        z = sub.solution_rad / LIMITS.as_array()[k]
        assert np.sum(1 / z**2) <= res.fun * (1 + 1e-6)


def test_lower_bounds_in_the_tables_names(tmp_path):
    table = GenericTable(MODELS / "two_axis_vertical_outer.urdf")
    path = write_file(
        tmp_path,
        "lower_bounds:\n  tilt_axis.tilt_a: 1\n  imu_mount.rot_z_arcmin: 0.01\n",
        "lb.yaml",
    )
    lower = table_lower_bounds(table, path)
    names = angular_names(table)
    assert lower[names.index("tilt_axis.tilt_a")] == pytest.approx(arcsec_to_rad(1.0))
    assert lower[names.index("imu_mount.rot_z")] == pytest.approx(arcsec_to_rad(0.6))
    allocation = allocate_table_tolerances(table, LIMITS, lower_bounds_rad=lower, grid_step_deg=30)
    assert np.all(allocation.upper_bounds_rad >= lower)
    too_big = write_file(tmp_path, "lower_bounds:\n  tilt_axis.tilt_a_arcmin: 2\n", "big.yaml")
    with pytest.raises(InfeasibleError, match="lower bounds alone"):
        allocate_table_tolerances(
            table, LIMITS, lower_bounds_rad=table_lower_bounds(table, too_big), grid_step_deg=30
        )
    for text, fragment in [
        ("lower_bounds:\n  dphi_y1: 1\n", "unknown error name 'dphi_y1'"),
        ("lower_bounds:\n  tilt_axis.offset_a_mm: 1\n", "not an angular error"),
        ("lower_bounds:\n  tilt_axis.tilt_a: -1\n", "negative"),
        ("bounds: {}\n", "lower_bounds"),
    ]:
        with pytest.raises(InputError, match=fragment):
            table_lower_bounds(table, write_file(tmp_path, text, "bad.yaml"))


def test_bad_grid_and_weights_are_refused():
    table = GenericTable(MODELS / "three_axis_imu_table.urdf")
    with pytest.raises(InputError, match="coarser --grid-step-deg"):
        grid_angles_rad(table, 1.0)
    with pytest.raises(InputError, match=r"\(0, 90\]"):
        grid_angles_rad(table, 0.0)
    with pytest.raises(InputError, match="choose one of model, equal"):
        allocate_table_tolerances(table, LIMITS, weights="paper")


def test_the_paper_table_through_the_generic_sensitivities_equals_its_own(rng):
    from turntable_pin.allocation.sensitivity import sensitivity_matrix
    from turntable_pin.model.errors import ANGULAR_ERROR_NAMES
    from turntable_pin.model.turntable import TurntableModel

    mapping = PAPER_TO_GENERIC
    table = GenericTable(MODELS / "turntable.urdf")
    names = angular_names(table)
    model = TurntableModel()
    for phi1, phi2 in rng.uniform(-np.pi, np.pi, (4, 2)):
        generic = table.regressor([np.array([phi1]), np.array([phi2])])[0]
        paper = sensitivity_matrix(model, phi1, phi2)
        for col, paper_name in enumerate(ANGULAR_ERROR_NAMES):
            column = table.parameter_names.index(mapping[paper_name])
            np.testing.assert_allclose(paper[:, col], generic[:, column], atol=1e-12)
    assert set(mapping.values()) <= set(names)

"""The paper's table is data over the one table class: the generic table under the paper's layout
reproduces the paper's chain (Table 3), its first-order model (eq. 26) and the façade of earlier
versions exactly; URDFs are given the paper's names only when they have the paper's joints."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import REPO_DIR, random_errors
from spec_reference import Rx, Ry, Rz
from turntable_pin import TurntableErrors
from turntable_pin.core.exceptions import ModelError
from turntable_pin.model.errors import ANGULAR_ERROR_NAMES, ERROR_NAMES
from turntable_pin.model.generic_table import GenericTable
from turntable_pin.model.paper_table import PAPER_LAYOUT, paper_table, table_of
from turntable_pin.model.small_angle import small_angle_matrix

MODELS = REPO_DIR / "models"
ANGLE = st.floats(-2 * np.pi, 2 * np.pi, allow_nan=False)


def _table3_rotation(errors: TurntableErrors, phi1: float, phi2: float) -> np.ndarray:
    """Rt of Table 3 written out by hand (independent of the layout machinery)."""
    e = errors
    return (
        Ry(phi1) @ Ry(e.dphi_y1) @ Rz(e.dalpha_z1) @ Rx(e.dalpha_x1) @ Ry(e.deps_y)
        @ Rx(e.deps_x) @ Rz(phi2) @ Ry(e.dalpha_y2) @ Rz(e.dphi_z2) @ Rx(e.dalpha_x2)
    )  # fmt: skip


def test_the_paper_table_is_the_generic_table_under_the_paper_layout():
    table = paper_table()
    assert isinstance(table, GenericTable)
    assert table.layout is PAPER_LAYOUT
    assert table.parameter_names == ERROR_NAMES
    assert table.angular_names == ANGULAR_ERROR_NAMES
    assert table.length_names == ("deta",)
    assert table.joint_names == ("outer_axis", "inner_axis")
    assert table.label == "paper"
    assert paper_table() is table  # read once per process


@settings(max_examples=40, deadline=None)
@given(phi1=ANGLE, phi2=ANGLE, seed=st.integers(0, 2**32 - 1))
def test_pinocchio_numpy_chain_and_table3_agree(phi1, phi2, seed):
    errors = random_errors(np.random.default_rng(seed), scale_arcsec=200.0)
    table = paper_table()
    by_hand = Ry(phi1) @ Rz(phi2)
    expected = by_hand.T @ _table3_rotation(errors, phi1, phi2)
    pinocchio = table.orientation_error(errors.as_array(), (phi1, phi2)).dR
    numpy_chain = table.rotation_error(errors.as_array(), (phi1, phi2))
    np.testing.assert_allclose(pinocchio, expected, atol=1e-12)
    np.testing.assert_allclose(numpy_chain, expected, atol=1e-12)


def test_the_regressor_on_the_paper_table_is_eq_26():
    phi = np.random.default_rng(3).uniform(-np.pi, np.pi, (2, 50))
    regressor = paper_table().regressor(phi)
    np.testing.assert_allclose(regressor[:, :, :8], small_angle_matrix(phi[1]), atol=1e-12)
    np.testing.assert_array_equal(regressor[:, :, 8], 0.0)  # deta moves, never turns


def test_urdfs_get_the_paper_names_only_with_the_paper_joints():
    assert table_of().layout is PAPER_LAYOUT
    assert table_of(MODELS / "turntable.urdf").layout is PAPER_LAYOUT
    for other in ("two_axis_vertical_outer", "three_axis_imu_table", "altaz_mount"):
        table = table_of(MODELS / f"{other}.urdf")
        assert table.layout is not PAPER_LAYOUT
        assert table.label.endswith(f"{other}.urdf")
        assert all("." in name for name in table.parameter_names)
    # another payload frame on the paper's URDF is no longer the paper's table
    assert table_of(MODELS / "turntable.urdf", "payload_mount").layout is not PAPER_LAYOUT


def test_a_layout_on_a_urdf_without_its_joints_is_refused_naming_both():
    with pytest.raises(ModelError, match="written for joints outer_axis, inner_axis.*has"):
        GenericTable(MODELS / "three_axis_imu_table.urdf", "imu", layout=PAPER_LAYOUT)


def test_yourdfpy_checks_any_table_independently(tmp_path):
    from turntable_pin.model.urdf_io import YourdfpyTurntable

    table = table_of(MODELS / "three_axis_imu_table.urdf")
    values = np.radians(np.random.default_rng(5).normal(0, 0.01, len(table.parameter_names)))
    values[[table.parameter_names.index(n) for n in table.length_names]] = 1e-4
    other = YourdfpyTurntable(
        table.write_urdf(values, tmp_path / "t.urdf"), table.urdf_path, table.joint_names,
        table.payload_frame,
    )  # fmt: skip
    for angles in [(0.1, 0.7, -1.2), (2.0, -0.4, 0.9)]:
        exact = table.orientation_error(values, angles)
        np.testing.assert_allclose(other.orientation_error_matrix(*angles), exact.dR, atol=1e-12)
        np.testing.assert_allclose(
            other.payload_origin_m(*angles), exact.payload_origin_m, atol=1e-12
        )

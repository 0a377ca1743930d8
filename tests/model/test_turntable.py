"""Pinocchio forward kinematics of the paper's table against independent computations."""

import numpy as np
import pinocchio as pin
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import random_errors
from spec_reference import Rx, Ry, Rz
from turntable_pin import ANGULAR_ERROR_NAMES, TurntableErrors, YourdfpyTurntable
from turntable_pin.model.paper_table import paper_table
from turntable_pin.model.small_angle import small_angle_matrix, small_angle_orientation_error


def table3_chain(e: TurntableErrors, phi1, phi2):
    """Paper Table 3 written out factor by factor, independent of the package's chain."""
    rt = (
        Ry(phi1) @ Ry(e.dphi_y1) @ Rz(e.dalpha_z1) @ Rx(e.dalpha_x1)
        @ Ry(e.deps_y) @ Rx(e.deps_x)
        @ Rz(phi2) @ Ry(e.dalpha_y2) @ Rz(e.dphi_z2) @ Rx(e.dalpha_x2)
    )  # fmt: skip
    rd = Ry(phi1) @ Rz(phi2)
    return rd.T @ rt


angle = st.floats(-2 * np.pi, 2 * np.pi)
error = st.floats(-1e-2, 1e-2)


@settings(max_examples=60, deadline=None)
@given(st.lists(error, min_size=8, max_size=8), st.floats(-1e-3, 1e-3), angle, angle)
def test_pinocchio_equals_table3_product(chi, deta, phi1, phi2):
    errors = TurntableErrors.from_array([*chi, deta])
    result = paper_table().orientation_error(errors.as_array(), (phi1, phi2))
    np.testing.assert_allclose(result.dR, table3_chain(errors, phi1, phi2), rtol=0, atol=1e-12)
    assert result.dpsi_rad == result.dR[0, 2]
    assert result.dtheta_rad == result.dR[1, 0]
    assert result.dgamma_rad == result.dR[2, 1]


def test_zero_errors_give_identity_exactly(rng):
    table = paper_table()
    for phi1, phi2 in rng.uniform(-10, 10, size=(50, 2)):
        result = table.orientation_error(np.zeros(9), (phi1, phi2))
        # Rd and Rt come from the same products; with identity placements they agree bit for bit.
        np.testing.assert_array_equal(result.dR @ np.eye(3), result.dR)
        assert np.abs(result.dR - np.eye(3)).max() <= 4 * np.finfo(float).eps
        np.testing.assert_array_equal(result.payload_origin_m, np.zeros(3))


def test_deta_moves_the_origin_and_not_the_orientation(rng):
    base = random_errors(rng)
    shifted = TurntableErrors.from_array(base.as_array() + np.r_[np.zeros(8), 3e-4])
    table = paper_table()
    for phi1, phi2 in rng.uniform(-4, 4, size=(20, 2)):
        ra = table.orientation_error(base.as_array(), (phi1, phi2))
        rb = table.orientation_error(shifted.as_array(), (phi1, phi2))
        np.testing.assert_allclose(ra.dR, rb.dR, atol=1e-15)
        moved = np.linalg.norm(rb.payload_origin_m - ra.payload_origin_m)
        assert abs(moved - 3e-4) < 1e-12  # a rigid translation of length 3e-4 m


def test_only_deta_moves_the_origin(rng):
    no_deta = TurntableErrors.from_array(np.r_[random_errors(rng).angular_array_rad(), 0.0])
    table = paper_table()
    for phi1, phi2 in rng.uniform(-4, 4, size=(10, 2)):
        origin = table.orientation_error(no_deta.as_array(), (phi1, phi2)).payload_origin_m
        assert np.abs(origin).max() < 1e-15


def test_small_angle_is_second_order(rng):
    """Halving every error quarters the difference between eq. 26 and the exact chain."""
    errors = random_errors(rng, scale_arcsec=2000.0)  # large, so second-order terms dominate
    phis = rng.uniform(-np.pi, np.pi, size=(20, 2))

    def gap(e):
        out = []
        for phi1, phi2 in phis:
            r = paper_table().orientation_error(e.as_array(), (phi1, phi2))
            exact = np.array([r.dpsi_rad, r.dtheta_rad, r.dgamma_rad])
            out.append(exact - small_angle_orientation_error(e, phi2))
        return np.array(out)

    g1, g2, g3 = gap(errors), gap(errors.scaled(0.5)), gap(errors.scaled(0.25))
    ratio12 = np.abs(g1).max() / np.abs(g2).max()
    ratio23 = np.abs(g2).max() / np.abs(g3).max()
    assert 3.8 < ratio12 < 4.2 and 3.9 < ratio23 < 4.1
    # and the first-order model really is first-order correct: the gap is O(err^2)
    assert np.abs(g1).max() < 5 * (2000 / 206265) ** 2


def test_written_urdf_reloads_in_pinocchio_and_yourdfpy(tmp_path, rng):
    for _ in range(3):
        errors = random_errors(rng, scale_arcsec=500.0)
        table = paper_table()
        path = table.write_urdf(errors.as_array(), tmp_path / "with_errors.urdf")
        plain = pin.buildModelFromUrdf(str(path))
        data = plain.createData()
        frame = plain.getFrameId("gyrowheel")
        other = YourdfpyTurntable(path)
        for phi1, phi2 in rng.uniform(-7, 7, size=(10, 2)):
            expected = table.orientation_error(errors.as_array(), (phi1, phi2))
            pin.framesForwardKinematics(plain, data, np.array([phi1, phi2]))
            rd = Ry(phi1) @ Rz(phi2)
            np.testing.assert_allclose(rd.T @ data.oMf[frame].rotation, expected.dR, atol=1e-12)
            np.testing.assert_allclose(
                other.orientation_error_matrix(phi1, phi2), expected.dR, atol=1e-12
            )
            np.testing.assert_allclose(
                other.payload_origin_m(phi1, phi2), expected.payload_origin_m, atol=1e-12
            )


def test_write_refuses_to_overwrite_the_nominal(tmp_path):
    import shutil

    from turntable_pin import InputError, default_urdf_path

    copy = tmp_path / "t.urdf"
    shutil.copy(default_urdf_path(), copy)
    before = copy.read_bytes()
    errors = TurntableErrors.from_arcsec(dphi_y1=1)
    try:
        paper_table(copy).write_urdf(errors.as_array(), copy)
    except InputError as exc:
        assert "refusing to overwrite" in str(exc)
    else:
        raise AssertionError("overwrote the input URDF")
    assert copy.read_bytes() == before


def test_central_differences_of_the_exact_chain_give_eq26(rng):
    """d(dpsi, dtheta, dgamma)/d(error) of the exact chain at zero error is the matrix of eq. 26."""
    h = 1e-6
    for phi1, phi2 in rng.uniform(-4, 4, size=(5, 2)):
        columns = []
        for name in ANGULAR_ERROR_NAMES:
            plus, minus = (
                paper_table().orientation_error(
                    TurntableErrors(**{name: d}).as_array(), (phi1, phi2)
                )
                for d in (h, -h)
            )
            columns.append(
                [(getattr(plus, a) - getattr(minus, a)) / (2 * h)
                 for a in ("dpsi_rad", "dtheta_rad", "dgamma_rad")]
            )  # fmt: skip
        np.testing.assert_allclose(np.array(columns).T, small_angle_matrix(phi2), atol=1e-9)


def test_models_dir_prefers_the_environment_then_the_checkout(tmp_path, monkeypatch):
    from turntable_pin.core.resources import default_urdf_path, models_dir

    assert (models_dir() / "turntable.urdf").is_file()  # the repository's models/
    monkeypatch.setenv("TURNTABLE_PIN_MODELS", str(tmp_path))
    assert models_dir() == tmp_path and default_urdf_path() == tmp_path / "turntable.urdf"

"""The orientation requirement (eqs. 15-16): the rectangles are inside, maximal and largest."""

import numpy as np
import pytest

from turntable_pin import InputError
from turntable_pin.calibration.positions import PositionSet
from turntable_pin.calibration.rate_error import orientation_error_rotation, rate_errors_dph
from turntable_pin.calibration.requirement import _MARGIN, orientation_requirement

LAT_RAD = np.radians(45.75)
W_M = 0.01


@pytest.fixture(scope="module", params=["grid:45", "grid:90"])
def requirement(request):
    return orientation_requirement(W_M, PositionSet.parse(request.param), LAT_RAD)


@pytest.fixture(scope="module")
def calibrated_requirement():
    return orientation_requirement(
        W_M, PositionSet.parse("grid:45"), LAT_RAD, definition="calibrated_coefficients"
    )


def rate_errors(result, angles):
    """[dwx, dwy] at (M, 3) angle triples, straight from eqs. 7-14."""
    rotations = orientation_error_rotation(*np.asarray(angles, float).T, exact=result.exact)
    return rate_errors_dph(result.gyrowheel, result.inputs, rotations, definition=result.definition)


def plane_points(u_half, v_half, n=41):
    u, v = np.meshgrid(np.linspace(-u_half, u_half, n), np.linspace(-v_half, v_half, n))
    return u.ravel(), v.ravel()


def check_inside_and_maximal(result):
    psi, theta, gamma = result.limits_rad
    u, v = plane_points(psi, theta)
    inside_x = rate_errors(result, np.c_[u, v, 0 * u])[:, 0]
    u, v = plane_points(theta, gamma)
    inside_y = rate_errors(result, np.c_[0 * u, u, v])[:, 1]
    assert inside_x.max() <= W_M * (1 + 1e-9)
    assert inside_y.max() <= W_M * (1 + 1e-9)
    grow = 1 + 1e-6
    corners = np.array([[1, 1], [1, -1], [-1, 1], [-1, -1]])

    def worst_x(p, t):
        return rate_errors(result, np.c_[corners[:, 0] * p, corners[:, 1] * t, np.zeros(4)])[
            :, 0
        ].max()

    def worst_y(t, g):
        return rate_errors(result, np.c_[np.zeros(4), corners[:, 0] * t, corners[:, 1] * g])[
            :, 1
        ].max()

    assert worst_x(psi * grow, theta) > W_M
    assert worst_y(theta, gamma * grow) > W_M
    assert max(worst_x(psi, theta * grow), worst_y(theta * grow, gamma)) > W_M


def test_rectangles_are_inside_and_maximal(requirement):
    check_inside_and_maximal(requirement)


def test_rectangles_are_inside_and_maximal_for_the_calibrated_definition(calibrated_requirement):
    check_inside_and_maximal(calibrated_requirement)


@pytest.mark.slow
def test_each_plane_rectangle_has_the_largest_area_brute_force(requirement):
    for index, rect in enumerate(requirement.rectangles):
        u_limit, v_limit = rect.axis_limits_rad
        n = 101
        us, vs = np.linspace(0, u_limit, n), np.linspace(0, v_limit, n)
        u, v = np.meshgrid(us, vs, indexing="ij")
        worst = np.zeros(u.shape)
        for su, sv in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
            angles = np.zeros((u.size, 3))
            angles[:, index] = su * u.ravel()
            angles[:, index + 1] = sv * v.ravel()
            worst = np.maximum(worst, rate_errors(requirement, angles)[:, index].reshape(u.shape))
        brute = np.max(np.where(worst <= W_M, u * v, 0.0))
        area = rect.half_widths_rad[0] * rect.half_widths_rad[1]
        assert area >= brute * (1 - 1e-9)
        assert area <= brute * (1 + 4.0 / n)  # the grid's resolution


def test_theta_is_shared_from_the_binding_plane(requirement):
    theta_x = requirement.rectangles[0].half_widths_rad[1]
    theta_y = requirement.rectangles[1].half_widths_rad[0]
    # The shared theta may be stepped in once by 2 _MARGIN (where rounding puts its corner out).
    assert requirement.theta_rad == pytest.approx(min(theta_x, theta_y), rel=3 * _MARGIN, abs=0)
    assert requirement.binding_plane == ("psi_theta" if theta_x <= theta_y else "theta_gamma")
    # the free side of the other plane can only have grown
    if requirement.binding_plane == "psi_theta":
        assert requirement.gamma_rad >= requirement.rectangles[1].half_widths_rad[1] * (1 - 1e-9)
    else:
        assert requirement.psi_rad >= requirement.rectangles[0].half_widths_rad[0] * (1 - 1e-9)


def test_box_corners_are_reported(requirement):
    signs = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T
    worst = rate_errors(requirement, signs * requirement.limits_rad).max(axis=0)
    assert requirement.box_dwx_dph == pytest.approx(worst[0], rel=1e-12)
    assert requirement.box_dwy_dph == pytest.approx(worst[1], rel=1e-12)


def test_limits_scale_with_the_accuracy():
    # dw is first order in the angles: halving w_m halves the limits (to second order).
    positions = PositionSet.parse("grid:90")
    a = orientation_requirement(0.01, positions, LAT_RAD)
    b = orientation_requirement(0.005, positions, LAT_RAD)
    np.testing.assert_allclose(b.limits_rad, a.limits_rad / 2, rtol=2e-3)


def test_to_dict_states_the_set_up(requirement):
    d = requirement.to_dict()
    for key in ("I_psi_deg", "I_theta_deg", "I_gamma_deg", "positions", "latitude_deg"):
        assert key in d
    assert d["latitude_deg"] == pytest.approx(45.75)
    assert d["I_psi_deg"] == pytest.approx(np.degrees(requirement.psi_rad))


def test_bad_accuracy():
    with pytest.raises(InputError, match="positive"):
        orientation_requirement(0.0, PositionSet.parse("grid:90"), LAT_RAD)


def test_a_long_requirement_reports_its_progress_on_stderr(monkeypatch, capsys):
    """A requirement past PROGRESS_DELAY_S reports each step on stderr (a three-axis grid takes
    5-20 s); progress=False, the library's default, and --quiet say nothing (issue 30)."""
    import turntable_pin.calibration.requirement as module
    from turntable_pin.cli import main

    positions = PositionSet.parse("grid:90")
    monkeypatch.setattr(module, "PROGRESS_DELAY_S", 0.0)
    quiet = orientation_requirement(W_M, positions, LAT_RAD)
    assert capsys.readouterr().err == ""
    loud = orientation_requirement(W_M, positions, LAT_RAD, progress=True)
    lines = capsys.readouterr().err.splitlines()
    steps = 2 * module.rectangle_steps() + 2
    assert lines[-1].startswith(f"requirement (16 positions): 100% ({steps}/{steps}, ")
    assert len(lines) >= 10 and loud.to_dict() == quiet.to_dict()
    assert main(["requirement", "--positions", "grid:90"]) == 0
    assert "requirement (16 positions): 100%" in capsys.readouterr().err
    assert main(["requirement", "--positions", "grid:90", "--quiet"]) == 0
    assert capsys.readouterr().err == ""

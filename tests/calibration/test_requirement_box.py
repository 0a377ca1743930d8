"""The requirement as a box that holds: every orientation error in it meets the accuracy, it is
tight, it is the largest (volume), and the paper's planes beside it are unchanged."""

import json

import numpy as np
import pytest

from turntable_pin import InputError
from turntable_pin.calibration.gyrowheel import GyroWheelModel
from turntable_pin.calibration.positions import PositionSet, position_inputs
from turntable_pin.calibration.rate_error import (
    orientation_error_rotation,
    rate_error,
    rate_errors_dph,
)
from turntable_pin.calibration.requirement import (
    box_corners,
    holding_scale,
    largest_box,
    orientation_requirement,
    rate_error_jacobian,
)
from turntable_pin.cli import main

LAT_RAD = np.radians(45.75)
W_M = 0.01
SETUPS = {
    "grid:30": ("grid:30", "true_coefficients", False),
    "grid:90x60": ("grid:90x60", "true_coefficients", False),
    "grid:45 exact": ("grid:45", "true_coefficients", True),
    "grid:45 beta1": ("grid:45", "calibrated_coefficients", False),
}


@pytest.fixture(scope="module", params=list(SETUPS))
def requirement(request):
    spec, definition, exact = SETUPS[request.param]
    return orientation_requirement(
        W_M, PositionSet.parse(spec), LAT_RAD, definition=definition, exact=exact
    )


def rate_errors(result, angles):
    """[dwx, dwy] at (M, 3) angle triples, straight from eqs. 7-14 (rate_error.py)."""
    rotations = orientation_error_rotation(*np.asarray(angles, float).T, exact=result.exact)
    return rate_errors_dph(result.gyrowheel, result.inputs, rotations, definition=result.definition)


def test_every_corner_and_random_inside_points_meet_the_accuracy(requirement):
    limits = requirement.box.limits_rad
    corners = rate_errors(requirement, box_corners(limits))
    assert corners.max() <= W_M * (1 + 1e-12)
    assert corners.max() == pytest.approx(W_M, rel=1e-9)  # a corner is on the contour
    rng = np.random.default_rng(19)
    inside = rng.uniform(-1.0, 1.0, (2000, 3)) * limits
    faces = box_corners(limits)[rng.integers(0, 8, 600)]  # points on the faces and edges
    faces[np.arange(600), rng.integers(0, 3, 600)] *= rng.uniform(-1.0, 1.0, 600)
    assert rate_errors(requirement, np.vstack([inside, faces])).max() <= W_M * (1 + 1e-12)


def test_the_box_is_tight(requirement):
    limits = requirement.box.limits_rad
    assert rate_errors(requirement, box_corners(1.001 * limits)).max() > W_M
    # the largest volume leaves no limit free: growing any one alone breaks the accuracy
    for k in range(3):
        grown = limits.copy()
        grown[k] *= 1.001
        assert rate_errors(requirement, box_corners(grown)).max() > W_M


def test_reported_corner_rates_are_those_of_the_model(requirement):
    box = requirement.box
    worst = rate_errors(requirement, box_corners(box.limits_rad)).max(axis=0)
    assert box.dwx_dph == pytest.approx(worst[0], rel=1e-12)
    assert box.dwy_dph == pytest.approx(worst[1], rel=1e-12)
    assert box.binding and box.criterion == "largest volume" and not any(box.capped)


def test_the_box_has_the_largest_volume_of_the_boxes_that_hold_to_first_order(requirement):
    jacobian = rate_error_jacobian(
        requirement.gyrowheel, requirement.inputs, exact=requirement.exact,
        definition=requirement.definition,
    )  # fmt: skip
    rows = np.abs(jacobian).reshape(-1, 3)
    limits, _ = largest_box(jacobian, W_M)
    assert (rows @ limits).max() <= W_M * (1 + 1e-12)
    # brute force: every direction scaled to the first-order contour, then refined around the best
    rng = np.random.default_rng(7)
    directions = rng.dirichlet(np.ones(3), 50_000)
    for spread in (0.02, 0.005, 0.001):
        scaled = directions * (W_M / (directions @ rows.T).max(axis=1))[:, None]
        best = scaled[np.argmax(np.prod(scaled, axis=1))]
        directions = np.abs(best / best.sum() + rng.normal(0, spread, (20_000, 3)))
    assert np.prod(limits) >= np.prod(best) * (1 - 1e-9)
    # and the full model's box is the first-order one scaled (by 1 - O(I))
    assert requirement.box.scale == pytest.approx(1.0, abs=1e-3)
    box = requirement.box
    np.testing.assert_allclose(box.limits_rad, box.scale * limits, rtol=1e-9)


def test_jacobian_is_the_rate_error_of_small_single_angles():
    gyrowheel = GyroWheelModel.nominal()
    inputs = position_inputs(PositionSet.parse("grid:45"), LAT_RAD)
    jacobian = rate_error_jacobian(gyrowheel, inputs)
    h = 1e-7
    for k in range(3):
        angles = np.zeros(3)
        angles[k] = h
        plus = rate_error(gyrowheel, inputs, *angles).dw_dph
        minus = rate_error(gyrowheel, inputs, *-angles).dw_dph
        np.testing.assert_allclose(jacobian[:, :, k], (plus - minus) / (2 * h), atol=1e-6)


def test_holding_scale_of_the_planes_is_the_issue_s_overshoot():
    result = orientation_requirement(W_M, PositionSet.parse("grid:30"), LAT_RAD)
    scale, worst = holding_scale(W_M, result.gyrowheel, result.inputs, result.limits_rad)
    # the planes' limits all at once reach dwy = 0.01142 deg/h: 1/1.142 of them holds
    assert worst.max() == pytest.approx(W_M, rel=1e-12)
    assert scale == pytest.approx(W_M / result.box_dwy_dph, rel=1e-3)
    assert result.box.volume_rad3 > scale**3 * np.prod(result.limits_rad)


def test_the_paper_s_planes_are_reported_unchanged_beside_the_box():
    result = orientation_requirement(W_M, PositionSet.parse("grid:30"), LAT_RAD)
    np.testing.assert_allclose(
        np.degrees(result.limits_rad), [0.01019, 0.00443, 0.00768], atol=5e-6
    )
    assert (round(result.box_dwx_dph, 5), round(result.box_dwy_dph, 5)) == (0.01048, 0.01142)
    np.testing.assert_allclose(
        np.degrees(result.box.limits_rad), [0.01012, 0.00359, 0.00698], atol=5e-6
    )
    out = result.to_dict()
    assert out["I_theta_deg"] == pytest.approx(np.degrees(result.theta_rad))
    assert out["box"]["I_theta_deg"] == pytest.approx(np.degrees(result.box.theta_rad))


def test_requirement_prints_the_box_beside_the_planes(capsys):
    assert main(["requirement", "--positions", "grid:45"]) == 0
    text = capsys.readouterr().out
    assert "I_psi = 0.00855 deg" in text
    assert "the largest box that holds" in text
    assert "|dpsi| <= 0.00982 deg" in text
    assert main(["requirement", "--positions", "grid:45", "--json"]) == 0
    box = json.loads(capsys.readouterr().out)["box"]
    assert box["I_psi_deg"] == pytest.approx(0.00982, abs=5e-6)


def test_requirement_plots_draw_the_box(tmp_path, capsys):
    assert main(["requirement", "--positions", "grid:90", "--plots", str(tmp_path)]) == 0
    assert (tmp_path / "figure5_requirement.png").stat().st_size > 10_000


def test_largest_box_caps_an_angle_no_row_limits():
    rows = np.array([[[100.0, 0.0, 50.0], [20.0, 0.0, 80.0]]])
    limits, capped = largest_box(rows, W_M, cap_rad=0.1)
    assert list(capped) == [False, True, False]
    assert limits[1] == pytest.approx(0.1)


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), 2.0])
def test_bad_accuracy_is_refused(bad):
    with pytest.raises(InputError, match="accuracy"):
        orientation_requirement(bad, PositionSet.parse("grid:90"), LAT_RAD)

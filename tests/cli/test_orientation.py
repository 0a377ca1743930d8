"""The command line: JSON output and clear errors (exit 2, no traceback) on bad input."""

import json

import numpy as np
import pinocchio as pin
import pytest

from conftest import cli
from turntable_pin import TurntableErrors, TurntableModel
from turntable_pin.cli import main
from turntable_pin.core.units import ARCSEC_PER_RAD


def test_orientation_json_matches_the_library():
    proc = cli(
        "orientation", "--phi1-deg", "30", "--phi2-deg", "45",
        "--error", "dphi_y1=3", "--error", "deps_x=-2", "--error", "deta=0.2", "--json",
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    errors = TurntableErrors.from_arcsec(dphi_y1=3, deps_x=-2, deta_mm=0.2)
    expected = TurntableModel(errors).orientation_error(np.radians(30), np.radians(45))
    for key in ("dR", "dpsi_arcsec", "dtheta_arcsec", "dgamma_arcsec", "payload_origin_mm"):
        assert key in out
    np.testing.assert_allclose(out["dR"], expected.dR, atol=1e-15)
    assert out["dpsi_arcsec"] == pytest.approx(expected.dpsi_rad * ARCSEC_PER_RAD, abs=1e-9)
    # small-angle value of eq. 26: 3 cos45 - (-2) sin45 ... = (3 + 2)*0.7071 for dpsi
    assert out["dpsi_small_angle_arcsec"] == pytest.approx(5 * np.sqrt(0.5), rel=1e-12)
    assert out["dtheta_small_angle_arcsec"] == 0.0
    # deta = 0.2 mm along x of the outer frame, turned by phi1 + dphi_y1 about y
    turn = np.radians(30) + 3 / ARCSEC_PER_RAD
    np.testing.assert_allclose(
        out["payload_origin_mm"], [0.2 * np.cos(turn), 0, -0.2 * np.sin(turn)], atol=1e-15
    )


def test_urdf_command_writes_a_model_pinocchio_reads(tmp_path):
    out = tmp_path / "t.urdf"
    assert main(["urdf", "--error", "dalpha_x2=5", "--error", "deps_y=-7", "-o", str(out)]) == 0
    model = pin.buildModelFromUrdf(str(out))
    data = model.createData()
    q = np.array([0.4, 1.1])
    pin.framesForwardKinematics(model, data, q)
    errors = TurntableErrors.from_arcsec(dalpha_x2=5, deps_y=-7)
    expected = TurntableModel(errors).payload_pose(*q)
    np.testing.assert_allclose(
        data.oMf[model.getFrameId("gyrowheel")].rotation, expected.rotation, atol=1e-12
    )


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["orientation", "--error", "dphi_w7=3"], "unknown error name 'dphi_w7'"),
        (["orientation", "--error", "dphi_y1=three"], "expected a number"),
        (["orientation", "--error", "dphi_y1"], "expected NAME=VALUE"),
        (["orientation", "--phi1-deg", "nan"], "--phi1-deg: expected a finite number"),
        (["orientation", "--phi2-deg", "inf"], "--phi2-deg: expected a finite number"),
        (["orientation", "--errors", "/does/not/exist.yaml"], "cannot read the file"),
    ],
)
def test_bad_input_exits_2_with_a_message(args, fragment):
    proc = cli(*args)
    assert proc.returncode == 2
    assert fragment in proc.stderr
    assert "Traceback" not in proc.stderr


def test_unreadable_yaml(tmp_path):
    bad = tmp_path / "errors.yaml"
    bad.write_text("errors: {dphi_y1: [1,\n")
    proc = cli("orientation", "--errors", str(bad))
    assert proc.returncode == 2
    assert "errors.yaml" in proc.stderr and "YAML" in proc.stderr
    assert "Traceback" not in proc.stderr

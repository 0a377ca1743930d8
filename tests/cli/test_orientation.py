"""``orientation`` and ``urdf``: JSON output against the library and plain Pinocchio on the paper's
table and on the bundled one-, two- and three-axis tables (their generic error names), and clear
errors (one line, exit 2, no traceback) on bad input."""

import json

import numpy as np
import pinocchio as pin
import pytest

from conftest import REPO_DIR, cli
from turntable_pin import TurntableErrors
from turntable_pin.cli import main
from turntable_pin.core.units import ARCSEC_PER_RAD, arcsec_to_rad
from turntable_pin.model.generic_table import GenericTable
from turntable_pin.model.paper_table import paper_table


def test_orientation_json_matches_the_library():
    proc = cli(
        "orientation", "--phi1-deg", "30", "--phi2-deg", "45",
        "--error", "dphi_y1=3", "--error", "deps_x=-2", "--error", "deta=0.2", "--json",
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    errors = TurntableErrors.from_arcsec(dphi_y1=3, deps_x=-2, deta_mm=0.2)
    expected = paper_table().orientation_error(errors.as_array(), np.radians([30, 45]))
    for key in ("dR", "dpsi_arcsec", "dtheta_arcsec", "dgamma_arcsec", "payload_origin_mm"):
        assert key in out
    np.testing.assert_allclose(out["dR"], expected.dR, atol=1e-15)
    assert out["dpsi_arcsec"] == pytest.approx(expected.dpsi_rad * ARCSEC_PER_RAD, abs=1e-9)
    # small-angle value of eq. 26: 3 cos45 - (-2) sin45 ... = (3 + 2)*0.7071 for dpsi
    assert out["dpsi_first_order_arcsec"] == pytest.approx(5 * np.sqrt(0.5), rel=1e-12)
    assert out["dtheta_first_order_arcsec"] == 0.0  # eq. 26's closed form: an exact zero
    assert out["angles_deg"] == {"phi1": 30.0, "phi2": 45.0}
    assert out["urdf"].endswith("turntable.urdf") and out["payload_frame"] == "gyrowheel"
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
    expected = paper_table().payload_pose(errors.as_array(), q)
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


# ---- any table --------------------------------------------------------------------------------
MODELS = REPO_DIR / "models"
CASES = [
    ("single_axis_rate_table.urdf", "90", ["spindle.tilt_b=60", "gyro_mount.rot_z=5"]),
    ("two_axis_vertical_outer.urdf", "30,-20", ["azimuth_axis.tilt_a=4", "tilt_axis.position=-3"]),
    ("three_axis_imu_table.urdf", "10,20,30",
     ["outer_gimbal.tilt_a=5", "inner_gimbal.tilt_b=-2", "middle_gimbal.offset_a_mm=0.2"]),
]  # fmt: skip


@pytest.mark.parametrize("urdf, angles, errors", CASES)
def test_orientation_of_each_bundled_table(urdf, angles, errors):
    argv = ["orientation", "--urdf", str(MODELS / urdf), "--angles-deg", angles, "--json"]
    for e in errors:
        argv += ["--error", e]
    proc = cli(*argv)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    table = GenericTable(MODELS / urdf)
    values = table.values()
    for e in errors:
        name, value = e.split("=")
        if name.endswith("_mm"):
            values[table.parameter_names.index(name[:-3])] = float(value) * 1e-3
        else:
            values[table.parameter_names.index(name)] = arcsec_to_rad(float(value))
    angles_rad = np.radians([float(a) for a in angles.split(",")])
    np.testing.assert_allclose(out["dR"], table.rotation_error(values, angles_rad), atol=1e-15)
    for name in ("dpsi", "dtheta", "dgamma"):  # first order is exact to second order
        assert abs(out[f"{name}_arcsec"] - out[f"{name}_first_order_arcsec"]) < 1e-3
    assert list(out["angles_deg"]) == list(table.joint_names)


def test_urdf_of_a_generic_table_reproduces_it_in_plain_pinocchio(tmp_path):
    urdf = MODELS / "three_axis_imu_table.urdf"
    out = tmp_path / "with_errors.urdf"
    proc = cli("urdf", "--urdf", str(urdf), "--error", "outer_gimbal.tilt_a=30",
               "--error", "imu_mount.rot_y_arcmin=1", "-o", str(out))  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    table = GenericTable(urdf)
    values = table.errors_from_user_units({"outer_gimbal.tilt_a": 30, "imu_mount.rot_y_arcmin": 1})
    plain, nominal = pin.buildModelFromUrdf(str(out)), table.nominal_pin_model
    angles = np.radians([40.0, -10.0, 75.0])
    q = table.chain.joint_vector(*angles)
    rotations = []
    for m in (plain, nominal):
        data = m.createData()
        pin.framesForwardKinematics(m, data, q)
        rotations.append(data.oMf[m.getFrameId("imu")].rotation)
    np.testing.assert_allclose(
        rotations[1].T @ rotations[0], table.rotation_error(values, angles), atol=1e-12
    )


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["--angles-deg", "1,2"], "this table has 3 joint(s), got 2 angle(s)"),
        (["--phi1-deg", "3"], "give --angles-deg"),
        (["--angles-deg", "1,x,3"], "--angles-deg '1,x,3'"),
        (["--error", "dphi_y1=3", "--angles-deg", "1,2,3"], "unknown error name 'dphi_y1'"),
        (["--payload-frame", "nowhere", "--angles-deg", "1,2,3"], "no frame 'nowhere'"),
    ],
)
def test_bad_use_on_a_generic_table_is_one_line_exit_2(argv, fragment):
    proc = cli("orientation", "--urdf", str(MODELS / "three_axis_imu_table.urdf"), *argv)
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and fragment in proc.stderr


def test_a_mimic_joint_is_refused_in_one_line(tmp_path):
    text = (MODELS / "two_axis_vertical_outer.urdf").read_text()
    bad = tmp_path / "mimic.urdf"
    joint = '<joint name="tilt_axis" type="revolute">'
    bad.write_text(text.replace(joint, joint + '<mimic joint="azimuth_axis"/>'))
    proc = cli("orientation", "--urdf", str(bad), "--angles-deg", "1,2")
    assert proc.returncode == 2 and "mimic joint" in proc.stderr


def test_the_paper_table_keeps_its_names_with_angles_deg():
    a = json.loads(cli("orientation", "--angles-deg", "30,45", "--error", "dphi_y1=3",
                       "--json").stdout)  # fmt: skip
    b = json.loads(cli("orientation", "--phi1-deg", "30", "--phi2-deg", "45", "--error",
                       "dphi_y1=3", "--json").stdout)  # fmt: skip
    assert a == b and "dpsi_first_order_arcsec" in a
    # one schema: the paper's table and a URDF table give the same keys
    c = json.loads(cli("orientation", "--urdf", "altaz_mount", "--angles-deg", "30,45",
                       "--json").stdout)  # fmt: skip
    assert set(a) == set(c)

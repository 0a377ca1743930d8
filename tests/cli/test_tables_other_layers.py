"""``rate-error``, ``requirement``, ``calibrate``, ``allocate``, ``montecarlo``, ``view`` and
``snapshot`` on any table (``--urdf``): the bundled tables against the library, the paper's URDF
given explicitly equal to the default, and every bad URDF one line with exit status 2."""

import json

import numpy as np
import pytest

from conftest import EXAMPLES_DIR, REPO_DIR, cli, needs_chromium, write_file
from turntable_pin.allocation.solver import (
    OrientationLimits,
    allocate_tolerances,
)
from turntable_pin.calibration.drift_fit import simulate_run
from turntable_pin.calibration.gyrowheel import GyroWheelModel
from turntable_pin.calibration.positions import PositionSet, position_inputs
from turntable_pin.calibration.rate_error import rate_error
from turntable_pin.core.csv_table import write_csv_table
from turntable_pin.model.generic_table import GenericTable

MODELS = REPO_DIR / "models"
THREE = str(MODELS / "three_axis_imu_table.urdf")
TWO = str(MODELS / "two_axis_vertical_outer.urdf")
ONE = str(MODELS / "single_axis_rate_table.urdf")
PAPER = str(MODELS / "turntable.urdf")
LIMITS = "psi=0.6,theta=0.25,gamma=0.45"


def _json(*argv):
    proc = cli(*argv, "--json")
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


def _one_line_exit_2(proc, fragment):
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    fragments = (fragment,) if isinstance(fragment, str) else fragment
    assert any(f in proc.stderr for f in fragments) and "Traceback" not in proc.stderr


def test_rate_error_of_the_three_axis_table_equals_the_library():
    out = _json("rate-error", "--urdf", THREE, "--positions", "grid:90x45x45",
                "--dpsi-deg", "0.01", "--dgamma-deg", "-0.02", "--latitude-deg", "40")  # fmt: skip
    table = GenericTable(THREE)
    inputs = position_inputs(PositionSet.parse("grid:90x45x45", table), np.radians(40.0))
    expected = rate_error(
        GyroWheelModel.nominal(), inputs, np.radians(0.01), 0.0, np.radians(-0.02)
    )
    assert out["dwx_dph"] == pytest.approx(expected.dwx_dph, rel=1e-12)
    assert out["dwy_dph"] == pytest.approx(expected.dwy_dph, rel=1e-12)
    assert out["joints"] == list(table.joint_names) and out["n_positions"] == 256


def test_requirement_of_the_three_axis_table_in_text():
    proc = cli("requirement", "--urdf", THREE, "--positions", "grid:90x45x45")
    assert proc.returncode == 0, proc.stderr
    assert "joints outer_gimbal, middle_gimbal, inner_gimbal" in proc.stdout
    assert "I_theta set by the" in proc.stdout


def test_calibrate_a_run_with_joint_named_columns(tmp_path):
    table = GenericTable(THREE)
    inputs = position_inputs(PositionSet.parse("grid:90x45x45", table), np.radians(45.75))
    truth = GyroWheelModel.nominal()
    columns = simulate_run(truth, inputs, noise_dph=0.0, seed=0)
    named = {
        (f"{table.joint_names[int(k[3]) - 1]}_deg" if k.startswith("phi") else k): v
        for k, v in columns.items()
    }
    run = write_csv_table(tmp_path / "run.csv", named)
    out = _json("calibrate", str(run), "--urdf", THREE)
    fitted = [out["x"]["coefficients_dph"][n] for n in ("DF", "x", "y", "z", "xx", "zz", "xy")]
    np.testing.assert_allclose(fitted, truth.x.as_array(), atol=1e-9)
    assert "outer_gimbal_deg" in out["residuals"][0] and out["urdf"] == THREE


@pytest.mark.parametrize("command", ["rate-error", "requirement", "calibrate"])
@pytest.mark.parametrize(
    "urdf, fragment", [(ONE, "too few distinct gravity directions"), (TWO, "cannot determine")]
)
def test_tables_that_cannot_calibrate_the_gyrowheel_exit_2(command, urdf, fragment, tmp_path):
    if command == "calibrate":
        rows = [(a, b) for a in range(0, 360, 30) for b in (0, 45, 90)]
        if urdf == ONE:  # one joint: one angle column (a phi2_deg would be refused)
            header, rows = "phi1_deg", sorted({(a,) for a, _ in rows})
        else:
            header = "phi1_deg,phi2_deg"
        text = "".join(",".join(map(str, (*row, 1, 2))) + "\n" for row in rows)
        run = write_file(tmp_path, f"{header},out_x_dph,out_y_dph\n" + text, "run.csv")
        proc = cli("calibrate", str(run), "--urdf", urdf)
        fragment = ("too few distinct", "cannot determine")
    else:
        proc = cli(command, "--urdf", urdf)
    _one_line_exit_2(proc, fragment)


@pytest.mark.parametrize("urdf", [ONE, TWO, THREE])
def test_allocate_names_the_tables_errors_and_meets_the_limits(urdf):
    out = _json("allocate", "--urdf", urdf, "--limits-arcmin", LIMITS, "--grid-step-deg", "30")
    table = GenericTable(urdf)
    assert list(out["upper_bounds_arcmin"]) == list(table.angular_names)
    expected = allocate_tolerances(
        OrientationLimits.from_arcmin(0.6, 0.25, 0.45), table=table, grid_step_deg=30.0
    )
    np.testing.assert_allclose(
        list(out["upper_bounds_arcmin"].values()),
        expected.upper_bounds_rad * 60 * 180 / np.pi,
        rtol=1e-12,
    )
    for name, limit in out["limits_arcmin"].items():
        assert out["worst_case_arcmin"][name] <= limit * (1 + 1e-9)


def test_allocate_three_axis_with_the_default_limits_of_its_positions():
    proc = cli("allocate", "--urdf", THREE, "--positions", "grid:90x45x45", "--grid-step-deg", "45")
    assert proc.returncode == 0, proc.stderr
    assert "inner_gimbal.tilt_b" in proc.stdout and "Error allocation of three_axis" in proc.stdout


@pytest.mark.parametrize("urdf", [ONE, THREE])
def test_montecarlo_on_a_table_stays_within_the_limits(urdf):
    proc = cli("montecarlo", "--urdf", urdf, "--limits-arcmin", LIMITS, "-n", "300",
               "--seed", "4", "--grid-step-deg", "45")  # fmt: skip
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "all within the limits" in proc.stdout
    assert "Monte Carlo" in proc.stderr  # progress
    out = _json("montecarlo", "--urdf", urdf, "--limits-arcmin", LIMITS, "-n", "300",
                "--seed", "4", "--grid-step-deg", "45")  # fmt: skip
    assert out["seed"] == 4 and out["all_within"]
    assert list(out["upper_bounds_arcmin"]) == list(GenericTable(urdf).angular_names)


def test_montecarlo_scaled_beyond_the_bounds_exceeds_a_limit():
    proc = cli("montecarlo", "--urdf", TWO, "--limits-arcmin", LIMITS, "-n", "400",
               "--grid-step-deg", "30", "--scale-bounds", "3", "--quiet")  # fmt: skip
    assert proc.returncode == 1 and "EXCEEDED" in proc.stdout


def test_the_paper_urdf_given_explicitly_is_the_paper_path():
    a = _json("rate-error", "--dpsi-deg", "0.01", "--positions", "grid:45")
    b = _json("rate-error", "--dpsi-deg", "0.01", "--positions", "grid:45", "--urdf", PAPER)
    assert a == b and a["joints"] == ["outer_axis", "inner_axis"]
    c = _json("allocate", "--limits-arcmin", LIMITS)
    d = _json("allocate", "--limits-arcmin", LIMITS, "--urdf", PAPER)
    assert c == d and "dphi_y1" in c["upper_bounds_arcmin"]


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["allocate", "--urdf", TWO], "no default limits for this table"),
        (["allocate", "--urdf", THREE, "--limits-arcmin", "1", "--grid-step-deg", "1"],
         "coarser --grid-step-deg"),
        (["rate-error", "--urdf", THREE, "--positions", "grid:30x30"],
         "2 steps for three_axis_imu_table.urdf of 3 joints"),
        (["snapshot", "--urdf", THREE, "--angles-deg", "1,2", "-o", "x.png"],
         "this table has 3 joint(s)"),
        (["snapshot", "--urdf", THREE, "--phi1-deg", "1", "-o", "x.png"], "give --angles-deg"),
    ],
)  # fmt: skip
def test_bad_use_on_a_table_is_one_line_exit_2(argv, fragment):
    _one_line_exit_2(cli(*argv), fragment)


@pytest.mark.parametrize("urdf", [None, TWO])
def test_every_allocation_option_works_on_every_table(urdf, tmp_path):
    """--grid-step-deg, --weights paper and --plots, once refused off (or on) the paper's table,
    are one path: the same keys, the figures written, on the paper's table and a URDF's."""
    table = ["--urdf", urdf] if urdf else []
    common = [*table, "--limits-arcmin", LIMITS, "--grid-step-deg", "30", "--weights", "paper"]
    out = _json("allocate", *common, "--plots", str(tmp_path / "a"))
    assert out["grid_step_deg"] == 30.0 and out["weights"] == "paper"
    assert (tmp_path / "a" / "figure8_sensitivities.png").is_file()
    proc = cli("montecarlo", *common, "-n", "50", "--plots", str(tmp_path / "m"), "--json")
    assert proc.returncode in (0, 1), proc.stderr
    mc = json.loads(proc.stdout)
    assert mc["grid_step_deg"] == 30.0 and (tmp_path / "m" / "figure9_montecarlo.png").is_file()
    paper = _json("allocate", "--limits-arcmin", LIMITS)
    assert set(out) - {"plot"} == set(paper)


# --- bad URDFs: every command turns the model's refusal into one line, exit 2 -------------------
def _chain(joints: str, links: str = "") -> str:
    return (
        '<?xml version="1.0"?><robot name="bad"><link name="l0"/><link name="l1"/>'
        f'<link name="l2"/>{links}'
        '<joint name="a" type="continuous"><parent link="l0"/><child link="l1"/>'
        f'<axis xyz="0 0 1"/></joint>{joints}</robot>'
    )


LIMIT = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
BAD_URDFS = {
    "branch": (_chain('<joint name="b" type="continuous"><parent link="l0"/><child link="l2"/>'
                      '<axis xyz="1 0 0"/></joint>'), "payload frame is ambiguous"),
    "prismatic": (_chain('<joint name="b" type="prismatic"><parent link="l1"/>'
                         f'<child link="l2"/><axis xyz="0 0 1"/>{LIMIT}</joint>'), "is prismatic"),
    "floating": (_chain('<joint name="b" type="floating"><parent link="l1"/><child link="l2"/>'
                        "</joint>"), "is floating"),
    "mimic": (_chain('<joint name="b" type="revolute"><parent link="l1"/><child link="l2"/>'
                     f'<axis xyz="0 0 1"/><mimic joint="a"/>{LIMIT}</joint>'), "mimic joint"),
    "four_axes": (_chain("".join(
        f'<joint name="j{i}" type="continuous"><parent link="l{i}"/><child link="l{i + 1}"/>'
        '<axis xyz="0 0 1"/></joint>' for i in range(1, 4)),
        '<link name="l3"/><link name="l4"/>'), "4 revolute joints"),
    "not_xml": ("<robot><link name='a'>", "not a readable URDF"),
}  # fmt: skip
COMMANDS = {
    "rate-error": [],
    "requirement": [],
    "calibrate": ["RUN"],
    "allocate": ["--limits-arcmin", "1"],
    "montecarlo": ["--limits-arcmin", "1", "-n", "10"],
    "view": ["--duration", "0"],
    "snapshot": ["-o", "OUT"],
    # the measurement layer (its own tests are in test_measurement*.py)
    "simulate": ["-o", "OUT"],
    "fit": ["DATA"],
    "diagnose": ["DATA"],
    "report": ["DATA", "-o", "OUT"],
    "effects": [],
}


def _placeholder(arg: str, run, folder) -> str:
    """A command's argument with RUN/DATA (an input file) and OUT (an output path) filled in."""
    if arg == "RUN":
        return str(run)
    if arg == "DATA":
        return str(EXAMPLES_DIR / "measurements_example.csv")
    return str(folder / "out.png") if arg == "OUT" else arg


@pytest.mark.parametrize("command", sorted(COMMANDS))
@pytest.mark.parametrize("case", sorted(BAD_URDFS))
def test_a_bad_urdf_is_one_line_exit_2_in_every_command(command, case, tmp_path):
    text, fragment = BAD_URDFS[case]
    urdf = write_file(tmp_path, text, "bad.urdf")
    run = write_file(tmp_path, "phi1_deg,out_x_dph,out_y_dph\n0,1,2\n", "run.csv")
    extra = [_placeholder(a, run, tmp_path) for a in COMMANDS[command]]
    _one_line_exit_2(cli(command, *extra, "--urdf", str(urdf)), fragment)


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_a_missing_payload_frame_is_one_line_exit_2_in_every_command(command, tmp_path):
    run = write_file(tmp_path, "phi1_deg,out_x_dph,out_y_dph\n0,1,2\n", "run.csv")
    extra = [_placeholder(a, run, tmp_path) for a in COMMANDS[command]]
    proc = cli(command, *extra, "--urdf", THREE, "--payload-frame", "nowhere")
    _one_line_exit_2(proc, "no frame 'nowhere'")


def test_view_of_a_table_serves_and_stops():
    pytest.importorskip("meshcat")
    proc = cli("view", "--urdf", TWO, "--angles-deg", "10,20", "--duration", "0")
    assert proc.returncode == 0, proc.stderr
    assert "meshcat viewer: http" in proc.stdout and "tilt_axis" in proc.stdout


@pytest.mark.slow
@needs_chromium
def test_snapshot_of_the_single_axis_table(tmp_path):
    pytest.importorskip("meshcat")
    out = _json("snapshot", "--urdf", ONE, "--angles-deg", "30", "--error",
                "spindle.tilt_a=5", "-o", str(tmp_path / "one.png"))  # fmt: skip
    assert out["angles_deg"] == {"spindle": 30.0} and out["joints"] == ["spindle"]
    assert (tmp_path / "one.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

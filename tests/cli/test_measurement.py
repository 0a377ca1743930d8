"""The measurement commands: simulate -> fit / diagnose / report, JSON keys, bad files exit 2."""

import json
import re

import pytest

from conftest import EXAMPLES_DIR, REPO_DIR, cli, run_cli
from turntable_pin.cli import main
from turntable_pin.core.files import read_yaml

EXAMPLE = EXAMPLES_DIR / "measurements_example.csv"


@pytest.fixture(scope="module")
def sim_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("sim") / "gravity.csv"
    code = main([
        "simulate", "--error", "dphi_y1=4", "--error", "deps_x=-3", "--effect", "gravity_sag:k=3",
        "--seed", "21", "--order", "random", "-o", str(path),
    ])  # fmt: skip
    assert code == 0
    return path


def test_bundled_example_diagnosis_names_its_hidden_effect_and_the_error_falls():
    # The README's main job, run as `python -m turntable_pin` in a child process: the one test of
    # the module entry point end to end (the other commands are run in-process with `cli`).
    proc = run_cli("diagnose", str(EXAMPLE), "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    truth = read_yaml(EXAMPLES_DIR / "truth" / "measurements_example.yaml")
    assert [out["verdict"]["missing_effect"]] == list(truth["hidden_effects"])
    assert out["steps"][0]["rms_arcsec"] < 0.6 * out["base"]["rms_arcsec"]
    assert 0.8 < out["steps"][0]["chi2_reduced"] < 1.25 < out["base"]["chi2_reduced"]


def test_fit_json_keys_and_before_after(sim_file, capsys, tmp_path):
    assert main(["fit", str(sim_file), "--effects", "gravity_sag", "--json",
                 "--plots", str(tmp_path / "plots")]) == 0  # fmt: skip
    out = json.loads(capsys.readouterr().out)
    for key in ("rms_arcsec", "chi2_reduced", "params", "identifiable", "p_value", "before"):
        assert key in out
    assert out["params"]["gravity_sag.k"]["value"] == pytest.approx(3, abs=0.5)
    assert out["before"]["chi2_reduced"] > 1.5 > out["chi2_reduced"]
    assert out["identifiable"]["rank"] == 6
    table = out["where_it_fails"]["per_position"]
    assert len(table) == 144 and {"row", "phi1_deg", "dtheta_arcsec", "max_sigmas"} <= set(table[0])
    assert (tmp_path / "plots" / "residuals.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.slow
def test_diagnose_until_explained_text_and_report(sim_file, capsys, tmp_path):
    assert main(["diagnose", str(sim_file), "--until-explained"]) == 0
    text = capsys.readouterr().out
    assert "missing effect: gravity_sag" in text and "step 1: add gravity_sag" in text
    report = tmp_path / "r.html"
    assert main(["report", str(sim_file), "-o", str(report)]) == 0
    html = report.read_text()
    assert "data:image/png;base64," in html and "gravity_sag" in html
    assert 'src="http' not in html and "<script" not in html  # self-contained


def test_fit_with_estimated_sigma(sim_file, capsys):
    assert main(["fit", str(sim_file), "--effects", "gravity_sag", "--ignore-sigma", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["sigma_source"] == "estimated" and out["p_value"] is None
    assert out["chi2_reduced"] == pytest.approx(1.0)
    assert out["before"]["chi2_reduced"] > 1.5


BAD = {
    "missing": ("phi1_deg,phi2_deg,dpsi_arcsec,dtheta_arcsec\n0,0,1,1\n", "row 1"),
    "text": (
        "phi1_deg,phi2_deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec\n0,0,1,1,1\n0,30,1,oops,1\n",
        "row 3, column 'dtheta_arcsec'",
    ),
    "sigma": (
        "phi1_deg,phi2_deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec,sigma_arcsec\n0,0,1,1,1,0\n",
        "row 2, column 'sigma_arcsec'",
    ),
    "text among numbers": (  # issue 27: the column was dropped without a word
        "phi1_deg,phi2_deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec,temperature_c\n"
        "0,0,1,1,1,20.5\n0,30,1,1,1,warm\n0,60,1,1,1,21\n",
        "row 3, column 'temperature_c': 'warm' is not a number",
    ),
}


@pytest.mark.parametrize("kind", list(BAD))
def test_bad_files_exit_2_naming_row_and_column(kind, tmp_path, capsys):
    text, fragment = BAD[kind]
    path = tmp_path / "bad.csv"
    path.write_text(text)
    proc = cli("diagnose", str(path), "--json")
    assert proc.returncode == 2
    assert fragment in proc.stderr and "bad.csv" in proc.stderr
    assert "Traceback" not in proc.stderr and proc.stdout == ""
    assert main(["fit", str(path)]) == 2
    err = capsys.readouterr()
    assert fragment in err.err and err.out == ""
    out = tmp_path / "r.html"
    assert main(["report", str(path), "-o", str(out)]) == 2 and not out.exists()


def test_text_columns_are_warned_of_and_an_effect_on_one_is_told_it_is_text(tmp_path):
    lines = EXAMPLE.read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    lines[header] += ",temperature_c,note"
    lines[header + 1 :] = [line + ",n/a,ok" for line in lines[header + 1 :]]
    path = tmp_path / "noted.csv"
    path.write_text("\n".join(lines) + "\n")
    warning = f"diagnose: warning: {path}: column(s) temperature_c, note ignored: not numbers"
    proc = cli("diagnose", str(path), "--json")
    assert proc.returncode == 0 and warning in proc.stderr
    proc = cli("fit", str(path), "--effects", "dpsi~poly1(temperature_c)")
    assert proc.returncode == 2 and "absent" not in proc.stderr
    assert "temperature_c, present in the data but not numbers" in proc.stderr


def test_report_never_overwrites_its_input(sim_file, capsys):
    before = sim_file.read_bytes()
    assert main(["report", str(sim_file), "-o", str(sim_file)]) == 2
    assert "refusing to write --output" in capsys.readouterr().err
    assert sim_file.read_bytes() == before


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["simulate", "--effect", "gravity:k=1", "-o", "x.csv"], "unknown effect 'gravity'"),
        (["simulate", "--effect", "gravity_sag:k", "-o", "x.csv"], "expected NAME:P=V"),
        (["simulate", "--effect", "gravity_sag:k=nan", "-o", "x.csv"], "finite"),
        (["fit", "nofile.csv"], "cannot read the file"),
    ],
)
def test_bad_arguments(args, fragment, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(args) == 2
    assert fragment in capsys.readouterr().err
    assert not (tmp_path / "x.csv").exists()


def test_unknown_effect_in_fit(sim_file, capsys):
    assert main(["fit", str(sim_file), "--effects", "gravity_sag,wobble"]) == 2
    assert "unknown effect 'wobble'" in capsys.readouterr().err


def test_the_measurement_loop_on_a_three_axis_table(tmp_path):
    urdf = str(REPO_DIR / "models" / "three_axis_imu_table.urdf")
    data = tmp_path / "imu.csv"
    proc = cli("simulate", "--urdf", urdf, "--phi1-step-deg", "90", "--phi2-step-deg", "60",
               "--phi3-step-deg", "60", "--effect", "encoder_harmonics@inner_gimbal:c1=4,s2=3",
               "--error", "middle_gimbal.tilt_a=8", "--seed", "2", "-o", str(data))  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    header = [ln for ln in data.read_text().splitlines() if not ln.startswith("#")][0]
    assert header.startswith("phi1_deg,phi2_deg,phi3_deg,") and header.endswith("dir1,dir2,dir3")
    proc = cli("diagnose", str(data), "--urdf", urdf, "--json")
    assert proc.returncode == 0, proc.stderr
    verdict = json.loads(proc.stdout)["verdict"]
    assert verdict["missing_effect"] == "encoder_harmonics@inner_gimbal"
    out = tmp_path / "identified.urdf"
    proc = cli("fit", str(data), "--urdf", urdf, "--effects", "encoder_harmonics@inner_gimbal",
               "--write-urdf", str(out), "--json")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    fit = json.loads(proc.stdout)
    assert fit["chi2_reduced"] < 1.3 and fit["identified_urdf"]["path"] == str(out)
    assert abs(fit["identified_urdf"]["errors_arcsec"]["middle_gimbal.tilt_a"] - 8) < 1
    # The paper's names are no names of this table.
    proc = cli("fit", str(data), "--urdf", urdf, "--effects", "inner_encoder_harmonics")
    assert proc.returncode == 2 and "unknown effect 'inner_encoder_harmonics'" in proc.stderr


# --- simulate: the designs engineers run ---------------------------------------------------------


def _rows(path):
    lines = [ln for ln in path.read_text().splitlines() if not ln.startswith("#")]
    header = lines[0].split(",")
    return [dict(zip(header, ln.split(","), strict=True)) for ln in lines[1:]]


def test_simulate_positions_file_in_its_order(tmp_path):
    positions = tmp_path / "positions.csv"
    positions.write_text(
        "# my plan\nphi2_deg,phi1_deg,dir1,note\n45,90,-1,a\n0,0,1,b\n10,180,1,c\n"
    )
    out = tmp_path / "out.csv"
    proc = cli("simulate", "--positions", str(positions), "--seed", "2", "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    rows = _rows(out)
    assert [(r["phi1_deg"], r["phi2_deg"], r["dir1"]) for r in rows] == [
        ("90.0", "45.0", "-1"), ("0.0", "0.0", "1"), ("180.0", "10.0", "1"),
    ]  # fmt: skip
    assert "# schedule: positions=positions.csv n_positions=3 given=dir1 repeats=1" in (
        out.read_text()
    )
    back = cli("diagnose", str(out), "--json")
    assert back.returncode == 0, back.stderr


def test_simulate_positions_file_of_a_three_axis_table_by_joint_name(tmp_path):
    urdf = str(REPO_DIR / "models" / "three_axis_imu_table.urdf")
    from turntable_pin.model.generic_table import GenericTable

    names = GenericTable(urdf).joint_names
    positions = tmp_path / "positions.csv"
    positions.write_text(f"{names[0]}_deg,phi2_deg,phi3_deg,time_s\n0,0,0,5\n90,10,20,50\n")
    out = tmp_path / "out.csv"
    assert cli("simulate", "--urdf", urdf, "--positions", str(positions), "-o",
               str(out)).returncode == 0  # fmt: skip
    rows = _rows(out)
    assert [(r["phi1_deg"], r["phi3_deg"], r["time_s"]) for r in rows] == [
        ("0.0", "0.0", "5.0"), ("90.0", "20.0", "50.0"),
    ]  # fmt: skip


def test_simulate_sweep_then_reverse_sweep_is_one_command(tmp_path):
    out = tmp_path / "sweep.csv"
    proc = cli("simulate", "--sweep", "phi1,phi2", "--phi1-step-deg", "90", "--phi2-step-deg",
               "90", "--phi2-start-deg", "90", "--approach", "motion", "-o", str(out))  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    pairs = [(float(r["phi1_deg"]), float(r["phi2_deg"])) for r in _rows(out)]
    assert pairs == [(0, 90), (90, 90), (180, 90), (270, 90), (0, 90), (0, 180), (0, 270), (0, 360)]
    text = out.read_text()
    assert "# schedule: sweep=phi1,phi2 phi1_step_deg=90 phi2_step_deg=90 held at " \
        "phi1_start_deg=0 phi2_start_deg=90" in text  # fmt: skip


def test_simulate_passes_random_positions_and_uneven_noise(tmp_path):
    out = tmp_path / "passes.csv"
    assert cli("simulate", "--passes", "2", "--phi1-step-deg", "180", "--phi2-step-deg", "180",
               "-o", str(out)).returncode == 0  # fmt: skip
    rows = _rows(out)
    assert [r["dir1"] for r in rows] == (["1"] * 4 + ["-1"] * 4) * 2
    assert [r["dir2"] for r in rows] == [r["dir1"] for r in rows]
    assert "approach=motion passes=2" in out.read_text()
    rnd = tmp_path / "random.csv"
    args = ("simulate", "--random-positions", "30", "--noise-spread", "3", "--seed", "7")
    assert cli(*args, "-o", str(rnd)).returncode == 0
    again = tmp_path / "again.csv"
    assert cli(*args, "-o", str(again)).returncode == 0
    assert rnd.read_text() == again.read_text()
    text = rnd.read_text()
    assert "# seed=7" in text and "noise_spread=3" in text and "random_positions=30" in text
    sigma = [float(r["sigma_arcsec"]) for r in _rows(rnd)]
    assert 1 / 3 <= min(sigma) < max(sigma) <= 3
    per_angle = tmp_path / "per_angle.csv"
    assert cli("simulate", "--noise-arcsec", "0.5,2,1", "--no-sigma", "-o",
               str(per_angle)).returncode == 0  # fmt: skip
    assert "sigma" not in _rows(per_angle)[0]


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (("--sweep", "phi1", "--random-positions", "5"), "not allowed with argument"),
        (("--sweep", "phi3"), "--sweep 'phi3': unknown axis 'phi3'"),
        (("--sweep", "phi1,phi1"), "swept twice"),
        (("--random-positions", "5", "--order", "random"), "--order random shuffles a grid"),
        (("--random-positions", "0"), "--random-positions"),
        (("--passes", "0"), "--passes"),
        (("--noise-arcsec", "1,2"), "one value or three"),
        (("--noise-spread", "0.5"), "--noise-spread"),
        (("--noise-arcsec", "1000", "--noise-spread", "3"), "--noise-spread 3: with --noise"),
        (("--random-positions", "600000", "--passes", "1"), "1,200,000 rows"),
        (("--phi2-start-deg", "4000"), "--phi2-start-deg"),
    ],
)
def test_simulate_bad_design_options_exit_2(args, fragment, tmp_path):
    proc = cli("simulate", *args, "-o", str(tmp_path / "x.csv"))
    assert proc.returncode == 2
    assert fragment in proc.stderr and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert not (tmp_path / "x.csv").exists()


@pytest.mark.parametrize(
    ("text", "extra", "fragment"),
    [
        ("phi1_deg,phi2_deg,dir1\n0,0,1\n90,45,2\n", (), "row 3, column 'dir1'"),
        ("phi1_deg,phi2_deg\n0,0\n90,4000\n", (), "row 3, column 'phi2_deg'"),
        ("phi1_deg\n0\n", (), "missing required column 'phi2_deg'"),
        ("phi1_deg,phi2_deg,time_s\n0,0,-5\n", (), "row 2, column 'time_s'"),
        ("phi1_deg,phi2_deg,time_s\n0,0,5\n0,0,5\n", (), "listed twice"),
        ("phi1_deg,phi2_deg,time_s\n0,0,5\n", ("--repeats", "2"), "--repeats: "),
        ("phi1_deg,phi2_deg,dir2\n0,0,1\n", ("--passes", "1"), "--passes: "),
    ],
)
def test_simulate_bad_positions_file_exit_2_naming_row_and_column(text, extra, fragment, tmp_path):
    positions = tmp_path / "positions.csv"
    positions.write_text(text)
    proc = cli("simulate", "--positions", str(positions), *extra, "-o", str(tmp_path / "x.csv"))
    assert proc.returncode == 2 and fragment in proc.stderr, proc.stderr
    assert "positions.csv" in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "x.csv").exists()
    assert positions.read_text() == text


def test_simulate_sweep_by_joint_name_on_another_table(tmp_path):
    urdf = str(REPO_DIR / "models" / "two_axis_vertical_outer.urdf")
    out = tmp_path / "sweep.csv"
    proc = cli("simulate", "--urdf", urdf, "--sweep", "tilt_axis,azimuth_axis", "--phi1-step-deg",
               "120", "--phi2-step-deg", "180", "-o", str(out))  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    pairs = [(float(r["phi1_deg"]), float(r["phi2_deg"])) for r in _rows(out)]
    assert pairs == [(0, 0), (0, 180), (0, 0), (120, 0), (240, 0)]
    assert "sweep=phi2,phi1" in out.read_text()
    bad = cli("simulate", "--urdf", urdf, "--sweep", "elevation", "-o", str(tmp_path / "x.csv"))
    assert bad.returncode == 2 and "phi1, phi2, azimuth_axis, tilt_axis" in bad.stderr


# --- a table is a telescope mount only when it says so (--mount, or the URDF's declaration) -------

ZY_TURNTABLE = REPO_DIR / "tests" / "zy_turntable.urdf"
"""A turntable whose outer axis turns about z and inner about -y (an alt-az mount's axes),
declaring nothing."""
NOT_OBSERVED = ("not observed", "roll about the boresight")


@pytest.fixture(scope="module")
def zy_run(tmp_path_factory):
    """The z/-y turntable measured at 144 positions, all three angles."""
    path = tmp_path_factory.mktemp("zy") / "zy_run.csv"
    made = cli("simulate", "--urdf", str(ZY_TURNTABLE), "--error", "swivel.position=20",
               "--error", "nod.tilt_a=5", "--error", "platen_mount.rot_x=8", "--seed", "3",
               "-o", str(path))  # fmt: skip
    assert made.returncode == 0, made.stderr
    rows = _rows(path)
    assert len(rows) == 144 and all(r["dgamma_arcsec"] for r in rows)
    return path


def _declared_copy(folder, kind: str = "altaz"):
    robot = '<robot name="zy_turntable">'
    text = ZY_TURNTABLE.read_text().replace(robot, f'{robot}\n  <turntable_pin mount="{kind}"/>')
    path = folder / "zy_declared.urdf"
    path.write_text(text)
    return path


def test_a_turntable_with_a_mount_s_axes_gets_no_tpoint_terms(zy_run):
    urdf = str(ZY_TURNTABLE)
    diagnosis = cli("diagnose", str(zy_run), "--urdf", urdf, "--json")
    assert diagnosis.returncode == 0, diagnosis.stderr
    candidates = {c["effect"] for c in json.loads(diagnosis.stdout)["candidates"]}
    assert candidates and not candidates & {"TF", "TX", "FO", "DAF"}
    text = cli("diagnose", str(zy_run), "--urdf", urdf).stdout
    assert "TX" not in text and "TF" not in text and "TPOINT" not in text
    fit = cli("fit", str(zy_run), "--urdf", urdf, "--json")
    assert fit.returncode == 0 and "pointing_terms" not in json.loads(fit.stdout)
    text = cli("fit", str(zy_run), "--urdf", urdf).stdout
    assert "TPOINT" not in text and not any(claim in text for claim in NOT_OBSERVED), text
    listing = cli("effects", "--urdf", urdf).stdout
    assert "TPOINT" not in listing and "\nTF:" not in listing


@pytest.mark.parametrize("declared_by", ["option", "urdf"])
def test_the_same_table_declared_alt_az_gets_them(zy_run, tmp_path, declared_by):
    urdf = ["--urdf", str(ZY_TURNTABLE), "--mount", "altaz"]
    if declared_by == "urdf":
        urdf = ["--urdf", str(_declared_copy(tmp_path))]
    diagnosis = json.loads(cli("diagnose", str(zy_run), *urdf, "--json").stdout)
    candidates = {c["effect"]: c for c in diagnosis["candidates"]}
    assert candidates["TF"]["testable"]
    assert "infinite at phi2 0 deg" in candidates["TX"]["reason"]  # the grid holds E = 0
    text = cli("fit", str(zy_run), *urdf).stdout
    assert "TPOINT terms (altaz mount;" in text and re.search(r"^  IA +-20\.\d+ \+- ", text, re.M)
    # dgamma was measured at every position: nothing says it was not
    assert not any(claim in text for claim in NOT_OBSERVED), text
    terms = json.loads(cli("fit", str(zy_run), *urdf, "--json").stdout)["pointing_terms"]
    assert "dgamma" not in terms["note"]
    # ... and --mount none makes the declared table a turntable again
    undeclared = cli("fit", str(zy_run), *urdf, "--mount", "none").stdout
    assert "TPOINT" not in undeclared


def test_a_declared_mount_that_is_not_one_is_refused_naming_the_urdf(zy_run, tmp_path):
    vertical = REPO_DIR / "models" / "two_axis_vertical_outer.urdf"
    for args in (["--urdf", str(vertical), "--mount", "altaz"],
                 ["--urdf", str(_declared_copy(tmp_path, "equatorial"))]):  # fmt: skip
        for command in ("fit", "diagnose"):
            proc = cli(command, str(zy_run), *args)
            assert proc.returncode == 2, proc.stdout
            assert args[1] in proc.stderr and "mount, but its payload orientation" in proc.stderr
            assert len(proc.stderr.strip().splitlines()) == 1
    bad = cli("fit", str(zy_run), "--urdf", str(ZY_TURNTABLE), "--mount", "alt-az")
    assert bad.returncode == 2 and "--mount" in bad.stderr

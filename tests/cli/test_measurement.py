"""The measurement commands: simulate -> fit / diagnose / report, JSON keys, bad files exit 2."""

import json

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

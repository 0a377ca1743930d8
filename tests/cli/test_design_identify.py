"""``turntable-pin design`` (identify): text, JSON, the positions' CSV that ``simulate
--positions`` reads, the figures, and bad input in one line with exit status 2."""

import json

import numpy as np
import pytest

from conftest import EXAMPLES_DIR, cli
from turntable_pin.measurement.data import read_measurements

DATA = EXAMPLES_DIR / "measurements_example.csv"


def test_identify_prints_the_design_and_its_standard_errors():
    proc = cli("design", "-n", "12", "--candidates", "500", "--effects", "inner_encoder_harmonics")
    assert proc.returncode == 0, proc.stderr
    text = proc.stdout
    assert text.startswith("design (identify, D-optimal): 12 positions of 644 candidates (seed 0)")
    assert "D-efficiency against the 144-position 30-degree grid" in text
    assert "inner_encoder_harmonics.c1" in text
    assert "not determined by any position within the limits: dphi_y1 - deps_y" in text


def test_the_json_records_the_seed_and_every_combination():
    proc = cli("design", "--urdf", "altaz_mount", "--limits-deg", "elevation=20:80", "-n", "10",
               "--candidates", "400", "--seed", "7", "--json")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["mode"] == "identify" and out["space"]["seed"] == 7
    assert out["space"]["limits"][1] == {"joint": "elevation", "angle": "phi2", "low_deg": 20.0,
                                         "high_deg": 80.0, "full_turn": False,
                                         "source": "--limits-deg"}  # fmt: skip
    assert len(out["positions_deg"]) == 10 and out["rank"] == len(out["combinations"])
    assert all(20.0 <= p[1] <= 80.0 for p in out["positions_deg"])
    assert {"name", "unit", "std", "std_grid", "std_grid_same_n"} <= set(out["combinations"][0])


def test_the_positions_file_round_trips_through_simulate_and_fit(tmp_path):
    positions = tmp_path / "next.csv"
    proc = cli("design", "--urdf", "altaz_mount", "--effects", "thermal_drift,backlash@azimuth",
               "-n", "8", "--candidates", "300", "--seed", "3", "--dwell-s", "20",
               "--noise-arcsec", "0.5", "-o", str(positions), "--json")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    text = positions.read_text()
    assert "# designed by turntable-pin design (identify: D-optimal)" in text
    assert "seed=3" in text
    assert "phi1_deg,phi2_deg,time_s,dir1,dir2" in text
    simulated = tmp_path / "sim.csv"
    proc = cli("simulate", "--urdf", "altaz_mount", "--positions", str(positions), "--effect",
               "thermal_drift:rz=5", "--noise-arcsec", "0.5", "-o", str(simulated))  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    data = read_measurements(simulated, ("azimuth", "elevation"))
    plan = np.array(out["plan"]["rows"])
    assert data.n_positions == 16  # each position early and late
    assert np.allclose(np.degrees(data.joint_rad), plan[:, :2])
    assert np.array_equal(data.time_s, plan[:, 2])
    assert np.array_equal(data.dirs[0], plan[:, 3]) and np.array_equal(data.dirs[1], plan[:, 4])
    proc = cli("fit", str(simulated), "--urdf", "altaz_mount", "--effects",
               "thermal_drift,backlash@azimuth", "--json")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    fitted = {c["name"]: c["std"] for c in json.loads(proc.stdout)["identifiable"]["combinations"]}
    for c in out["combinations"]:
        assert fitted[c["name"]] == pytest.approx(c["std"], rel=0.01)


def test_plots_and_measured_positions(tmp_path):
    proc = cli("design", "--from", str(DATA), "-n", "6", "--candidates", "300",
               "--plots", str(tmp_path / "figures"))  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "after the 144 positions measured" in proc.stdout
    for name in ("design_positions.png", "design_standard_errors.png"):
        png = tmp_path / "figures" / name
        assert png.read_bytes().startswith(b"\x89PNG")
        assert f"wrote {png}" in proc.stdout


@pytest.mark.parametrize(
    "argv, reason",
    [
        (["--urdf", "altaz_mount", "--limits-deg", "elevation=100:120"], "leaves no position"),
        (["--limits-deg", "phi2=90:10"], "leaves no position"),
        (["--limits-deg", "tilt=0:10"], "unknown joint 'tilt'"),
        (["-n", "1"], "1 position gives 3 measured angles, not more than the 5 combinations"),
        (["--urdf", "single_axis_rate_table", "--effects", "encoder_harmonics@spindle", "-n", "4"],
         "cannot determine all 9 combinations; the fewest that do: 5"),
        (["--urdf", "altaz_mount", "--limits-deg", "elevation=45:45", "--effects",
          "encoder_harmonics@elevation"], "no position can see it"),
        (["--effects", "no_such_effect"], "unknown effect 'no_such_effect'"),
        (["--from", "no_such_file.csv"], "no_such_file.csv"),
    ],
)  # fmt: skip
def test_bad_input_is_one_line_naming_the_reason(argv, reason):
    proc = cli("design", "--candidates", "300", *argv)
    assert proc.returncode == 2, proc.stdout
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("turntable-pin design: error:"), proc.stderr
    assert reason in lines[0]

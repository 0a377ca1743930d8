"""The command line's cases of "nothing lost, nothing runaway, nothing left behind": every bad
option value, absurd number and silently dropped input ends in one line naming the place and exit
status 2, never a traceback, never an input changed, no output written."""

import pytest

from conftest import EXAMPLES_DIR, cli, write_file

DATA = EXAMPLES_DIR / "measurements_example.csv"


def _refused(proc, line: str):
    """Assert a one-line refusal equal to (or, for a fragment, containing) ``line``."""
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert line in lines[0], lines[0]
    assert proc.stdout == ""


@pytest.mark.parametrize(
    "args, line",
    [
        (["montecarlo", "-n", "10", "--seed=-1"],
         "turntable-pin montecarlo: error: argument --seed: expected a whole number 0 <= seed < "
         "2**63, got '-1' (see turntable-pin montecarlo --help)"),
        (["montecarlo", "-n", "10", "--seed", "9223372036854775808"], "argument --seed"),
        (["montecarlo", "-n", "10", "--seed", "1.5"], "argument --seed"),
        (["simulate", "--seed=-1", "-o", "{tmp}/x.csv"],
         "turntable-pin simulate: error: argument --seed: expected a whole number 0 <= seed < "
         "2**63, got '-1'"),
        (["rate-error", "--dpsi-deg", "1e308"],
         "turntable-pin rate-error: error: argument --dpsi-deg: expected a number in [-5, 5] deg "
         "(a small orientation error), got '1e308'"),
        (["rate-error", "--latitude-deg", "1e308"],
         "argument --latitude-deg: latitude must be within +-90 degrees, got '1e308'"),
        (["requirement", "--accuracy-dph", "1e308"],
         "argument --accuracy-dph: expected an accuracy in [1e-06, 1] deg/h, got '1e308'"),
        (["allocate", "--limits-deg", "1e308"],
         "turntable-pin allocate: error: --limits-deg: orientation limit for psi is 1e+308 deg; "
         "it must be at most 5 deg (a small orientation error)"),
        (["allocate", "--limits-deg", "1e-9"],
         "turntable-pin allocate: error: --limits-deg 1e-9 with the lower bounds of "),
        (["allocate", "--accuracy-dph", "0"], "argument --accuracy-dph: expected a number > 0"),
        (["montecarlo", "--limits-arcmin", "1", "-n", "10", "--scale-bounds", "1e308"],
         "--scale-bounds 1e+308: the scaled bounds reach"),
        (["montecarlo", "--limits-arcmin", "1", "-n", "10", "--grid-step-deg", "0"],
         "argument --grid-step-deg: expected a number in [1e-06, 90] deg"),
        (["orientation", "--phi1-deg", "1e308"],
         "argument --phi1-deg: expected a number in [-3600, 3600] deg (ten turns)"),
        (["orientation", "--error", "dphi_y1=1e308"],
         "turntable-pin orientation: error: --error 'dphi_y1=1e308': error 'dphi_y1' = 1e+308 "
         "arcsec is not a small error: an angular error must be at most 5 deg (18000 arcsec)"),
        (["orientation", "--error", "deta=1e308"], "|deta| must be at most 10 mm"),
        (["orientation", "--error", "dphi_y1=1", "--error", "dphi_y1_arcmin=2"],
         "--error 'dphi_y1_arcmin=2': dphi_y1 is given twice (also 'dphi_y1=1')"),
        (["orientation", "--error", "a\rb=1"], "--error 'a\\rb=1': unknown error name 'a\\rb'"),
        (["simulate", "--effect", "gravity_sag:k=1,k=2", "-o", "{tmp}/x.csv"],
         "turntable-pin simulate: error: --effect 'gravity_sag:k=1,k=2': parameter 'k' is given "
         "twice"),
        (["simulate", "--effect", "backlash:", "-o", "{tmp}/x.csv"],
         "turntable-pin simulate: error: --effect 'backlash:': a ':' with no parameters after it; "
         "give them as backlash:P=V,... (parameters: b1, b2 in arcsec)"),
        (["simulate", "--effect", "thermal_drift", "-o", "{tmp}/x.csv"],
         "turntable-pin simulate: error: --effect 'thermal_drift': effect 'thermal_drift' without "
         "parameters would simulate nothing; give at least one of rz, ry, rx in arcsec/h (e.g. "
         "thermal_drift:rz=1)"),
        (["simulate", "--effect", "gravity_sag:k=1", "--effect", "gravity_sag:k=2", "-o",
          "{tmp}/x.csv"], "--effect 'gravity_sag:k=2': effect 'gravity_sag' is given twice"),
        (["simulate", "--noise-arcsec", "1e308", "-o", "{tmp}/x.csv"],
         "argument --noise-arcsec: expected a number in [1e-09, 1800] arcsec"),
        (["simulate", "--dwell-s", "1e308", "-o", "{tmp}/x.csv"], "argument --dwell-s"),
        (["simulate", "--dwell-s", "1e6", "-o", "{tmp}/x.csv"],
         "--dwell-s 1e+06: the run would last 1.43e+08 s, more than 3.16224e+07 s (a year)"),
        (["simulate", "--phi1-step-deg", "0", "-o", "{tmp}/x.csv"], "argument --phi1-step-deg"),
        (["fit", str(DATA), "--k-sigma", "0"],
         "turntable-pin fit: error: argument --k-sigma: expected a number > 0, got '0'"),
        (["fit", str(DATA), "--k-sigma=-1"], "argument --k-sigma: expected a number > 0"),
        (["fit", str(DATA), "--k-sigma", "nan"], "argument --k-sigma: expected a finite number"),
    ],
)  # fmt: skip
def test_bad_options_are_one_line_refusals(tmp_path, args, line):
    args = [a.replace("{tmp}", str(tmp_path)) for a in args]
    _refused(cli(*args), line)
    assert list(tmp_path.iterdir()) == []  # no output, no temporary file


def test_yaml_files_that_would_drop_a_value(tmp_path):
    twice = write_file(tmp_path, "errors:\n  dphi_y1: 1\n  dphi_y1: 2\n", "twice.yaml")
    beside = write_file(tmp_path, "errors:\n  dphi_y1: 1\nextra: 2\n", "beside.yaml")
    before = {p: p.read_bytes() for p in (twice, beside)}
    _refused(
        cli("orientation", "--errors", str(twice)),
        f"turntable-pin orientation: error: {twice}, line 3: key 'dphi_y1' is given twice (first "
        "on line 2); give each key once",
    )
    _refused(
        cli("orientation", "--errors", str(beside)),
        f"turntable-pin orientation: error: {beside}: unknown top-level key(s) 'extra' beside "
        "'errors:'; the file holds either 'errors:' alone or the error names",
    )
    assert {p: p.read_bytes() for p in before} == before


def test_an_absurd_measurement_is_refused_not_diagnosed(tmp_path):
    lines = DATA.read_text().splitlines()
    row = next(i for i, line in enumerate(lines) if line.startswith("phi1_deg")) + 1
    cells = lines[row].split(",")
    cells[2] = "1e308"
    lines[row] = ",".join(cells)
    path = write_file(tmp_path, "\n".join(lines) + "\n")
    proc = cli("diagnose", str(path))
    _refused(proc, f"{path}, row {row + 1}, column 'dpsi_arcsec': a measured orientation error")


def test_a_copied_calibration_row_is_refused(tmp_path):
    lines = (EXAMPLES_DIR / "gyrowheel_run_example.csv").read_text().splitlines()
    lines.append(lines[-1])
    path = write_file(tmp_path, "\n".join(lines) + "\n", "run.csv")
    _refused(cli("calibrate", str(path)), f"{path}, row {len(lines)}, column 'phi1_deg': the same "
             f"position as row {len(lines) - 1}")  # fmt: skip


def test_valid_runs_are_unchanged(tmp_path):
    out = tmp_path / "sim.csv"
    proc = cli("simulate", "--seed", str(2**63 - 1), "--effect", "thermal_drift:rz=2", "-o",
               str(out))  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "seed 9223372036854775807" in proc.stdout
    proc = cli("fit", str(out), "--effects", "thermal_drift", "--k-sigma", "2.5")
    assert proc.returncode == 0, proc.stderr
    assert "positions beyond 2.5 sigma" in proc.stdout

"""A telescope mount that was not synced: the German-equatorial mount with its hour-angle index
5.7 deg off, no roll measured. ``simulate`` makes the run, ``fit`` recovers the errors to the
noise, ``diagnose`` names no effect on clean data; offsets of 40 deg, and rows no error set of
the table explains, are refused in one line naming where."""

import json

import numpy as np
import pytest

from conftest import REPO_DIR, cli, write_file
from turntable_pin.model.generic_table import GenericTable

GEM_URDF = REPO_DIR / "models" / "german_equatorial_mount.urdf"

TRUTH_ARCSEC = {
    "hour_angle.position": 5.7 * 3600.0,  # the index offset of a mount not synced
    "hour_angle.tilt_a": 25.0,
    "hour_angle.tilt_b": -12.0,
    "declination.position": -30.0,
    "declination.tilt_a": 20.0,
    "tube_mount.rot_y": 15.0,
    "tube_mount.rot_z": 8.0,
}
"""The simulated errors (arcsec): one large constant offset and small errors."""

NOISE_ARCSEC = 1.0


def _positions(folder):
    """A pointing run's positions: hour angle every 30 deg, declination -35 .. 75 deg."""
    rows = [(h, d) for h in range(-165, 180, 30) for d in range(-35, 80, 11)]
    text = "phi1_deg,phi2_deg\n" + "".join(f"{h},{d}\n" for h, d in rows)
    return write_file(folder, text, "positions.csv")


def _simulate(folder, errors: dict, name: str):
    out = folder / name
    argv = ["simulate", "--urdf", str(GEM_URDF), "--positions", str(_positions(folder)),
            "--noise-arcsec", str(NOISE_ARCSEC), "--seed", "57", "-o", str(out),
            "--not-measured", "dgamma"]  # fmt: skip
    for key, value in errors.items():
        argv += ["--error", f"{key}={value}"]
    return cli(*argv), out


@pytest.fixture(scope="module")
def unsynced_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("gem")
    errors = {k: v for k, v in TRUTH_ARCSEC.items() if k != "hour_angle.position"}
    errors["hour_angle.position_deg"] = 5.7
    proc, path = _simulate(folder, errors, "unsynced.csv")
    assert proc.returncode == 0, proc.stderr
    return path


def test_the_unsynced_run_holds_angles_beyond_the_old_five_degree_limit(unsynced_run):
    table = GenericTable(GEM_URDF)
    from turntable_pin.measurement.data import read_measurements

    data = read_measurements(unsynced_run, table.joint_names)
    assert np.isnan(data.angles_rad[:, 2]).all()
    largest_deg = np.degrees(np.nanmax(np.abs(data.angles_rad)))
    assert 5.0 < largest_deg < 30.0


def test_fit_recovers_the_errors_to_the_noise(unsynced_run):
    from turntable_pin.measurement.data import read_measurements
    from turntable_pin.measurement.effect_model import OrientationModel

    proc = cli("fit", "--urdf", str(GEM_URDF), "--json", str(unsynced_run))
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["chi2_reduced"] == pytest.approx(1.0, abs=0.25)
    assert out["rank"] == 6  # what the positions determine without dgamma
    # The fitted errors reproduce the noise-free orientation errors of the truth well inside the
    # noise (the statistical error of a 6-parameter fit to 264 angles, ~0.15 of the noise).
    table = GenericTable(GEM_URDF)
    data = read_measurements(unsynced_run, table.joint_names)
    model = OrientationModel(data.variables(), [], table)
    fitted = np.array([out["params"][n]["value"] for n in model.parameter_names]) / 206264.806
    truth = model.parameter_vector({n: v / 206264.806 for n, v in TRUTH_ARCSEC.items()})
    diff_arcsec = (model.predict(fitted) - model.predict(truth))[:, :2] * 206264.806
    assert np.sqrt(np.mean(diff_arcsec**2)) < 0.3 * NOISE_ARCSEC
    # The determined combinations: the offset's to its standard error; the small ones also up to
    # the second-order ambiguity of splitting the undetermined hour_angle.position +
    # declination.tilt_b (offset in rad times the small errors, ~3 arcsec): at degrees of offset
    # the linear combinations are not exactly invariant along it.
    second_order = np.radians(5.7) * max(abs(v) for v in TRUTH_ARCSEC.values() if v < 3600)
    for combination in out["identifiable"]["combinations"]:
        truth_value = sum(
            c * TRUTH_ARCSEC.get(n, 0.0) for n, c in combination["coefficients"].items()
        )
        error = abs(combination["value"] - truth_value)
        if "hour_angle.position" in combination["coefficients"]:
            assert error < 4.0 * combination["std"], combination
        else:
            assert error < 4.0 * combination["std"] + second_order, combination


def test_diagnose_names_no_effect_on_the_clean_unsynced_run(unsynced_run):
    proc = cli("diagnose", "--urdf", str(GEM_URDF), "--json", str(unsynced_run))
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["verdict"]["missing_effect"] is None and not out["verdict"]["unexplained"]
    assert out["base"]["chi2_reduced"] == pytest.approx(1.0, abs=0.25)
    # No candidate fits worse than the base errors alone (it nests them): the fits with effects
    # start from the base solution when the offsets are large.
    for candidate in out["candidates"]:
        if candidate.get("rms_arcsec") is not None:
            assert candidate["rms_arcsec"] <= out["base"]["rms_arcsec"] * (1 + 1e-9), candidate


def test_an_offset_of_40_degrees_is_refused_by_simulate(tmp_path):
    proc, _ = _simulate(tmp_path, {"hour_angle.position_deg": 40}, "forty.csv")
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == [
        "turntable-pin simulate: error: --error 'hour_angle.position_deg=40': error "
        "'hour_angle.position_deg' = 40 deg is not an error of the table: an angular error must "
        "be at most 30 deg (108000 arcsec)"
    ]


def _measured_csv(folder, errors_rad: dict, name: str, gross_rows=()):
    """A run of the mount with these errors, noise free, dgamma not measured; the rows
    ``gross_rows`` (indices) 10 deg off in dtheta."""
    from turntable_pin.measurement.effect_model import OrientationModel
    from turntable_pin.measurement.effects.base import PositionVariables

    table = GenericTable(GEM_URDF)
    rows = np.radians([(h, d) for h in range(-165, 180, 30) for d in range(-35, 80, 11)])
    model = OrientationModel(PositionVariables(rows), [], table)
    angles = np.degrees(model.predict(model.parameter_vector(errors_rad))) * 3600.0
    angles[list(gross_rows), 1] += 10.0 * 3600.0
    lines = ["phi1_deg,phi2_deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec,sigma_arcsec"]
    for (h, d), (psi, theta, _) in zip(np.degrees(rows), angles, strict=True):
        lines.append(f"{h:.6f},{d:.6f},{psi:.6f},{theta:.6f},,1")
    return write_file(folder, "\n".join(lines) + "\n", name)


@pytest.mark.parametrize("command", ["fit", "diagnose"])
def test_a_run_with_40_degree_offsets_is_refused_in_one_line(tmp_path, command):
    path = _measured_csv(tmp_path, {"hour_angle.position": np.radians(40)}, "forty.csv")
    proc = cli(command, "--urdf", str(GEM_URDF), str(path))
    assert proc.returncode == 2 and proc.stdout == ""
    (line,) = proc.stderr.splitlines()
    assert line.startswith(f"turntable-pin {command}: error: {path}, row ")
    assert "a measured orientation error must be within +-108000 arcsec (30 deg; more is no " \
        "orientation error of the table)" in line  # fmt: skip


@pytest.mark.parametrize("command", ["fit", "diagnose"])
def test_rows_no_error_set_explains_are_refused_naming_them(tmp_path, command):
    errors = {"hour_angle.position": np.radians(5.7), "declination.tilt_a": 1e-4}
    path = _measured_csv(tmp_path, errors, "gross.csv", gross_rows=(3, 40))
    proc = cli(command, "--urdf", str(GEM_URDF), str(path))
    assert proc.returncode == 2 and proc.stdout == ""
    (line,) = proc.stderr.splitlines()
    assert f"row(s) 5, 42 of {path}: the best fit of the table's errors leaves up to " in line
    assert "beyond 5 deg: no error set of this table explains them" in line

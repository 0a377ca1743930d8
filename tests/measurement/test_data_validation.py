"""The measurement reader refuses values outside their physical range, naming file, row and
column (a finite but absurd value used to give rms inf and "missing effect: none")."""

import pytest

from conftest import cli, write_file
from turntable_pin.core.exceptions import InputError
from turntable_pin.measurement.data import (
    MAX_COMMANDED_ANGLE_DEG,
    MAX_MEASURED_ANGLE_ARCSEC,
    MAX_SIGMA_ARCSEC,
    MAX_TIME_S,
    MIN_SIGMA_ARCSEC,
    read_measurements,
)

HEADER = "phi1_deg,phi2_deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec,sigma_arcsec,time_s\n"
ROWS = ["0,0,1,2,3,1,0", "0,90,1,2,3,1,60", "90,0,1,2,3,1,120"]


def _file(tmp_path, row: int, column: str, value: str):
    rows = [r.split(",") for r in ROWS]
    rows[row][HEADER.strip().split(",").index(column)] = value
    return write_file(tmp_path, HEADER + "".join(",".join(r) + "\n" for r in rows))


def test_the_limits():
    assert MAX_MEASURED_ANGLE_ARCSEC == 108000.0  # 30 deg
    assert MAX_SIGMA_ARCSEC == 18000.0  # 5 deg
    assert MAX_COMMANDED_ANGLE_DEG == 3600.0
    assert MIN_SIGMA_ARCSEC == 1e-9
    assert MAX_TIME_S == 366 * 86400.0


@pytest.mark.parametrize(
    "column, value, fragment",
    [
        ("dpsi_arcsec", "1e308", "a measured orientation error must be within +-108000 arcsec"),
        ("dgamma_arcsec", "-108000.5", "a measured orientation error must be within"),
        ("dtheta_arcsec", "144000", "(30 deg; more is no orientation error of the table)"),
        ("phi1_deg", "1e308", "a commanded angle must be within +-3600 deg (ten turns)"),
        ("phi2_deg", "-3600.1", "a commanded angle must be within +-3600 deg"),
        ("sigma_arcsec", "1e-300", "sigma must be at least 1e-09 arcsec"),
        ("sigma_arcsec", "18001", "sigma must be at most 18000 arcsec"),
        ("sigma_arcsec", "0", "sigma must be > 0"),
        ("time_s", "1e308", "time since the start of the run must be at most"),
    ],
)
def test_out_of_range_values_are_refused_naming_row_and_column(tmp_path, column, value, fragment):
    path = _file(tmp_path, 1, column, value)
    with pytest.raises(InputError) as info:
        read_measurements(path)
    assert fragment in str(info.value)
    assert str(info.value).startswith(f"{path}, row 3, column '{column}': ")


def test_values_at_the_limits_are_read(tmp_path):
    path = _file(tmp_path, 0, "dpsi_arcsec", "-108000")
    data = read_measurements(path)
    assert data.n_positions == 3
    read_measurements(_file(tmp_path, 1, "sigma_arcsec", "18000"))
    read_measurements(_file(tmp_path, 2, "phi1_deg", "3600"))
    read_measurements(_file(tmp_path, 2, "sigma_arcsec", "1e-9"))


def test_the_cli_refuses_an_absurd_measurement_in_one_line(tmp_path):
    path = _file(tmp_path, 2, "dtheta_arcsec", "1e308")
    for command in ("fit", "diagnose"):
        proc = cli(command, str(path))
        assert proc.returncode == 2 and proc.stdout == ""
        assert proc.stderr.splitlines() == [
            f"turntable-pin {command}: error: {path}, row 4, column 'dtheta_arcsec': a measured "
            "orientation error must be within +-108000 arcsec (30 deg; more is no orientation "
            "error of the table), found 1e+308"
        ]

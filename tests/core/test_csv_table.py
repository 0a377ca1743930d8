import numpy as np
import pytest

from conftest import write_file
from turntable_pin import InputError
from turntable_pin.core.csv_table import read_csv_table, write_csv_table

REQ = ("phi1_deg", "phi2_deg", "dpsi_arcsec")
HEAD = "phi1_deg,phi2_deg,dpsi_arcsec\n"


def test_reads_required_and_optional_columns(tmp_path):
    text = "# comment\nphi2_deg,phi1_deg,dpsi_arcsec,extra,time_s\n0,90,1.5,x,3\n"
    path = write_file(tmp_path, text)
    table = read_csv_table(path, REQ, ("time_s", "sigma_arcsec"))
    assert len(table) == 1 and table.has("time_s") and not table.has("sigma_arcsec")
    assert table["phi1_deg"][0] == 90 and table.rows.tolist() == [3]


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("", "empty"),
        ("phi1_deg,phi2_deg\n0,0\n", "row 1: missing required column(s) 'dpsi_arcsec'"),
        ("phi1_deg,Phi2_Deg,dpsi_arcsec\n0,0,0\n", "'phi2_deg' (found 'Phi2_Deg')"),
        (HEAD + "0,0,1\n0,abc,1\n", "row 3, column 'phi2_deg': expected a number, found 'abc'"),
        (HEAD + "0,0,nan\n", "row 2, column 'dpsi_arcsec': expected a finite"),
        (HEAD + "0,,1\n", "row 2, column 'phi2_deg': expected a number, found an empty"),
        ("phi1_deg,phi2_deg,dpsi_arcsec\n0,0\n", "row 2: expected 3 cells"),
        ("phi1_deg,phi1_deg,phi2_deg,dpsi_arcsec\n0,0,0,0\n", "appears twice"),
    ],
)  # fmt: skip
def test_problems_name_file_row_and_column(tmp_path, text, fragment):
    path = write_file(tmp_path, text)
    with pytest.raises(InputError) as info:
        read_csv_table(path, REQ)
    assert str(path) in str(info.value)
    assert fragment in str(info.value)


def test_write_then_read_round_trip(tmp_path):
    cols = {"phi1_deg": [0.0, 30.0], "phi2_deg": [1e-17, 2.5], "dpsi_arcsec": [1 / 3, -2.0]}
    path = write_csv_table(tmp_path / "out.csv", cols, comment="seed 3\nsimulated")
    table = read_csv_table(path, REQ)
    for name, values in cols.items():
        np.testing.assert_array_equal(table[name], values)

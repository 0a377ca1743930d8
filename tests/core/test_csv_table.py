import numpy as np
import pytest

from conftest import write_file
from turntable_pin import InputError
from turntable_pin.core.csv_table import read_csv_table, read_header, write_csv_table

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


def test_whole_column_reading_equals_cell_by_cell(tmp_path):
    """The fast path (every cell clean) gives what the checked cell-by-cell reading gives."""
    from turntable_pin.core import csv_table

    rng = np.random.default_rng(0)
    lines = ["# comment", "a, b ,c,note"]
    for _ in range(300):
        lines.append(f"{rng.normal():.17g}, {rng.uniform(-1e3, 1e3)!r} ,{rng.integers(9)},x y")
    path = write_file(tmp_path, "\n".join(lines) + "\n", "t.csv")
    table = read_csv_table(path, ("a", "b"), ("c",), extra=True)
    import csv

    text = [(i, line) for i, line in enumerate(path.read_text().splitlines(True), start=1)]
    text = [(i, line) for i, line in text if line.strip() and not line.startswith("#")]
    rows = list(csv.reader([line for _, line in text]))
    header = tuple(h.strip() for h in rows[0])
    index = {name: header.index(name) for name in ("a", "b", "c")}
    values, other, numbers = csv_table._cell_by_cell(
        path, text, rows[1:], header, index, ["note"], set()
    )
    for name in ("a", "b", "c"):
        np.testing.assert_array_equal(table[name], np.asarray(values[name]))
    np.testing.assert_array_equal(table.rows, numbers)
    assert table.skipped == ("note",)


def test_vectorised_rounding_equals_python_round():
    from turntable_pin.core.csv_table import _rounded_9

    rng = np.random.default_rng(1)
    grids = [np.arange(0, 360, 0.9), np.arange(0, 360, 1.44), np.arange(0, 3e4, 30.0)]
    samples = [*grids, rng.uniform(-400, 400, 5000), np.array([-1e-12, 0.0, -0.0, 1.0, -1.0]),
               np.arange(0, 3e7, 30.0)]  # fmt: skip
    for values in samples:
        expected = np.array([round(v, 9) for v in values.tolist()])
        np.testing.assert_array_equal(_rounded_9(values), expected)


def test_repeated_rows_found_by_keys_equal_as_python_compares_them(tmp_path):
    """-0.0 and 0.0 are the same position (as Python's tuples compare them)."""
    from turntable_pin.core.csv_table import refuse_repeated_rows

    path = write_file(tmp_path, "p,q\n1,2\n-0.0000000000001,5\n3,4\n0,5\n", "r.csv")
    table = read_csv_table(path, ("p", "q"))
    with pytest.raises(InputError, match="same position as row 3") as info:
        refuse_repeated_rows(table, ("p", "q"), "advice")
    assert "row 5" in str(info.value)


def test_numpy_reading_of_a_clean_file_equals_cell_by_cell(tmp_path):
    """An unquoted, all-numeric file is read by numpy at once: the same numbers as ``float``
    cell by cell (CRLF line ends, spaces, exponents, signs), extra columns kept, refused (a bad
    cell among numbers) or skipped (text)."""
    import csv

    from turntable_pin.core import csv_table

    rng = np.random.default_rng(2)
    lines = ["# comment", "a, b ,c,temp,bad"]
    for k in range(400):
        cells = [f"{rng.normal():.17g}", f" {rng.uniform(-1e3, 1e3):.6e} ", f"+{k}", f"{k / 7!r}",
                 "inf" if k == 5 else "1"]  # fmt: skip
        lines.append(",".join(cells))
    path = write_file(tmp_path, "\r\n".join(lines) + "\r\n", "n.csv")
    # numpy reads 'inf' as a number: a numeric column with one bad cell, refused where it is
    with pytest.raises(InputError, match="row 8, column 'bad': expected a finite number, found"):
        read_csv_table(path, ("a", "b"), ("c",), extra=True)
    lines[7] = lines[7].replace(",inf", ",x")  # now a text cell: still a numeric column
    path = write_file(tmp_path, "\r\n".join(lines) + "\r\n", "n.csv")
    with pytest.raises(InputError, match="row 8, column 'bad': 'x' is not a number"):
        read_csv_table(path, ("a", "b"), ("c",), extra=True)
    lines = [line if i < 2 else line[: line.rindex(",")] + ",x" for i, line in enumerate(lines)]
    path = write_file(tmp_path, "\r\n".join(lines) + "\r\n", "n.csv")
    table = read_csv_table(path, ("a", "b"), ("c",), extra=True)
    assert table.skipped == ("bad",) and list(table.extra) == ["temp"]
    with path.open(newline="", encoding="utf-8-sig") as handle:
        text = [(i, line) for i, line in enumerate(handle, start=1)]
    text = [(i, line) for i, line in text if line.strip() and not line.startswith("#")]
    rows = list(csv.reader([line for _, line in text]))
    header = tuple(h.strip() for h in rows[0])
    index = {name: header.index(name) for name in ("a", "b", "c")}
    values, other, numbers = csv_table._cell_by_cell(
        path, text, rows[1:], header, index, ["temp", "bad"], set()
    )
    for name in ("a", "b", "c"):
        np.testing.assert_array_equal(table[name], np.asarray(values[name]))
    np.testing.assert_array_equal(table.extra["temp"], [float(c) for c in other["temp"]])
    np.testing.assert_array_equal(table.rows, numbers)


def test_the_header_read_alone_agrees_with_the_whole_reading(tmp_path):
    text = "# made by hand\n\n# second comment\n a , b,c\n1,2,3\n"
    path = write_file(tmp_path, text)
    table = read_csv_table(path, ("a",), extra=True)
    assert read_header(path) == (table.header, table.header_row) == (("a", "b", "c"), 4)
    assert read_header(tmp_path / "absent.csv") == ((), 0)
    assert read_header(write_file(tmp_path, "# only a comment\n", "empty.csv")) == ((), 0)


def test_a_missing_column_error_names_the_header_row_and_the_closest_column(tmp_path):
    from turntable_pin.core.csv_table import closest_column_hint
    from turntable_pin.measurement.data import read_measurements

    assert "'dteta_arcsec'" in closest_column_hint("dtheta_arcsec", ["phi1_deg", "dteta_arcsec"])
    assert closest_column_hint("dtheta_arcsec", ["phi1_deg", "temperature_c"]) == ""
    path = tmp_path / "m.csv"
    path.write_text(
        "# a comment line first\nphi1_deg,phi_2deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec\n"
        "0,0,1,1,1\n"
    )
    with pytest.raises(InputError) as caught:
        read_measurements(path)
    message = str(caught.value)
    assert "row 2" in message and "is 'phi_2deg' a misspelling" in message


@pytest.mark.parametrize("quoted", [False, True])
@pytest.mark.parametrize(
    "cell, fragment",
    [
        ("warm", "row 17, column 'temperature_c': 'warm' is not a number"),
        ("", "row 17, column 'temperature_c': expected a number, found an empty cell"),
        ("nan", "row 17, column 'temperature_c': expected a finite number, found 'nan'"),
    ],
)
def test_a_numeric_other_column_with_a_bad_cell_is_refused_naming_row_and_column(
    tmp_path, cell, fragment, quoted
):
    """Issue 27: one bad cell among numbers no longer drops the column without a word."""
    rows = [f"{k},{20 + k / 10}" if k != 15 else f"{k},{cell}" for k in range(30)]
    if quoted:
        rows[0] = '"0",20.0'
    path = write_file(tmp_path, "a,temperature_c\n" + "\n".join(rows) + "\n")
    with pytest.raises(InputError) as info:
        read_csv_table(path, ("a",), extra=True)
    assert fragment in str(info.value) and str(path) in str(info.value)
    assert "so it is a numeric column" in str(info.value)


def test_the_boundary_between_a_numeric_and_a_text_column(tmp_path):
    """Numeric when at least half of the filled cells are numbers; else text, named in
    ``skipped`` (a ``note`` with a number in it, a column empty throughout)."""
    text = "a,half,note,empty\n1,3,ok,\n2,hot,see log,\n3,,2,\n4,,checked,\n"
    path = write_file(tmp_path, text)
    with pytest.raises(InputError, match="row 3, column 'half': 'hot' is not a number"):
        read_csv_table(path, ("a",), extra=True)
    table = read_csv_table(write_file(tmp_path, text.replace(",3,ok", ",cold,ok")), ("a",),
                           extra=True)  # fmt: skip
    assert table.skipped == ("half", "note", "empty") and not table.extra


def test_missing_columns_are_never_called_absent_when_present_as_text():
    from turntable_pin.core.csv_table import ignored_columns_words, missing_columns_words

    words = missing_columns_words(["time_s", "temperature_c"], ("temperature_c",), "the run")
    assert words == (
        "time_s, absent from the run; temperature_c, present in the run but not numbers "
        "(text or empty throughout), so ignored"
    )
    assert missing_columns_words(["x"], (), "the data") == "x, absent from the data"
    assert ignored_columns_words(["note"]).startswith("column(s) note ignored: not numbers")


@pytest.mark.parametrize(
    "delimiter, named",
    [(";", "';'"), ("\t", "a tab"), ("|", "'|'")],
    ids=["semicolon", "tab", "bar"],
)
def test_another_delimiter_is_named_not_taken_for_a_missing_column(tmp_path, delimiter, named):
    text = (
        "# made by a spreadsheet\n\n"
        + HEAD.replace(",", delimiter)
        + "0;0;1\n".replace(";", delimiter)
    )
    path = write_file(tmp_path, text)
    for read in (lambda: read_csv_table(path, REQ), lambda: read_header(path)):
        with pytest.raises(InputError) as info:
            read()
        message = str(info.value)
        assert f"row 3: the delimiter is {named} (expected ',')" in message
        assert "missing" not in message


def test_a_missing_column_that_may_be_empty_says_an_empty_cell_means_not_measured(tmp_path):
    path = write_file(tmp_path, "phi1_deg,phi2_deg,dpsi_arcsec\n0,0,1\n")
    blank = ("dpsi_arcsec", "dtheta_arcsec", "dgamma_arcsec")
    with pytest.raises(InputError) as info:
        read_csv_table(path, ("phi1_deg", "phi2_deg", *blank), blank=blank)
    message = str(info.value)
    assert "missing required column(s) 'dtheta_arcsec', 'dgamma_arcsec'" in message
    assert "keep the columns with their cells left empty (an empty cell means not measured)" in (
        message
    )
    assert "misspelling" not in message  # dpsi_arcsec is a column of its own, no misspelling


def test_a_known_column_is_never_proposed_and_no_hint_is_given_twice(tmp_path):
    header = "phi1_deg,phi2_deg,sigma_arcsec,dangle_arcsec"
    path = write_file(tmp_path, header + "\n0,0,1,1\n")
    blank = ("dpsi_arcsec", "dtheta_arcsec", "dgamma_arcsec")
    with pytest.raises(InputError) as info:
        read_csv_table(path, ("phi1_deg", "phi2_deg", *blank), ("sigma_arcsec",), blank=blank)
    message = str(info.value)
    assert "sigma_arcsec' a misspelling" not in message
    assert message.count("is 'dangle_arcsec' a misspelling") == 1

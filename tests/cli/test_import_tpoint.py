"""``turntable-pin import-tpoint``: the bundled MMT run in, the CSV read back by the measurement
commands, an equatorial run with its tilted URDF, and bad input as one line with exit status 2."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES_DIR, REPO_DIR, cli, write_file
from turntable_pin.cli.words import CLI_WORDS
from turntable_pin.core.words import speaking
from turntable_pin.measurement.data import read_measurements
from turntable_pin.measurement.tpoint import convert_tpoint, read_tpoint
from turntable_pin.model.generic_table import GenericTable

MMT = EXAMPLES_DIR / "mmt_pointing" / "k_and_e.dat"
ALTAZ_URDF = REPO_DIR / "models" / "altaz_mount.urdf"
EQUATORIAL = """Equatorial run
: EQUAT
-33 52 00 2024 3 1 10.0 1000.0 100.0 0.5
1 0 0.0  +20 0 0.0  1 0 2.0  +20 0 10.0  2 30
3 0 0.0  -10 0 0.0  3 0 1.0  -10 0 5.0  2 30
0 30 0.0  -60 0 0.0  0 30 4.0  -60 0 1.0  2 30.5
"""


def _one_line_exit_2(proc, fragment):
    assert proc.returncode == 2, proc.stdout + proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert lines[0].startswith("turntable-pin import-tpoint: error:") and fragment in lines[0]


def test_the_mmt_run_is_imported_and_read_back(tmp_path):
    out = tmp_path / "mmt.csv"
    proc = cli("import-tpoint", str(MMT), "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    assert "80 stars, altaz mount (: ALTAZ)" in proc.stdout
    assert "refraction: none" in proc.stdout and "--urdf models/altaz_mount.urdf" in proc.stdout
    with speaking(CLI_WORDS):  # the file names the command line's flag, as the CLI speaks
        expected = convert_tpoint(read_tpoint(MMT)).csv_text()
    assert out.read_text() == expected
    data = read_measurements(out, GenericTable(ALTAZ_URDF).joint_names)
    assert data.n_positions == 80
    proc = cli("fit", str(out), "--urdf", str(ALTAZ_URDF), "--json")
    assert proc.returncode == 0, proc.stderr


def test_refraction_apply_is_stated_in_the_output_and_the_file(tmp_path):
    out = tmp_path / "mmt.csv"
    proc = cli("import-tpoint", str(MMT), "-o", str(out), "--refraction", "apply")
    assert proc.returncode == 0, proc.stderr
    assert "refraction: applied (Saemundsson, 13 C, 741 mbar)" in proc.stdout
    assert "# refraction: applied (Saemundsson" in out.read_text()


def test_an_equatorial_run_writes_the_tilted_urdf_and_reads_back(tmp_path):
    run = write_file(tmp_path, EQUATORIAL, "eq.dat")
    out, urdf = tmp_path / "eq.csv", tmp_path / "eq.urdf"
    proc = cli("import-tpoint", str(run), "-o", str(out))
    _one_line_exit_2(proc, "an equatorial run needs --write-urdf")
    assert not out.exists()
    proc = cli("import-tpoint", str(run), "-o", str(out), "--write-urdf", str(urdf))
    assert proc.returncode == 0, proc.stderr
    assert (
        "3 stars, equatorial mount (: EQUAT)" in proc.stdout
        and "refraction: applied" in proc.stdout
    )
    assert "Copy tilted to latitude" in urdf.read_text()
    assert f"read with --urdf {urdf}" in out.read_text()
    table = GenericTable(urdf)
    assert table.joint_names == ("hour_angle", "declination")
    assert read_measurements(out, table.joint_names).n_positions == 3
    proc = cli("import-tpoint", str(run), "-o", str(out), "--write-urdf", str(urdf),
               "--latitude-deg", "-30", "--refraction", "none")  # fmt: skip
    assert proc.returncode == 0 and "polar axis at -30.000000 deg" in proc.stdout
    assert "refraction: none" in proc.stdout


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--mount", "equatorial"], "line 19: the file states an altaz mount"),
        (["--azimuth-origin", "north"], "line 13: the file's comment states 'South = 0'"),
        (["--refraction", "maybe"], "invalid choice"),
    ],
)
def test_options_contradicting_the_file_are_refused(args, fragment, tmp_path):
    proc = cli("import-tpoint", str(MMT), "-o", str(tmp_path / "x.csv"), *args)
    assert proc.returncode == 2 and fragment in proc.stderr, proc.stderr
    assert not (tmp_path / "x.csv").exists()


BAD = {
    "option": (": ALTAZ\n: FROB\n+31 41 19.6\n1 2 1 2\n", "line 3: unknown option line ': FROB'"),
    "equat as altaz": (": EQUAT\n+31 41 19.6\n", "line 2: the file states an equatorial mount"),
    "fields": (": ALTAZ\n+31 41 19.6\n1 2 1\n", "line 4: expected 4 numbers"),
    "number": (": ALTAZ\n+31 41 19.6\n1 2 1 two\n", "line 4: data: 'two' is not a number"),
    "run line": (": ALTAZ\n1 2 1 2\n", "line 3: expected the run-parameter line"),
    "no data": (": ALTAZ\n+31 41 19.6\n", "no data lines after the run-parameter line (line 3)"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_files_are_one_line_exit_2(case, tmp_path):
    body, fragment = BAD[case]
    run = write_file(tmp_path, "caption\n" + body, "bad.dat")
    extra = ["--mount", "altaz"] if case == "equat as altaz" else []
    out = tmp_path / "out.csv"
    proc = cli("import-tpoint", str(run), "-o", str(out), *extra)
    _one_line_exit_2(proc, fragment)
    assert str(run) in proc.stderr and not out.exists()


def test_outputs_may_not_be_the_input(tmp_path):
    run = tmp_path / "run.dat"
    run.write_bytes(MMT.read_bytes())
    _one_line_exit_2(cli("import-tpoint", str(run), "-o", str(run)), "it is the data file")
    _one_line_exit_2(
        cli("import-tpoint", str(run), "-o", str(tmp_path / "a.csv"), "--write-urdf", str(run)),
        "refusing to write --write-urdf",
    )
    _one_line_exit_2(
        cli(
            "import-tpoint",
            str(run),
            "-o",
            str(tmp_path / "a.csv"),
            "--write-urdf",
            str(tmp_path / "a.csv"),
        ),  # fmt: skip
        "they are one file",
    )
    assert run.read_bytes() == MMT.read_bytes()
    _one_line_exit_2(cli("import-tpoint", str(tmp_path / "nope.dat"), "-o", "x.csv"), "cannot read")


def test_import_tpoint_loads_no_fitting_or_plotting_library(tmp_path):
    from test_package_layout import _heavy_modules_loaded_by

    heavy = ("scipy", "matplotlib", "yourdfpy", "meshcat")
    argv = ["import-tpoint", str(MMT), "-o", str(tmp_path / "mmt.csv")]
    assert _heavy_modules_loaded_by(argv, heavy) == []
    assert (tmp_path / "mmt.csv").is_file()


def test_a_repeated_star_is_refused_at_import_naming_both_lines(tmp_path):
    """Issue 27: a copied line was imported, and fit and diagnose then refused the CSV naming
    its rows; the import now refuses it naming the lines of the TPOINT file."""
    lines = MMT.read_text().splitlines()
    assert lines[20].split() == "192.3860283 77.3468410111111 -167.2778909 77.3475476".split()
    lines.insert(76, lines[20])  # line 77 repeats line 21
    run = write_file(tmp_path, "\n".join(lines) + "\n", "repeated.dat")
    out = tmp_path / "repeated.csv"
    proc = cli("import-tpoint", str(run), "-o", str(out))
    _one_line_exit_2(proc, "lines 21 and 77 are the same star at the same raw position")
    assert not out.exists()

"""The CSV hints every command gives alike (issue 30): the delimiter named, the empty column
that means "not measured", the header's problems at the header's line (the file's line number,
comment lines counted) whichever command reads the file, each hint once."""

import pytest

from conftest import EXAMPLES_DIR, cli, refused, write_file

EXAMPLE = (EXAMPLES_DIR / "measurements_example.csv").read_text()
COMMENTS = sum(1 for line in EXAMPLE.splitlines() if line.startswith("#"))
HEADER_ROW = COMMENTS + 1


def _with_header(change) -> str:
    lines = EXAMPLE.splitlines()
    lines[COMMENTS] = change(lines[COMMENTS])
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize(
    "text, words",
    [
        (EXAMPLE.replace(",", ";"), "the delimiter is ';' (expected ',')"),
        (_with_header(lambda h: h.replace("phi2_deg", "phi1_deg")),
         "column 'phi1_deg' appears twice in the header"),
    ],
    ids=["semicolons", "repeated-column"],
)  # fmt: skip
def test_calibrate_and_diagnose_report_a_header_problem_alike_at_the_headers_line(
    tmp_path, text, words
):
    path = write_file(tmp_path, text)
    lines = [refused(cli(command, str(path)), words) for command in ("calibrate", "diagnose")]
    located = {line.split(": error: ", 1)[1] for line in lines}
    assert len(located) == 1, lines  # the same message from both
    assert located.pop().startswith(f"{path}, row {HEADER_ROW}: {words}")
    assert all("missing" not in line for line in lines)


def test_a_missing_angle_column_says_an_empty_column_means_not_measured(tmp_path):
    text = _with_header(lambda h: h.replace(",dgamma_arcsec", ""))
    text = "\n".join(
        line if line.startswith("#") or i == COMMENTS else ",".join(
            cell for k, cell in enumerate(line.split(",")) if k != 4
        )
        for i, line in enumerate(text.splitlines())
    )  # fmt: skip
    path = write_file(tmp_path, text + "\n")
    line = refused(
        cli("diagnose", str(path)),
        f"row {HEADER_ROW}: missing required column(s) 'dgamma_arcsec'",
        "if dgamma_arcsec was not measured, keep the column with its cells left empty (an empty "
        "cell means not measured)",
    )
    assert "misspelling" not in line  # sigma_arcsec, dtheta_arcsec are columns of their own


def test_a_sigma_header_problem_is_at_the_headers_line(tmp_path):
    text = _with_header(lambda h: h + ",sigma_dpsi_arcsec")
    lines = text.splitlines()
    text = "\n".join(
        line if line.startswith("#") or i == COMMENTS else line + ",1.0"
        for i, line in enumerate(lines)
    )  # fmt: skip
    path = write_file(tmp_path, text + "\n")
    refused(cli("diagnose", str(path)), f"row {HEADER_ROW}, column 'sigma_arcsec': give either")


@pytest.mark.parametrize("command", ["calibrate", "diagnose", "fit", "report"])
def test_the_help_of_a_command_reading_a_csv_says_the_row_rule(command):
    from turntable_pin.core.csv_table import ROW_RULE

    page = " ".join(cli(command, "--help").stdout.split())
    assert ROW_RULE in page and "comment lines counted" in ROW_RULE

"""Property-based fuzzing of every user input: the CSV readers (measurement file, calibration
run), the YAML readers (errors, GyroWheel coefficients, manufacturing lower bounds) and the numeric
options of the command line.

Whatever the input, the command ends with exit status 0 (or 1 for a Monte Carlo run that exceeds a
limit), or with status 2 and exactly one line on stderr naming the place (the file or the option);
never a traceback, never a warning, never an input file changed, never a file left behind
(``fuzzing.run_and_check``). The CLI runs in this process (``conftest.cli``) to keep the examples
cheap.
"""

from __future__ import annotations

import math
import shutil
import string
import tempfile
from pathlib import Path

import pytest
import yaml
from hypothesis import assume, given
from hypothesis import strategies as st

from conftest import EXAMPLES_DIR, cli
from fuzzing import example_folder, fuzz, run_and_check, scratch_folder

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def scratch():
    """A folder for the examples: each example gets (and removes) a subfolder of it."""
    yield from scratch_folder()


# ---- cell, value and key texts ----------------------------------------------------------------
SPECIAL_NUMBERS = [
    "", " ", "nan", "NaN", "inf", "-inf", "1e308", "-1e308", "1e-308", "5e-324", "0", "-0",
    "-1", "1", "+1", "0.5", "360", "3600", "3600.5", "-3601", "18000", "18000.5", "1e6", "1e7",
    "2e5", "1e-9", "1e-10", "0x10", "1_0", "١", "abc", "1,5", '"7"', "True", "1e999", "9" * 30,
    "2**63", "9223372036854775807", "9223372036854775808", "-9223372036854775809",
]  # fmt: skip

number_text = st.one_of(
    st.sampled_from(SPECIAL_NUMBERS),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.floats(-1e7, 1e7).map(lambda x: f"{x:g}"),
    st.integers(-(2**70), 2**70).map(str),
)
cell_text = st.one_of(number_text, st.text(string.printable, max_size=6))


@st.composite
def mutated_csv(draw, base_text: str) -> str:
    """``base_text`` with a few cells, rows, header names or lines changed, copied or removed."""
    lines = base_text.splitlines()
    start = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.sampled_from(["cell", "cell", "cell", "copy", "drop", "cells", "header",
                                     "line", "extra"]))  # fmt: skip
        i = draw(st.integers(start + 1, max(start + 1, len(lines) - 1)))
        if i >= len(lines):
            continue
        cells = lines[i].split(",")
        if kind == "cell":
            cells[draw(st.integers(0, len(cells) - 1))] = draw(cell_text)
            lines[i] = ",".join(cells)
        elif kind == "copy":
            lines.insert(draw(st.integers(start + 1, len(lines))), lines[i])
        elif kind == "drop":
            del lines[i]
        elif kind == "cells":
            lines[i] = ",".join(cells[: draw(st.integers(0, len(cells) + 1))])
        elif kind == "header":
            header = lines[start].split(",")
            names = st.text(string.ascii_lowercase + "_ ", max_size=9)
            header[draw(st.integers(0, len(header) - 1))] = draw(
                st.one_of(st.sampled_from(header), names)
            )
            lines[start] = ",".join(header)
        elif kind == "line":
            lines[i] = draw(st.text(max_size=20))
        else:
            lines[i] = lines[i] + "," + draw(cell_text)
    return "\n".join(lines) + draw(st.sampled_from(["\n", "", "\r\n", "\n\n#"]))


def _small_measurements() -> str:
    """A small simulated measurement file (32 positions, every optional column)."""
    folder = Path(tempfile.mkdtemp())
    try:
        path = folder / "base.csv"
        proc = cli(
            "simulate", "--error", "dphi_y1=3", "--effect", "gravity_sag:k=2",
            "--phi1-step-deg", "90", "--phi2-step-deg", "45", "--seed", "5", "-o", str(path),
        )  # fmt: skip
        assert proc.returncode == 0, proc.stderr
        return path.read_text()
    finally:
        shutil.rmtree(folder)


MEASUREMENTS = _small_measurements()
RUN = (EXAMPLES_DIR / "gyrowheel_run_example.csv").read_text()


@fuzz(60)
@given(text=mutated_csv(MEASUREMENTS), ignore_sigma=st.booleans())
def test_measurement_csv(scratch, text, ignore_sigma):
    folder = example_folder(scratch)
    path = folder / "data.csv"
    path.write_text(text, encoding="utf-8")
    args = ["fit", str(path)] + (["--ignore-sigma"] if ignore_sigma else [])
    run_and_check(folder, args, "data.csv")


@fuzz(60)
@given(text=mutated_csv(RUN))
def test_calibration_run_csv(scratch, text):
    folder = example_folder(scratch)
    path = folder / "run.csv"
    path.write_text(text, encoding="utf-8")
    run_and_check(folder, ["calibrate", str(path)], "run.csv")


# ---- YAML files -------------------------------------------------------------------------------
ERROR_KEYS = [
    "dphi_y1", "dphi_z2_arcsec", "dalpha_x1_arcmin", "dalpha_z1_deg", "dalpha_x2_rad", "deps_x",
    "deps_y_arcsec", "deta", "deta_mm", "deta_m", "deta_um", "dphi_y1_arcsec", "dalpha_y2",
    "deta_deg", "dphi_y1_mm", "dphi", "errors", "", "DPHI_Y1",
]  # fmt: skip
yaml_scalar = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(-1e4, 1e4),
    st.integers(-(2**70), 2**70),
    st.booleans(),
    st.none(),
    st.text(max_size=6),
    st.sampled_from(SPECIAL_NUMBERS),
)
yaml_value = st.recursive(
    yaml_scalar,
    lambda inner: st.one_of(
        st.lists(inner, max_size=3), st.dictionaries(st.text(max_size=4), inner, max_size=3)
    ),
    max_leaves=4,
)


@st.composite
def yaml_text(draw, document) -> str:
    """A YAML text of ``document``, sometimes with a line repeated or replaced by noise."""
    text = yaml.safe_dump(draw(document), sort_keys=False, allow_unicode=True)
    lines = text.splitlines()
    kind = draw(st.sampled_from(["as is", "as is", "repeat", "noise"]))
    if lines and kind != "as is":
        i = draw(st.integers(0, len(lines) - 1))
        if kind == "repeat":
            lines.insert(i, lines[i])
        else:
            lines[i] = draw(st.text(max_size=12))
    return "\n".join(lines) + "\n"


def _errors_mapping():
    entries = st.dictionaries(
        st.one_of(st.sampled_from(ERROR_KEYS), st.text(max_size=5)), yaml_value, max_size=5
    )
    return st.one_of(
        entries,
        entries.map(lambda e: {"errors": e}),
        st.tuples(entries, st.text(max_size=5), yaml_value).map(
            lambda t: {"errors": t[0], t[1]: t[2]}
        ),
        yaml_value,
    )


@fuzz(60)
@given(text=yaml_text(_errors_mapping()))
def test_errors_yaml(scratch, text):
    folder = example_folder(scratch)
    path = folder / "errors.yaml"
    path.write_text(text, encoding="utf-8")
    run_and_check(folder, ["orientation", "--errors", str(path), "--phi1-deg", "30"], "errors.yaml")


def _gyrowheel_mapping():
    nominal = yaml.safe_load((EXAMPLES_DIR.parent / "gyrowheel_nominal.yaml").read_text())

    @st.composite
    def changed(draw):
        data = {axis: dict(values) for axis, values in nominal.items()}
        for _ in range(draw(st.integers(1, 3))):
            axis = draw(st.sampled_from(["x", "y", "z"]))
            block = data.setdefault(axis, {})
            if isinstance(block, dict):
                key = draw(st.one_of(st.sampled_from(["DF", "x", "y", "z", "xx", "yy", "zz", "xy",
                                                      "yx"]), st.text(max_size=3)))  # fmt: skip
                if draw(st.booleans()):
                    block[key] = draw(yaml_value)
                else:
                    block.pop(key, None)
            else:
                data[axis] = draw(yaml_value)
        return data

    return st.one_of(changed(), yaml_value)


@fuzz(40)
@given(text=yaml_text(_gyrowheel_mapping()))
def test_gyrowheel_yaml(scratch, text):
    folder = example_folder(scratch)
    path = folder / "gyrowheel.yaml"
    path.write_text(text, encoding="utf-8")
    args = ["rate-error", "--gyrowheel", str(path), "--dpsi-deg", "0.01", "--positions", "grid:45"]
    run_and_check(folder, args, "gyrowheel.yaml")


def _lower_bounds_mapping():
    bounds = st.dictionaries(
        st.one_of(st.sampled_from(ERROR_KEYS), st.text(max_size=5)), yaml_value, max_size=4
    )
    reasoning = st.dictionaries(
        st.one_of(st.sampled_from(["dphi_y1", "deps_x", "deta"]), st.text(max_size=4)),
        yaml_value,
        max_size=2,
    )
    return st.one_of(
        st.fixed_dictionaries({"lower_bounds": bounds}),
        st.fixed_dictionaries({"lower_bounds": bounds, "reasoning": reasoning}),
        st.tuples(bounds, st.text(max_size=5), yaml_value).map(
            lambda t: {"lower_bounds": t[0], t[1]: t[2]}
        ),
        yaml_value,
    )


@fuzz(15)
@given(text=yaml_text(_lower_bounds_mapping()))
def test_lower_bounds_yaml(scratch, text):
    folder = example_folder(scratch)
    path = folder / "bounds.yaml"
    path.write_text(text, encoding="utf-8")
    args = ["allocate", "--limits-arcmin", "2", "--lower-bounds", str(path)]
    run_and_check(folder, args, "bounds.yaml")


# ---- numeric options --------------------------------------------------------------------------
FAST_OPTIONS = [
    # (command and fixed arguments, option); the value is fuzzed as --option=VALUE
    (["orientation"], "--phi1-deg"),
    (["orientation"], "--phi2-deg"),
    (["rate-error", "--positions", "grid:45"], "--dpsi-deg"),
    (["rate-error", "--positions", "grid:45"], "--dtheta-deg"),
    (["rate-error", "--positions", "grid:45"], "--dgamma-deg"),
    (["rate-error", "--positions", "grid:45"], "--latitude-deg"),
    (["calibrate", str(EXAMPLES_DIR / "gyrowheel_run_example.csv")], "--latitude-deg"),
    (["simulate", "--phi1-step-deg", "90", "--phi2-step-deg", "90"], "--seed"),
    (["simulate", "--phi1-step-deg", "90", "--phi2-step-deg", "90"], "--noise-arcsec"),
    (["simulate", "--phi1-step-deg", "90", "--phi2-step-deg", "90"], "--dwell-s"),
    (["simulate", "--phi2-step-deg", "90"], "--phi1-step-deg"),
    (["simulate", "--phi1-step-deg", "90", "--phi2-step-deg", "90"], "--repeats"),
]


def _number(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def _not_a_large_count(text: str, largest: int) -> bool:
    """Whether ``text`` is refused as a count or is a count of at most ``largest``."""
    number = _number(text)
    return number is None or not math.isfinite(number) or number <= largest or number % 1 != 0


@fuzz(120)
@given(case=st.sampled_from(FAST_OPTIONS), value=number_text)
def test_numeric_options(scratch, case, value):
    fixed, option = case
    if option == "--phi1-step-deg":  # keep the simulated runs small
        number = _number(value)
        assume(number is None or not 0 < number < 30)
    if option == "--repeats":
        assume(_not_a_large_count(value, 20))
    folder = example_folder(scratch)
    args = [*fixed, f"{option}={value}"]
    outputs = ()
    if fixed[0] == "simulate":
        args += ["-o", str(folder / "out.csv")]
        outputs = ("out.csv",)
    run_and_check(folder, args, option, outputs=outputs)


@fuzz(25)
@given(value=number_text)
def test_fit_k_sigma(scratch, value):
    folder = example_folder(scratch)
    path = folder / "data.csv"
    path.write_text(MEASUREMENTS)
    run_and_check(folder, ["fit", str(path), f"--k-sigma={value}"], "--k-sigma")


@fuzz(15)
@given(
    option=st.sampled_from(["--limits-deg", "--limits-arcmin"]),
    value=st.one_of(
        number_text,
        st.tuples(number_text, number_text, number_text).map(
            lambda t: f"psi={t[0]},theta={t[1]},gamma={t[2]}"
        ),
    ),
)
def test_allocate_limits(scratch, option, value):
    folder = example_folder(scratch)
    run_and_check(folder, ["allocate", f"{option}={value}"], option)


@fuzz(10)
@given(
    option=st.sampled_from(["-n", "--seed", "--grid-step-deg", "--scale-bounds"]),
    value=number_text,
)
def test_montecarlo_options(scratch, option, value):
    number = _number(value)
    if option == "-n":  # small runs only (sizes are checked elsewhere)
        assume(_not_a_large_count(value, 50))
    if option == "--grid-step-deg":
        assume(number is None or not 0 < number < 5)
    folder = example_folder(scratch)
    base = ["montecarlo", "--limits-arcmin", "1", "--quiet", "-n", "20"]
    run_and_check(folder, [*base, f"{option}={value}"], option)


@fuzz(40)
@given(
    item=st.one_of(
        st.tuples(st.sampled_from(ERROR_KEYS), number_text).map(lambda t: f"{t[0]}={t[1]}"),
        st.text(max_size=10),
    )
)
def test_error_option(scratch, item):
    folder = example_folder(scratch)
    run_and_check(folder, ["orientation", f"--error={item}"], "--error")

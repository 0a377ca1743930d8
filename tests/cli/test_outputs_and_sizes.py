"""Nothing lost, nothing runaway: a command never writes over one of its inputs, and a run too big
for memory is refused up front, saying what it would need."""

import os
import shutil

import numpy as np
import pytest

from conftest import EXAMPLES_DIR, cli, write_file
from turntable_pin.core.exceptions import InputError
from turntable_pin.core.sizes import check_count, turn_grid_count

ERRORS = EXAMPLES_DIR / "errors_example.yaml"
DATA = EXAMPLES_DIR / "measurements_example.csv"
BOUNDS = EXAMPLES_DIR.parent / "manufacturing_lower_bounds.yaml"
URDF = EXAMPLES_DIR.parent / "turntable.urdf"
MMT = EXAMPLES_DIR / "mmt_pointing" / "k_and_e.dat"


def _copy(tmp_path, source):
    target = tmp_path / source.name
    shutil.copyfile(source, target)
    return target


# (command line with {in} standing for the input copy, the input file)
WRITERS = [
    (["urdf", "--errors", "{in}", "-o", "{in}"], ERRORS),
    (["urdf", "--urdf", "{in}", "-o", "{in}"], URDF),
    (["orientation", "--errors", "{in}"], None),  # writes nothing: never refused
    (["simulate", "--errors", "{in}", "-o", "{in}"], ERRORS),
    (["simulate", "--urdf", "{in}", "-o", "{in}"], URDF),
    (["report", "{in}", "-o", "{in}"], DATA),
    (["fit", "{in}", "--plots", "{in}"], DATA),
    (["fit", "{in}", "--write-urdf", "{in}"], DATA),  # the data were lost to a URDF
    (["fit", DATA.as_posix(), "--urdf", "{in}", "--write-urdf", "{in}"], URDF),
    (["import-tpoint", "{in}", "-o", "out.csv", "--write-urdf", "{in}"], MMT),
    (["diagnose", "{in}", "--plots", "{in}"], DATA),
    (["allocate", "--lower-bounds", "{in}", "--plots", "{in}"], BOUNDS),
    (["montecarlo", "-n", "10", "--lower-bounds", "{in}", "--plots", "{in}"], BOUNDS),
    (["snapshot", "--errors", "{in}", "-o", "{in}"], ERRORS),
    (["design", "--urdf", "{in}", "-o", "{in}"], URDF),
    (["design", "--from", "{in}", "--plots", "{in}"], DATA),
]


@pytest.mark.parametrize("argv, source", [w for w in WRITERS if w[1] is not None])
def test_every_writer_refuses_an_output_that_is_an_input(tmp_path, argv, source):
    original = _copy(tmp_path, source)
    before = (original.read_bytes(), original.stat().st_mtime_ns)
    proc = cli(*[str(original) if a == "{in}" else a for a in argv])
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "refusing to write" in lines[0] and str(original) in lines[0]
    assert (original.read_bytes(), original.stat().st_mtime_ns) == before


def test_a_link_to_the_input_is_the_input(tmp_path):
    original = _copy(tmp_path, ERRORS)
    link = tmp_path / "looks_new.urdf"
    os.symlink(original, link)
    proc = cli("urdf", "--errors", str(original), "-o", str(link))
    assert proc.returncode == 2 and "refusing to write" in proc.stderr
    assert original.read_bytes() == ERRORS.read_bytes()


def test_a_distinct_output_is_written(tmp_path):
    original = _copy(tmp_path, ERRORS)
    proc = cli("urdf", "--errors", str(original), "-o", str(tmp_path / "out.urdf"))
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "out.urdf").read_text().startswith("<?xml")


@pytest.mark.parametrize(
    "argv, what",
    [
        (["simulate", "--phi1-step-deg", "1e-3", "-o", "{out}"], "rows of simulated"),
        (["rate-error", "--positions", "grid:0.1", "--dpsi-deg", "0.01"], "positions"),
        (["rate-error", "--positions", "grid:1e-300", "--dpsi-deg", "0.01"], "positions"),
        (["requirement", "--positions", "grid:0.5"], "positions"),
        (["montecarlo", "-n", "1000000000000", "--seed", "1"], "random turntables"),
    ],
)
def test_runaway_sizes_are_refused_up_front_with_what_they_need(tmp_path, argv, what):
    out = tmp_path / "never.csv"
    proc = cli(*[str(out) if a == "{out}" else a for a in argv])
    assert proc.returncode == 2, proc.stderr
    line = proc.stderr.strip()
    assert "\n" not in line and what in line and "at most" in line
    assert not out.exists()


def test_check_count_states_the_need_and_accepts_the_limit():
    assert check_count(200_000, 200_000, "positions") == 200_000
    with pytest.raises(InputError, match=r"200,001 positions would be needed, about 0\.8 GB"):
        check_count(200_001, 200_000, "positions", 4000)
    with pytest.raises(InputError, match="at most 10 are accepted"):
        check_count(float("inf"), 10, "rows")


@pytest.mark.parametrize("step", [0.7, 1.0, 7.5, 30.0, 45.0, 360.0, 1e-3])
def test_turn_grid_count_is_the_length_of_the_grids(step):
    assert turn_grid_count(step) == np.arange(0.0, 360.0 - 1e-9, step).size


def test_diagnosis_and_fit_refuse_more_rows_than_their_limit(monkeypatch, tmp_path):
    import turntable_pin.measurement.diagnosis as diagnosis
    import turntable_pin.measurement.fit as fit

    monkeypatch.setattr(diagnosis, "MAX_DIAGNOSED_ROWS", 100)
    monkeypatch.setattr(fit, "MAX_FITTED_ROWS", 100)
    for command in ("diagnose", "fit"):
        proc = cli(command, str(DATA))
        assert proc.returncode == 2
        assert "144 measurement rows would be needed" in proc.stderr, proc.stderr


def test_rows_at_one_position_get_a_design_warning(tmp_path):
    rng = np.random.default_rng(4)
    rows = ["phi1_deg,phi2_deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec,sigma_arcsec,time_s,dir1"]
    for i in range(144):
        noise = rng.normal(0.0, 1.0, 3)
        step = 2.0 * (i % 2)  # the table's position error changes between the approaches
        rows.append(
            f"30,45,{noise[0] + step:.3f},{noise[1]:.3f},{noise[2]:.3f},1,{60 * i},"
            f"{1 if i % 2 else -1}"
        )
    path = write_file(tmp_path, "\n".join(rows) + "\n")
    proc = cli("diagnose", str(path), "--json")
    assert proc.returncode == 0, proc.stderr
    import json

    out = json.loads(proc.stdout)
    assert len(out["warnings"]) == 1
    assert "all 144 rows are at one position" in out["warnings"][0]
    assert "determine 3 of the 5 combinations" in out["warnings"][0]
    text = cli("diagnose", str(path)).stdout
    assert "warning: all 144 rows are at one position" in text


def test_a_full_grid_gets_no_design_warning():
    import json

    out = json.loads(cli("diagnose", str(DATA), "--json").stdout)
    assert out["warnings"] == []


def _command_actions(command: str):
    """The argparse actions of ``command``'s own parser."""
    import argparse

    from turntable_pin.cli import build_parser

    parser = build_parser(command)
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices[command]._actions


def _guard_cases():
    """(command, output option, input option or positional) for every command's parser."""
    from pathlib import Path

    from turntable_pin.cli import COMMANDS
    from turntable_pin.cli.common import OUTPUT_OPTIONS, input_path

    cases = []
    for command in COMMANDS:
        actions = _command_actions(command)
        outputs = [a for a in actions if a.dest in OUTPUT_OPTIONS]
        inputs = [a for a in actions if a.dest not in OUTPUT_OPTIONS
                  and a.type in (Path, input_path)]  # fmt: skip
        cases += [(command, o.dest, i.dest) for o in outputs for i in inputs]
    return cases


@pytest.mark.parametrize("command, output, source", _guard_cases())
def test_every_output_option_of_every_command_refuses_every_input(
    tmp_path, command, output, source
):
    # Issue 18: one guard for every command, every output option against every input option.
    import contextlib
    import io

    from turntable_pin.cli import main

    target = tmp_path / "file.txt"
    target.write_text("an input that must survive\n")
    argv = [command]
    for action in _command_actions(command):
        flag = action.option_strings[-1] if action.option_strings else None
        if action.dest in (output, source):
            argv += [flag, str(target)] if flag else [str(target)]
        elif flag is None and action.dest not in ("help",):  # another positional: a file
            argv.append(str(tmp_path / f"other_{action.dest}.csv"))
        elif action.required:
            value = action.choices[0] if action.choices else str(tmp_path / f"{action.dest}.out")
            argv += [flag, str(value)]
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr):
        status = main(argv)
    assert status == 2, (argv, stderr.getvalue())
    assert "refusing to write" in stderr.getvalue(), stderr.getvalue()
    assert target.read_text() == "an input that must survive\n"

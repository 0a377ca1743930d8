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
EFFECT = EXAMPLES_DIR / "effects" / "inner_encoder_3rev.yaml"
RUN = EXAMPLES_DIR / "gyrowheel_run_example.csv"


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
    # issue 27: files named inside an option's text are inputs too
    (["fit", DATA.as_posix(), "--effects", "{in}", "--write-urdf", "{in}"], EFFECT),
    (["fit", DATA.as_posix(), "--effects", "base_tilt,{in}", "--plots", "{in}"], EFFECT),
    (["design", "--effects", "{in}", "-n", "12", "-o", "{in}"], EFFECT),
    (
        ["design", "--separate", "{in},base_tilt", "--amplitude", "base_tilt:x=1", "-o", "{in}"],
        EFFECT,
    ),  # fmt: skip
    (["design", "--separate", "TF,base_tilt", "--amplitude", "{in}:c3=1", "-o", "{in}"], EFFECT),
    (["simulate", "--effect", "{in}:c3=1", "-o", "{in}"], EFFECT),
    (
        ["simulate", "--catalogue", "{in}", "--effect", "inner_encoder_3rev:c3=1", "-o", "{in}"],
        EFFECT,
    ),  # fmt: skip
    (["requirement", "--positions", "{in}", "--plots", "{in}"], DATA),
    (["allocate", "--positions", "{in}", "--plots", "{in}"], DATA),
]


@pytest.mark.parametrize("argv, source", [w for w in WRITERS if w[1] is not None])
def test_every_writer_refuses_an_output_that_is_an_input(tmp_path, argv, source):
    original = _copy(tmp_path, source)
    before = (original.read_bytes(), original.stat().st_mtime_ns)
    proc = cli(*[a.replace("{in}", str(original)) for a in argv])
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
    "argv, what, limit",
    [
        (["simulate", "--phi1-step-deg", "1e-3", "-o", "{out}"], "rows of simulated", "at most"),
        (["rate-error", "--positions", "grid:0.1", "--dpsi-deg", "0.01"], "positions", "at most"),
        # below the finest grid step there is no count to estimate: the step itself is refused
        (["rate-error", "--positions", "grid:1e-300", "--dpsi-deg", "0.01"], "grid:1e-300",
         "grid step must be in [1e-06, 360] degrees"),
        (["requirement", "--positions", "grid:0.5"], "positions", "at most"),
        (["montecarlo", "-n", "1000000000000", "--seed", "1"], "random turntables", "at most"),
    ],
)  # fmt: skip
def test_runaway_sizes_are_refused_up_front_with_what_they_need(tmp_path, argv, what, limit):
    out = tmp_path / "never.csv"
    proc = cli(*[str(out) if a == "{out}" else a for a in argv])
    assert proc.returncode == 2, proc.stderr
    line = proc.stderr.strip()
    assert "\n" not in line and what in line and limit in line
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
    import turntable_pin.measurement.fit as fit
    import turntable_pin.stats.diagnosis_engine as diagnosis

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


def _argv(command: str, given: dict[str, str], tmp_path) -> list[str]:
    """A command line of ``command`` with the options (dests) ``given``, every other positional a
    file name in ``tmp_path`` and every other required option a value."""
    argv = [command]
    for action in _command_actions(command):
        flag = action.option_strings[-1] if action.option_strings else None
        if action.dest in given:
            argv += [flag, given[action.dest]] if flag else [given[action.dest]]
        elif flag is None and action.dest not in ("help",):  # another positional: a file
            argv.append(str(tmp_path / f"other_{action.dest}.csv"))
        elif action.required:
            value = action.choices[0] if action.choices else str(tmp_path / f"{action.dest}.out")
            argv += [flag, str(value)]
    return argv


def _main(argv: list[str]) -> tuple[int, str]:
    """``turntable-pin ARGV`` in this process: the exit status and stderr."""
    import contextlib
    import io

    from turntable_pin.cli import main

    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(io.StringIO()):
        status = main(argv)
    return status, stderr.getvalue()


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
    argv = _argv(command, {output: str(target), source: str(target)}, tmp_path)
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr):
        status = main(argv)
    assert status == 2, (argv, stderr.getvalue())
    assert "refusing to write" in stderr.getvalue(), stderr.getvalue()
    assert target.read_text() == "an input that must survive\n"


# --- issue 27, second sweep: files named inside an option's text are inputs ---------------------
def _text_input_cases():
    """(command, output option, option whose text names input files, its text) for every
    command's parser; {f} stands for the file."""
    from turntable_pin.cli import COMMANDS
    from turntable_pin.cli.common import OUTPUT_OPTIONS, effect_list, effect_spec, position_scheme

    texts = {effect_list: "base_tilt,{f}", effect_spec: "{f}:c3=1", position_scheme: "{f}"}
    cases = []
    for command in COMMANDS:
        actions = _command_actions(command)
        outputs = [a.dest for a in actions if a.dest in OUTPUT_OPTIONS]
        named = [(a.dest, texts[a.type]) for a in actions if a.type in texts]
        cases += [(command, o, dest, text) for o in outputs for dest, text in named]
    return cases


def test_the_options_that_name_files_inside_their_text_are_all_known():
    found = {(command, dest) for command, _, dest, _ in _text_input_cases()}
    assert found == {
        ("fit", "effects"),
        ("design", "effects"),
        ("design", "separate"),
        ("design", "amplitude"),
        ("simulate", "effect"),
        ("requirement", "positions"),
        ("allocate", "positions"),
        ("montecarlo", "positions"),
    }


@pytest.mark.parametrize("command, output, source, text", _text_input_cases())
def test_every_output_refuses_a_file_named_inside_an_option(
    tmp_path, command, output, source, text
):
    name = "positions.csv" if source == "positions" else "mine.yaml"
    target = tmp_path / name
    target.write_text("an input that must survive\n")
    given = {output: str(target), source: text.format(f=target)}
    status, stderr = _main(_argv(command, given, tmp_path))
    assert status == 2, stderr
    assert f"refusing to write --{output.replace('_', '-')} {target}: it is --{source}" in stderr
    assert target.read_text() == "an input that must survive\n"


# --- every output checked before any is written ---------------------------------------------
def _bad_output(tmp_path, kind: str, folder: bool):
    """An output path that cannot be written, of ``kind``."""
    path = tmp_path / f"bad_{kind}"
    if kind == "wrong kind":  # a folder where a file is expected, or the reverse
        path.mkdir() if not folder else path.write_text("a file\n")
    elif kind == "under a file":
        (tmp_path / "afile").write_text("a file\n")
        path = tmp_path / "afile" / "out"
    elif kind == "write-protected":
        path.write_text("protected\n")
        path.chmod(0o444)
    elif kind == "link to nothing":
        path.symlink_to(tmp_path / "nowhere")
    return path


BAD_OUTPUTS = ("wrong kind", "under a file", "write-protected", "link to nothing")
MESSAGES = {
    "wrong kind": "it is a f",
    "under a file": "afile is a file, not a folder",
    "write-protected": "permission denied (the file is write-protected, mode 0444)",
    "link to nothing": "which does not exist",
}


def _output_cases():
    from turntable_pin.cli import COMMANDS
    from turntable_pin.cli.common import FOLDER_OUTPUTS, OUTPUT_OPTIONS

    cases = []
    for command in COMMANDS:
        for action in _command_actions(command):
            if action.dest in OUTPUT_OPTIONS:
                folder = action.dest in FOLDER_OUTPUTS
                kinds = [k for k in BAD_OUTPUTS if not (folder and k == "write-protected")]
                cases += [(command, action.dest, kind) for kind in kinds]
    return cases


@pytest.mark.parametrize("command, output, kind", _output_cases())
def test_every_output_of_every_command_is_checked_before_the_command_runs(
    tmp_path, command, output, kind
):
    from turntable_pin.cli.common import FOLDER_OUTPUTS

    bad = _bad_output(tmp_path, kind, output in FOLDER_OUTPUTS)
    status, stderr = _main(_argv(command, {output: str(bad)}, tmp_path))
    assert status == 2
    lines = stderr.strip().splitlines()
    assert (
        len(lines) == 1 and f"error: --{output.replace('_', '-')} {bad}: cannot write" in lines[0]
    )
    assert MESSAGES[kind] in lines[0], lines[0]


# Every command that writes two outputs (its own run: the data exist; {a} and {b} the outputs).
TWO_OUTPUTS = {
    "simulate": ["simulate", "--run", "-o", "{output}", "--truth", "{truth}"],
    "fit": ["fit", DATA.as_posix(), "--plots", "{plots}", "--write-urdf", "{write_urdf}"],
    "import-tpoint": [
        "import-tpoint",
        MMT.as_posix(),
        "-o",
        "{output}",
        "--write-urdf",
        "{write_urdf}",
    ],  # fmt: skip
    "design": ["design", "-n", "6", "-o", "{output}", "--plots", "{plots}"],
    "calibrate": [
        "calibrate",
        RUN.as_posix(),
        "--diagnose",
        "--plots",
        "{plots}",
        "--report",
        "{report}",
    ],  # fmt: skip
}


def test_every_command_with_two_outputs_is_listed():
    from turntable_pin.cli import COMMANDS
    from turntable_pin.cli.common import OUTPUT_OPTIONS

    two = {c for c in COMMANDS
           if sum(a.dest in OUTPUT_OPTIONS for a in _command_actions(c)) > 1}  # fmt: skip
    assert two == set(TWO_OUTPUTS)


def _two_output_cases():
    from turntable_pin.cli.common import FOLDER_OUTPUTS

    cases = []
    for command, argv in TWO_OUTPUTS.items():
        outputs = [a[1:-1] for a in argv if a.startswith("{")]
        for bad in outputs:
            kinds = [
                k for k in BAD_OUTPUTS if not (bad in FOLDER_OUTPUTS and k == "write-protected")
            ]
            cases += [(command, bad, kind) for kind in kinds]
    return cases


@pytest.mark.parametrize("command, bad, kind", _two_output_cases())
def test_a_refused_output_leaves_the_other_output_as_it_was(tmp_path, command, bad, kind):
    # simulate --run -o S.csv --truth DIR wrote S.csv, then refused DIR: S.csv's earlier contents
    # were lost. Now nothing is written unless every output can be.
    from turntable_pin.cli.common import FOLDER_OUTPUTS

    argv = TWO_OUTPUTS[command]
    good = next(a[1:-1] for a in argv if a.startswith("{") and a[1:-1] != bad)
    earlier = tmp_path / "earlier"
    if good in FOLDER_OUTPUTS:  # a folder of figures made earlier
        earlier.mkdir()
        (earlier / "residuals.png").write_text("an earlier figure\n")
    else:
        earlier.write_text("earlier contents\n")
    snapshot = sorted(
        (str(p), p.read_text()) for p in [earlier, *earlier.rglob("*")] if p.is_file()
    )
    path = _bad_output(tmp_path, kind, bad in FOLDER_OUTPUTS)
    values = {good: str(earlier), bad: str(path)}
    proc = cli(*[values[a[1:-1]] if a.startswith("{") else a for a in argv])
    assert proc.returncode == 2, proc.stderr
    assert f"--{bad.replace('_', '-')} {path}: cannot write" in proc.stderr
    after = sorted((str(p), p.read_text()) for p in [earlier, *earlier.rglob("*")] if p.is_file())
    assert after == snapshot


# --- a write-protected output, an output through a link ------------------------------------
def test_a_write_protected_output_is_refused_and_kept(tmp_path):
    keep = tmp_path / "keep.csv"
    keep.write_text("earlier run\n")
    keep.chmod(0o444)
    proc = cli("simulate", "--run", "-o", str(keep))
    assert proc.returncode == 2
    assert proc.stderr.strip() == (
        f"turntable-pin simulate: error: --output {keep}: cannot write the file: permission "
        "denied (the file is write-protected, mode 0444)"
    )
    assert keep.read_text() == "earlier run\n" and keep.stat().st_mode & 0o777 == 0o444
    keep.chmod(0o640)  # writable: replaced, and its mode kept
    assert cli("simulate", "--run", "-o", str(keep)).returncode == 0
    assert keep.read_text().startswith("#") and keep.stat().st_mode & 0o777 == 0o640


@pytest.mark.parametrize(
    "argv",
    [
        ["urdf", "-o", "{link}"],
        ["simulate", "-o", "{link}"],
        ["simulate", "--run", "-o", "{link}"],
        ["import-tpoint", MMT.as_posix(), "-o", "{link}"],
        ["fit", DATA.as_posix(), "--write-urdf", "{link}"],
        ["design", "-n", "6", "-o", "{link}"],
        ["report", DATA.as_posix(), "-o", "{link}"],
    ],
)
def test_an_output_that_is_a_link_is_written_through_to_its_target(tmp_path, argv):
    real = tmp_path / "kept" / "real.out"
    real.parent.mkdir()
    real.write_text("earlier\n")
    link = tmp_path / "link.out"
    link.symlink_to(real)
    proc = cli(*[str(link) if a == "{link}" else a for a in argv])
    assert proc.returncode == 0, proc.stderr
    assert link.is_symlink() and link.resolve() == real.resolve()
    assert real.read_text() != "earlier\n"
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["kept", "link.out", "real.out"]


def test_a_plots_folder_that_is_a_link_fills_its_target(tmp_path):
    real = tmp_path / "figures"
    real.mkdir()
    (tmp_path / "plots").symlink_to(real)
    proc = cli("fit", str(DATA), "--plots", str(tmp_path / "plots"))
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "plots").is_symlink() and (real / "residuals.png").is_file()

"""User code at the seam, at the command line: a Python effect module that breaks its contract,
raises or exits ends every command that takes it in one line and exit status 2 naming the file
and the effect (the traceback only with TURNTABLE_PIN_TRACEBACK=1); a module effect named like a
catalogued one is refused, naming both definitions."""

import pytest

from conftest import EXAMPLES_DIR, REPO_DIR, cli, refused, write_file
from effect_modules import (
    ORIENTATION_PARAMETERS,
    ORIENTATION_TERMS,
    RUN_COLUMNS,
    RUN_PARAMETERS,
    orientation_module,
    run_module,
)

RUN = EXAMPLES_DIR / "runs" / "run_clean.csv"
DATA = EXAMPLES_DIR / "measurements_example.csv"

RUN_BREAKS = {
    "wrong shape": (RUN_PARAMETERS, "return np.zeros((n, 2))"),
    "NaN": (RUN_PARAMETERS, "return np.full((n, 2, 1), np.nan)"),
    "inf": (RUN_PARAMETERS, "return np.full((n, 2, 1), np.inf)"),
    "a plain number": (RUN_PARAMETERS, "return 1.0"),
    "no parameter": ("return ()", RUN_COLUMNS),
    "raises": (RUN_PARAMETERS, "raise ValueError('oops')"),
}
ORIENTATION_BREAKS = {
    "wrong shape": (
        ORIENTATION_PARAMETERS,
        ORIENTATION_TERMS.replace("np.cos(3 * a)", "np.ones(64)"),
    ),
    "NaN": (ORIENTATION_PARAMETERS, ORIENTATION_TERMS.replace("np.cos(3 * a)", "a * np.nan")),
    "inf": (ORIENTATION_PARAMETERS, ORIENTATION_TERMS.replace("np.cos(3 * a)", "a * np.inf")),
    "a plain number": (ORIENTATION_PARAMETERS, "return 1.0"),
    "no parameter": ("return ()", ORIENTATION_TERMS),
    "unknown parameter": (ORIENTATION_PARAMETERS, ORIENTATION_TERMS.replace('"c3"', '"zz"')),
    "raises": (ORIENTATION_PARAMETERS, "raise ValueError('oops')"),
}
RUN_COMMANDS = {
    "calibrate --diagnose": ["calibrate", str(RUN), "--diagnose"],
    "calibrate --effects": ["calibrate", str(RUN), "--effects", "cable_drag"],
    "design --separate --run": [
        "design",
        "--separate",
        "cable_drag,instrument_tilt",
        "--run",
        str(RUN),
        "-n",
        "3",
        "--candidates",
        "200",
    ],  # fmt: skip
}
ORIENTATION_COMMANDS = {
    "fit --effects": ["fit", str(DATA), "--effects", "lobes", "--effects-module"],
    "diagnose --catalogue": ["diagnose", str(DATA), "--catalogue"],
}


@pytest.mark.parametrize("command", RUN_COMMANDS)
@pytest.mark.parametrize("break_", RUN_BREAKS)
def test_a_broken_run_effect_module_is_one_line(tmp_path, command, break_):
    module = write_file(tmp_path, run_module(*RUN_BREAKS[break_]), "cable.py")
    out = tmp_path / "positions.csv"
    args = [*RUN_COMMANDS[command], "--effects-module", str(module)]
    if command.startswith("design"):
        args += ["-o", str(out)]
    line = refused(cli(*args), str(module), "effect 'cable_drag' (class CableDrag)")
    assert ("raised ValueError: oops" in line) == (break_ == "raises")
    assert not out.exists()


@pytest.mark.parametrize("command", ORIENTATION_COMMANDS)
@pytest.mark.parametrize("break_", ORIENTATION_BREAKS)
def test_a_broken_orientation_effect_module_is_one_line(tmp_path, command, break_):
    module = write_file(tmp_path, orientation_module(*ORIENTATION_BREAKS[break_]), "lobes.py")
    line = refused(cli(*ORIENTATION_COMMANDS[command], str(module)), str(module),
                     "effect 'lobes' (class Lobes)")  # fmt: skip
    if break_ == "raises":
        assert f"{module}, line 15: " in line and "raised ValueError: oops" in line


def test_the_traceback_only_on_request(tmp_path, monkeypatch):
    module = write_file(tmp_path, orientation_module(terms="raise ValueError('oops')"), "lobes.py")
    args = ["fit", str(DATA), "--effects", "lobes", "--effects-module", str(module)]
    line = refused(cli(*args), "TURNTABLE_PIN_TRACEBACK=1 shows the traceback")
    monkeypatch.setenv("TURNTABLE_PIN_TRACEBACK", "1")
    proc = cli(*args)
    assert proc.returncode == 2 and proc.stderr.splitlines()[-1] == line
    assert "Traceback (most recent call last)" in proc.stderr
    assert f'File "{module}", line 15, in chain_terms' in proc.stderr


@pytest.mark.parametrize("command", ["fit", "diagnose", "calibrate"])
def test_a_module_that_calls_sys_exit_at_import_is_refused(tmp_path, command):
    module = write_file(tmp_path, "import sys\n\nsys.exit(0)\n", "leaves.py")
    args = {
        "fit": ["fit", str(DATA), "--effects-module", str(module)],
        "diagnose": ["diagnose", str(DATA), "--catalogue", str(module)],
        "calibrate": ["calibrate", str(RUN), "--diagnose", "--effects-module", str(module)],
    }[command]
    refused(cli(*args), f"{module}, line 3: cannot import it: it called sys.exit(0) while being "
              "imported")  # fmt: skip


def test_ctrl_c_in_a_module_still_interrupts(tmp_path):
    module = write_file(tmp_path, "raise KeyboardInterrupt\n", "stops.py")
    proc = cli("diagnose", str(DATA), "--catalogue", str(module))
    assert proc.returncode == 130 and "interrupted" in proc.stderr


def test_a_run_effect_named_like_a_catalogued_one_no_longer_relabels_the_side(tmp_path):
    module = write_file(tmp_path, run_module(name="bias_drift"), "drift.py")
    proc = cli("calibrate", str(EXAMPLES_DIR / "runs" / "run_bias_drift.csv"), "--diagnose",
               "--effects-module", str(module))  # fmt: skip
    refused(proc, f"{module} (class CableDrag): effect 'bias_drift' is already in the "
              "catalogue (turntable_pin.instrument.effects.bias_drift.BiasDrift)")  # fmt: skip


@pytest.mark.parametrize("where", ["module", "catalogue"])
def test_orientation_effects_of_one_name_are_refused_naming_both(tmp_path, where):
    module = write_file(tmp_path, orientation_module(name="backlash"), "lobes.py")
    if where == "module":
        proc = cli("fit", str(DATA), "--effects-module", str(module), "--effects", "backlash")
        refused(proc, f"{module} (class Lobes): effect 'backlash' is already in the catalogue")
        return
    mine = write_file(tmp_path, orientation_module(), "mine.py")
    yaml = write_file(tmp_path, "name: lobes\nterms: [dphi_z2~h3(phi2)]\n", "lobes.yaml")
    proc = cli("diagnose", str(DATA), "--catalogue", str(yaml), "--catalogue", str(mine))
    refused(proc, f"{mine} (class Lobes): effect 'lobes' is also defined by {yaml}, line 1")
    proc = cli("fit", str(DATA), "--effects-module", str(mine), "--effects", str(yaml))
    refused(proc, f"{yaml}, line 1: effect 'lobes' is also defined by {mine} (class Lobes)")


def test_the_docs_and_the_help_say_a_module_is_code_that_runs():
    docs = (REPO_DIR / "docs" / "measurements.md").read_text()
    assert "**A Python effect module is code that runs.**" in docs
    assert "TURNTABLE_PIN_TRACEBACK=1" in docs
    for command in (["fit"], ["diagnose"], ["calibrate"], ["design"], ["effects"]):
        text = " ".join(cli(*command, "--help").stdout.split())
        assert "code that runs: it is imported and its methods called" in text, command

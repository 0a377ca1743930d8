"""The contract of a run effect the user writes, checked before any fit on a probe of the run's
rows and on the run: every break one UserCodeError naming the file, the effect, the method, what
it returned and what was expected; names of the run catalogue (with or without ``table:``) and
names two effects share refused naming both definitions."""

import numpy as np
import pytest

from conftest import REPO_DIR, write_file
from effect_modules import RUN_COLUMNS, RUN_PARAMETERS, run_module
from turntable_pin.calibration.run import read_run
from turntable_pin.core.exceptions import InputError, UserCodeError
from turntable_pin.instrument.diagnosis import diagnose_run
from turntable_pin.instrument.effects import run_catalogue
from turntable_pin.instrument.model import fit_run
from turntable_pin.instrument.user_effects import (
    check_user_run_effects,
    load_run_effects_modules,
    probe_context,
)

RUN = REPO_DIR / "models" / "examples" / "runs" / "run_clean.csv"

GOOD_PARAMETERS = RUN_PARAMETERS
GOOD_COLUMNS = RUN_COLUMNS
module_text = run_module


@pytest.fixture(scope="module")
def run():
    return read_run(RUN, np.radians(45.75))


BROKEN = [
    (
        GOOD_PARAMETERS,
        "return np.zeros((n, 2))",
        "columns(context) returned an array of shape (7, 2) (float64) on a probe of 7 of the run's "
        "rows; expected an array of shape (7, 2, 1)",
    ),
    (GOOD_PARAMETERS, "return np.ones(64)", "returned an array of shape (64,) (float64)"),
    (GOOD_PARAMETERS, "return np.zeros((64, 2, 1))", "shape (64, 2, 1)"),
    (GOOD_PARAMETERS, "return np.full((n, 2, 1), np.nan)", "returned NaN at 7 of 7 positions"),
    (GOOD_PARAMETERS, "return np.full((n, 2, 1), -np.inf)", "returned inf at 7 of 7 positions"),
    (GOOD_PARAMETERS, "return 1.0", "columns(context) returned float 1.0"),
    (GOOD_PARAMETERS, "return None", "columns(context) returned None"),
    (GOOD_PARAMETERS, 'return "columns"', "columns(context) returned 'columns'"),
    ("return ()", GOOD_COLUMNS, "parameters(run) returned no parameter"),
    ('return ("b",)', GOOD_COLUMNS, "parameters(run) returned 'b' as parameter 1"),
    (
        'return (ParameterSpec("b", "deg/h", 1.0, "d"), ParameterSpec("c", "deg/h", 1.0, "d"))',
        GOOD_COLUMNS,
        "expected an array of shape (7, 2, 2)",
    ),
    (
        'return (ParameterSpec("b", "deg/h", -1.0, "d"),)',
        GOOD_COLUMNS,
        "parameter 'b': per_user_unit is float -1.0",
    ),
    (
        GOOD_PARAMETERS,
        'raise ValueError("oops in columns")',
        "line 17: effect 'cable_drag' (class CableDrag): columns(context) on a probe of 7 of the "
        "run's rows raised ValueError: oops in columns",
    ),
    (
        'raise RuntimeError("oops")',
        GOOD_COLUMNS,
        "line 13: effect 'cable_drag' (class CableDrag): parameters(run) on a probe of 7 of the "
        "run's rows raised RuntimeError: oops",
    ),
    (
        GOOD_PARAMETERS,
        "import sys; sys.exit(0)",
        "columns(context) on a probe of 7 of the run's rows called sys.exit(0)",
    ),
    (
        GOOD_PARAMETERS,
        "return np.zeros((n, 2, 1)) if n < 10 else np.zeros((n, 2))",
        "columns(context) returned an array of shape (144, 2) (float64) on the run (144 positions)",
    ),
]


@pytest.mark.parametrize("parameters, columns, message", BROKEN, ids=range(len(BROKEN)))
def test_a_broken_run_effect_is_refused_in_one_line_before_any_fit(
    tmp_path, run, parameters, columns, message
):
    path = write_file(tmp_path, module_text(parameters, columns), "cable.py")
    with pytest.raises(UserCodeError) as caught:
        load_run_effects_modules([path], run)
    text = str(caught.value)
    assert text.startswith(str(path)) and "\n" not in text
    assert "effect 'cable_drag' (class CableDrag)" in text and message in text, text


def test_a_good_run_effect_passes_and_its_side_is_checked(tmp_path, run):
    (effect,) = load_run_effects_modules([write_file(tmp_path, module_text(), "cable.py")], run)
    assert fit_run(run, [effect]).result.rank == 15
    bad = write_file(tmp_path, module_text(side="gyro"), "side.py")
    with pytest.raises(UserCodeError, match="its side is 'gyro'; expected 'table' or 'instrument'"):
        load_run_effects_modules([bad], run)


@pytest.mark.parametrize(
    "name, catalogued",
    [
        ("bias_drift", "turntable_pin.instrument.effects.bias_drift.BiasDrift"),
        ("backlash", "turntable_pin.instrument.effects.table_side.TableEffect"),
        ("dphi_y1", "turntable_pin.instrument.effects.table_side.TableError"),
        ("instrument_tilt", "turntable_pin.instrument.effects.mount.InstrumentTilt"),
    ],
)
def test_a_run_effect_named_like_a_catalogued_one_is_refused(tmp_path, run, name, catalogued):
    path = write_file(tmp_path, module_text(name=name), "named.py")
    with pytest.raises(InputError) as caught:
        load_run_effects_modules([path], run)
    assert str(caught.value) == (
        f"{path} (class CableDrag): effect '{name}' is already in the catalogue ({catalogued}); "
        "give yours another name"
    )


def test_two_run_effects_of_one_name_are_refused_naming_both(tmp_path, run):
    first = write_file(tmp_path, module_text(), "one.py")
    second = write_file(tmp_path, module_text(), "two.py")
    with pytest.raises(InputError) as caught:
        load_run_effects_modules([first, second], run)
    assert str(caught.value) == (
        f"{second} (class CableDrag): effect 'cable_drag' is also defined by {first} (class "
        "CableDrag); give one of them another name"
    )


def test_a_run_effect_broken_on_the_run_only_is_not_hidden_by_the_diagnosis(tmp_path, run):
    columns = "return np.zeros((n, 2, 1)) if n < 10 else np.full((n, 2, 1), np.nan)"
    path = write_file(tmp_path, module_text(columns=columns), "cable.py")
    from turntable_pin.instrument.effects import RunEffect
    from turntable_pin.measurement.user_effects import load_effects_module

    (effect,) = load_effects_module(path, RunEffect)  # not checked: straight to the library
    with pytest.raises(UserCodeError, match=r"returned NaN at 144 of 144 positions on the run"):
        diagnose_run(run, catalogue=(*run_catalogue(), effect))
    check_user_run_effects([], run)  # nothing to check is fine


def test_the_probe_is_a_few_of_the_runs_rows(run):
    from turntable_pin.instrument.model import run_context

    context = run_context(run)
    probe = probe_context(run, context.coefficients)
    assert probe.run.n_positions == 7 and probe.sensitivity.shape == (7, 2, 3)
    assert np.array_equal(probe.run.joint_rad, run.joint_rad[[0, 3, 6, 9, 12, 15, 18]])


def test_run_and_orientation_effects_share_one_base_and_each_family_loads_its_own(tmp_path):
    """One base class (stats.candidate_effect.CandidateEffect) under both families: a module
    with an orientation effect and a run effect gives each family its own, the run effect's
    story tells its side after its name, and a side the run family does not know is refused."""
    from effect_modules import orientation_module
    from turntable_pin.instrument.effects import RunEffect
    from turntable_pin.measurement.effects.base import Effect
    from turntable_pin.measurement.effects.contract import check_story
    from turntable_pin.measurement.user_effects import load_effects_module
    from turntable_pin.stats.candidate_effect import CandidateEffect

    run_class = "class CableDrag" + run_module().split("class CableDrag", 1)[1]
    imports = "\n\nfrom turntable_pin.instrument.effects import RunEffect\n\n\n"
    text = orientation_module() + imports + run_class
    path = write_file(tmp_path, text, "both.py")
    (lobes,) = load_effects_module(path, Effect)
    (drag,) = load_effects_module(path, RunEffect)
    assert type(lobes).__name__ == "Lobes" and type(drag).__name__ == "CableDrag"
    assert isinstance(lobes, CandidateEffect) and isinstance(drag, CandidateEffect)
    assert not isinstance(drag, Effect) and not isinstance(lobes, RunEffect)
    assert list(drag.describe())[:2] == ["effect", "side"] and drag.describe()["side"] == "table"
    assert "side" not in lobes.describe()
    check_story(drag, RunEffect)
    drag.side = "payload"
    with pytest.raises(UserCodeError, match="its side is 'payload'; expected 'table' or "
                       "'instrument'"):  # fmt: skip
        check_story(drag, RunEffect)

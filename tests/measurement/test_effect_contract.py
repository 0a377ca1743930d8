"""The contract of an orientation effect the user writes, checked once where it enters: on a probe
when it is loaded, on the data where it meets them. Every break is one UserCodeError naming the
file, the effect, the method, what it returned and what was expected -- never a numpy traceback,
and never hidden by a diagnosis as a candidate that "cannot be fitted"."""

import numpy as np
import pytest

from conftest import REPO_DIR, write_file
from effect_modules import ORIENTATION_PARAMETERS, ORIENTATION_TERMS, orientation_module
from turntable_pin.core.exceptions import InputError, UserCodeError
from turntable_pin.measurement.catalogue import catalogue
from turntable_pin.measurement.diagnosis import diagnose_measurements
from turntable_pin.measurement.effect_model import OrientationModel
from turntable_pin.measurement.effects.contract import check_effect, probe_variables
from turntable_pin.measurement.fit import fit_orientation
from turntable_pin.measurement.simulation import simulate_measurements
from turntable_pin.measurement.table import measured_table
from turntable_pin.measurement.user_effects import (
    check_user_effects,
    load_catalogue,
    load_effects_module,
    load_effects_modules,
    read_effect_file,
)
from turntable_pin.model.generic_table import GenericTable

GOOD_PARAMETERS = ORIENTATION_PARAMETERS
GOOD_TERMS = ORIENTATION_TERMS
module_text = orientation_module


def _terms(c3: str, s3: str = "np.sin(3 * a)", site='"dphi_z2", None') -> str:
    return f'return (ChainTerm({site}, {{"c3": {c3}, "s3": {s3}}}),)'


BROKEN = [
    # (parameters, terms, what the line says)
    (
        GOOD_PARAMETERS,
        _terms("np.ones(64)"),
        "weight 'c3' has shape (64,) on a probe of 7 positions",
    ),
    (GOOD_PARAMETERS, _terms("np.ones((7, 1))"), "has shape (7, 1)"),
    (GOOD_PARAMETERS, _terms("a * np.nan"), "weight 'c3' is not finite (NaN at 7 of 7 positions)"),
    (GOOD_PARAMETERS, _terms("a * np.inf"), "not finite (inf at 7 of 7 positions)"),
    (GOOD_PARAMETERS, _terms('"one"'), "weight 'c3' is 'one' on a probe of 7 positions"),
    (GOOD_PARAMETERS, _terms("a + 1j"), "expected a number or an array of shape (7,)"),
    (GOOD_PARAMETERS, _terms("None"), "weight 'c3' is None"),
    ("return ()", GOOD_TERMS, "parameters(variables) returned no parameter"),
    ("return None", GOOD_TERMS, "parameters(variables) returned None"),
    ('return ("c3", "s3")', GOOD_TERMS, "returned 'c3' as parameter 1"),
    (
        'return (ParameterSpec("c3", "arcsec", ARCSEC, "c"), ParameterSpec("c3", "arcsec", ARCSEC, '
        '"s"))',
        GOOD_TERMS,
        "declares the parameter 'c3' twice",
    ),
    (
        'return (ParameterSpec("c3", "arcsec", 0.0, "c"), ParameterSpec("s3", "arcsec", ARCSEC, '
        '"s"))',
        GOOD_TERMS,
        "parameter 'c3': per_user_unit is float 0.0; expected a finite number > 0",
    ),
    (
        'return (ParameterSpec("c3", "arcsec", float("nan"), "c"), ParameterSpec("s3", "arcsec", '
        'ARCSEC, "s"))',
        GOOD_TERMS,
        "per_user_unit is float nan",
    ),
    (
        GOOD_PARAMETERS,
        _terms("np.cos(3 * a)").replace('"c3"', '"zz"'),
        "weight 'zz' is not a parameter of the effect; parameters(variables) declares c3, s3",
    ),
    (
        GOOD_PARAMETERS,
        'return (ChainTerm("dphi_z2", None, {"c3": a}),)',
        "declares 's3' but no term of chain_terms(variables) weighs it",
    ),
    (GOOD_PARAMETERS, "return None", "chain_terms(variables) returned None"),
    (GOOD_PARAMETERS, 'return ("dphi_z2",)', "term 1 is 'dphi_z2' on a probe of 7 positions"),
    (
        GOOD_PARAMETERS,
        _terms("a", site='"dphi_q", None'),
        "site 'dphi_q' is not one of this table's",
    ),
    (GOOD_PARAMETERS, _terms("a", site='"post", "w"'), "a 'post' term turns about axis x, y or z"),
    (GOOD_PARAMETERS, _terms("a", site='"measured", "x"'), "a 'measured' term adds to dpsi"),
    (
        GOOD_PARAMETERS,
        'return (ChainTerm("dpsi", None, {"c3": a, "s3": a}),)',
        "site 'dpsi' is not one of this table's; expected a base error (dphi_y1, ",
    ),
    (
        GOOD_PARAMETERS,
        'return (ChainTerm("dphi_z2", None, [("c3", a), ("s3", a)]),)',
        "weights is list",
    ),
    (
        'raise RuntimeError("no parameters today")',
        GOOD_TERMS,
        "line 11: effect 'lobes' (class Lobes): parameters(variables) on a probe of 7 positions "
        "raised RuntimeError: no parameters today",
    ),
    (
        GOOD_PARAMETERS,
        "return (1 / 0,)",
        "line 15: effect 'lobes' (class Lobes): chain_terms(variables) on a probe of 7 positions "
        "raised ZeroDivisionError",
    ),
    (
        GOOD_PARAMETERS,
        "import sys; sys.exit(0)",
        "chain_terms(variables) on a probe of 7 positions called sys.exit(0)",
    ),
]


@pytest.mark.parametrize("parameters, terms, message", BROKEN, ids=range(len(BROKEN)))
def test_a_broken_effect_is_refused_in_one_line_when_it_enters(
    tmp_path, parameters, terms, message
):
    path = write_file(tmp_path, module_text(parameters, terms), "lobes.py")
    with pytest.raises(UserCodeError) as caught:
        load_effects_modules([path])
    text = str(caught.value)
    assert text.startswith(str(path)) and "\n" not in text
    assert "effect 'lobes' (class Lobes)" in text and message in text, text


def test_a_good_module_effect_passes_and_knows_its_file(tmp_path):
    path = write_file(tmp_path, module_text(), "lobes.py")
    (effect,) = load_effects_modules([path])
    assert effect.source == str(path)
    assert [e.name for e in load_catalogue([path])] == ["lobes"]


@pytest.mark.parametrize(
    "attribute, message",
    [
        ('    required_columns = "time_s"\n', "its required_columns is the text 'time_s'"),
        ("    required_columns = (1,)\n", "its required_columns is tuple (1,)"),
        ("    title = 3\n", "its title is int 3; expected a text"),
        ('    name = "lobes wide"\n', "letters, digits and _ . @ -"),
        ("    name = 7\n", "its name is int 7; expected a text"),
    ],
)
def test_the_story_and_the_name_are_checked_too(tmp_path, attribute, message):
    text = module_text().replace('    title = "three-lobed inner encoder"\n', attribute)
    path = write_file(tmp_path, text, "lobes.py")
    with pytest.raises((UserCodeError, InputError), match=message.replace("(", r"\(")
                       .replace(")", r"\)")):  # fmt: skip
        load_effects_modules([path])


def _measured():
    """144 simulated positions (the default 30-degree grid) with a 3/rev inner encoder error."""
    return simulate_measurements(None, {"inner_encoder_harmonics": {"c1": 3}}, seed=1).data


def test_an_effect_broken_on_the_data_only_is_refused_before_the_fit_is_believed(tmp_path):
    terms = "return (ChainTerm('dphi_z2', None, {'c3': np.cos(3 * a) / (variables.n < 10), " \
            "'s3': np.sin(3 * a)}),)"  # fmt: skip
    path = write_file(tmp_path, module_text(terms=terms), "lobes.py")
    (effect,) = load_effects_modules([path])  # fine on the probe of 7 positions
    data = _measured()
    with pytest.raises(UserCodeError, match=r"weight 'c3' is not finite \(inf at \d+ of 144 "
                       r"positions\) on the data \(144 positions\)"):  # fmt: skip
        fit_orientation(data, [effect])
    # not hidden as "cannot be fitted on these data" among the candidates of a diagnosis
    with pytest.raises(UserCodeError, match="on the data"):
        diagnose_measurements(data, catalogue=(*catalogue(), effect))


def test_an_effect_that_raises_on_the_data_names_its_line(tmp_path):
    terms = "if variables.n > 10:\n            raise ValueError('too many')\n        " + GOOD_TERMS
    path = write_file(tmp_path, module_text(terms=terms), "lobes.py")
    (effect,) = load_effects_module(path)
    with pytest.raises(UserCodeError) as caught:
        OrientationModel(_measured().variables(), [effect])
    assert str(caught.value).startswith(f"{path}, line 16: effect 'lobes' (class Lobes): "
                                        "chain_terms(variables) on the data (144 positions) "
                                        "raised ValueError: too many")  # fmt: skip
    assert isinstance(caught.value.__cause__, ValueError)


def test_the_check_on_the_data_runs_once_per_data_set(tmp_path):
    path = write_file(tmp_path, module_text(), "lobes.py")
    (effect,) = load_effects_module(path)
    calls = []
    chain_terms = effect.chain_terms
    effect.chain_terms = lambda variables: calls.append(1) or chain_terms(variables)
    variables = _measured().variables()
    for _ in range(3):
        OrientationModel(variables, [effect])
    assert len(calls) == 1


def test_an_object_passed_from_python_is_checked_where_it_meets_the_data():
    from turntable_pin.measurement.effects.base import ChainTerm, Effect, ParameterSpec

    class Halfway(Effect):
        name = "halfway"

        def parameters(self, variables):
            return (ParameterSpec("k", "arcsec", 1e-6, "k"),)

        def chain_terms(self, variables):
            return (ChainTerm("measured", "dpsi", {"k": variables.angle(1)[: variables.n // 2]}),)

    with pytest.raises(UserCodeError, match=r"test_effect_contract.py: effect 'halfway' \(class "
                       r"test_an_object_passed.*Halfway\): .*has shape \(72,\)"):  # fmt: skip
        fit_orientation(_measured(), [Halfway()])


TABLES = [
    None,
    *sorted((REPO_DIR / "models").glob("*.urdf")),
    REPO_DIR / "tests" / "zy_turntable.urdf",
]


@pytest.mark.parametrize("urdf", TABLES, ids=lambda p: "paper" if p is None else p.name)
def test_the_catalogue_keeps_the_contract_it_asks_of_the_users_effects(urdf):
    table = measured_table(None if urdf is None else GenericTable(urdf))
    for effect in catalogue(table):
        probe = probe_variables(table.n_joints, effect.required_columns)
        specs, terms = check_effect(effect, probe, table.base_names)
        assert specs and terms, effect.name


def test_yaml_and_module_effects_of_one_name_are_refused_naming_both(tmp_path):
    module = write_file(tmp_path, module_text(), "lobes.py")
    effect_file = write_file(tmp_path, "format: 1\nname: lobes\nterms: [dphi_z2~h3(phi2)]\n",
                             "lobes.yaml")  # fmt: skip
    with pytest.raises(InputError) as caught:
        load_catalogue([effect_file, module])
    assert str(caught.value) == (
        f"{module} (class Lobes): effect 'lobes' is also defined by {effect_file}, line 2; give "
        "one of them another name"
    )
    with pytest.raises(InputError, match=rf"{effect_file}, line 2: effect 'lobes' is also "
                       rf"defined by {module} \(class Lobes\)"):  # fmt: skip
        load_catalogue([module, effect_file])
    twice = write_file(tmp_path, module_text() + module_text().split("\n\n\n", 1)[1]
                       .replace("class Lobes", "class Lobes2"), "twice.py")  # fmt: skip
    with pytest.raises(InputError, match=r"twice.py \(class Lobes2\): effect 'lobes' is also "
                       r"defined by .*twice.py \(class Lobes\)"):  # fmt: skip
        load_effects_modules([twice])


def test_a_module_effect_named_like_a_catalogued_one_is_refused(tmp_path):
    path = write_file(tmp_path, module_text(name="backlash"), "lobes.py")
    message = (r"lobes.py \(class Lobes\): effect 'backlash' is already in the catalogue "
               r"\(turntable_pin.measurement.effects.backlash.Backlash\)")  # fmt: skip
    for load in (load_effects_modules, load_catalogue):
        with pytest.raises(InputError, match=message):
            load([path])
    clash = write_file(tmp_path, "name: backlash\nterms: [dphi_z2~h3(phi2)]\n", "b.yaml")
    with pytest.raises(InputError, match="b.yaml, line 1: effect 'backlash' is already in"):
        check_user_effects([read_effect_file(clash)])


def test_probe_variables_have_every_column_an_effect_may_need():
    probe = probe_variables(3, ("temperature_c", "dir2", "time_s"))
    assert probe.n == 7 and probe.n_joints == 3
    assert probe.has("time_s") and probe.has("dir3") and probe.has("temperature_c")
    assert len(np.unique(probe.angle(2))) == 7

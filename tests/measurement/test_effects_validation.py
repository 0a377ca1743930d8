"""``NAME:P=V,...`` effect specifications: nothing given is silently dropped or ignored."""

import pytest

from turntable_pin.core.exceptions import InputError
from turntable_pin.measurement.effects import get_effect, parameter_names, parse_effect_spec


@pytest.mark.parametrize(
    "text, expected",
    [
        ("gravity_sag:k=3", ("gravity_sag", {"k": 3.0})),
        (" backlash : b1 = 2 , b2=-1.5", ("backlash", {"b1": 2.0, "b2": -1.5})),
        ("thermal_drift:rz=1,", ("thermal_drift", {"rz": 1.0})),
    ],
)
def test_valid_specifications(text, expected):
    assert parse_effect_spec(text) == expected


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("gravity_sag:k=1,k=2", "parameter 'k' is given twice"),
        ("backlash:", "a ':' with no parameters after it; give them as backlash:P=V,... "
                      "(parameters: b1, b2 in arcsec)"),
        ("thermal_drift", "effect 'thermal_drift' without parameters would simulate nothing; give "
                          "at least one of rz, ry, rx in arcsec/h (e.g. thermal_drift:rz=1)"),
        ("gravity_sag:k", "expected NAME:P=V"),
        ("gravity_sag:=2", "expected NAME:P=V"),
        ("gravity_sag:k=nan", "parameter 'k': expected a finite number"),
        ("gravity_sag:k=two", "parameter 'k': expected a number"),
        ("gravity:k=1", "unknown effect 'gravity'"),
    ],
)  # fmt: skip
def test_refused_specifications(text, fragment):
    with pytest.raises(InputError) as info:
        parse_effect_spec(text)
    assert fragment in str(info.value)


def test_parameter_names_include_those_that_need_optional_columns():
    assert parameter_names(get_effect("backlash")) == ("b1", "b2")
    assert parameter_names(get_effect("thermal_drift")) == ("rz", "ry", "rx")

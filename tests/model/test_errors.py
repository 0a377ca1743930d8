import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from turntable_pin import ERROR_NAMES, InputError, TurntableErrors
from turntable_pin.core.units import ARCSEC_PER_RAD


def test_user_units_are_arcsec_and_mm():
    errors = TurntableErrors.from_user_units({"dphi_y1": 3.0, "deta": 0.2})
    assert errors.dphi_y1 == pytest.approx(3.0 / ARCSEC_PER_RAD, rel=1e-15)
    assert errors.deta == pytest.approx(2e-4, rel=1e-15)


def test_unit_suffixes():
    errors = TurntableErrors.from_user_units(
        {"dphi_y1_arcmin": 1.0, "deps_x_deg": 1.0, "deps_y_rad": 1e-5, "deta_m": 1e-4}
    )
    assert errors.dphi_y1 == pytest.approx(math.radians(1 / 60))
    assert errors.deps_x == pytest.approx(math.radians(1))
    assert errors.deps_y == 1e-5
    assert errors.deta == 1e-4


@pytest.mark.parametrize(
    "entry, fragment",
    [
        ({"dphi_q": 1}, "unknown error name 'dphi_q'"),
        ({"dphi_y1_furlong": 1}, "unit 'furlong' is not one of"),
        ({"deta_arcsec": 1}, "unit 'arcsec'"),
        ({"dphi_y1": "x"}, "expected a number"),
        ({"dphi_y1": float("nan")}, "finite"),
        ({"dphi_y1": 1, "dphi_y1_arcsec": 2}, "given twice"),
    ],
)
def test_bad_entries_name_the_problem(entry, fragment):
    with pytest.raises(InputError, match=fragment):
        TurntableErrors.from_user_units(entry)


def test_frozen():
    errors = TurntableErrors()
    with pytest.raises(AttributeError):
        errors.dphi_y1 = 1.0  # type: ignore[misc]


@given(st.lists(st.floats(-1e-3, 1e-3), min_size=9, max_size=9))
def test_user_units_round_trip(values):
    errors = TurntableErrors.from_array(values)
    again = TurntableErrors.from_user_units(errors.to_user_units())
    np.testing.assert_allclose(again.as_array(), errors.as_array(), rtol=1e-12, atol=1e-300)


def test_yaml_round_trip_and_errors(tmp_path):
    errors = TurntableErrors.from_arcsec(dphi_y1=1.5, deps_x=-2.0, deta_mm=0.3)
    path = tmp_path / "e.yaml"
    errors.to_yaml(path)
    np.testing.assert_allclose(TurntableErrors.from_yaml(path).as_array(), errors.as_array())
    bad = tmp_path / "bad.yaml"
    bad.write_text("errors: [1, 2\n")
    with pytest.raises(InputError, match="bad.yaml: not valid YAML"):
        TurntableErrors.from_yaml(bad)
    wrong = tmp_path / "wrong.yaml"
    wrong.write_text("errors:\n  dphi_x9: 1\n")
    with pytest.raises(InputError, match="wrong.yaml: unknown error name 'dphi_x9'"):
        TurntableErrors.from_yaml(wrong)


def test_names_follow_the_spec():
    assert ERROR_NAMES == (
        "dphi_y1", "dphi_z2", "dalpha_x1", "dalpha_z1",
        "dalpha_x2", "dalpha_y2", "deps_x", "deps_y", "deta",
    )  # fmt: skip

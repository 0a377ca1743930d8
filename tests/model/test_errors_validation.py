"""Error sets refuse what is not a small turntable error and what a file would silently drop."""

import re

import pytest

from turntable_pin.core.exceptions import InputError
from turntable_pin.core.units import DEG_PER_RAD
from turntable_pin.model.errors import (
    MAX_ANGULAR_ERROR_DEG,
    MAX_DETA_M,
    TurntableErrors,
    parse_error_value,
)


def test_the_limits():
    assert MAX_ANGULAR_ERROR_DEG == 5.0 and MAX_DETA_M == 0.01


@pytest.mark.parametrize(
    "key, value",
    [("dphi_y1", 18000), ("dphi_y1_deg", -5), ("deps_x_arcmin", 300), ("deta", 10),
     ("deta_m", -0.01), ("deta_um", 10000)],
)  # fmt: skip
def test_values_at_the_limits_are_taken(key, value):
    name, si = parse_error_value(key, value)
    limit = MAX_DETA_M if name == "deta" else MAX_ANGULAR_ERROR_DEG / DEG_PER_RAD
    assert abs(si) == pytest.approx(limit)


@pytest.mark.parametrize(
    "key, value, fragment",
    [
        ("dphi_y1", 1e308, "is not a small error: an angular error must be at most 5 deg"),
        ("dalpha_x2_deg", 5.001, "at most 5 deg (18000 arcsec)"),
        ("deps_y_rad", -0.1, "is not a small error"),
        ("deta", 10.5, "|deta| must be at most 10 mm"),
        ("deta_m", 1e308, "|deta| must be at most 10 mm"),
    ],
)
def test_values_beyond_the_limits_are_refused(key, value, fragment):
    with pytest.raises(InputError, match=re.escape(fragment)):
        parse_error_value(key, value)


def test_a_yaml_file_with_absurd_error_names_the_file(tmp_path):
    path = tmp_path / "e.yaml"
    path.write_text("errors:\n  dphi_y1: 1e308\n")
    with pytest.raises(InputError) as info:
        TurntableErrors.from_yaml(path)
    assert str(info.value).startswith(f"{path}: error 'dphi_y1' = 1e+308 arcsec is not a small")


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("errors:\n  dphi_y1: 1\nextra: 2\n", "unknown top-level key(s) 'extra' beside 'errors:'"),
        ("deta_mm: 0.1\nerrors:\n  dphi_y1: 1\n", "unknown top-level key(s) 'deta_mm'"),
        ("errors:\n  dphi_y1: 1\n  dphi_y1: 2\n", "line 3: key 'dphi_y1' is given twice"),
        ("dphi_y1: 1\ndphi_y1_arcsec: 2\n", "error 'dphi_y1' is given twice"),
    ],
)
def test_nothing_in_an_errors_file_is_silently_dropped(tmp_path, text, fragment):
    path = tmp_path / "e.yaml"
    path.write_text(text)
    with pytest.raises(InputError) as info:
        TurntableErrors.from_yaml(path)
    assert fragment in str(info.value) and str(path) in str(info.value)


def test_valid_files_read_as_before(tmp_path):
    path = tmp_path / "e.yaml"
    path.write_text("errors:\n  dphi_y1_arcsec: 3.0\n  deta_mm: 0.2\n")
    assert TurntableErrors.from_yaml(path) == TurntableErrors.from_arcsec(dphi_y1=3.0, deta_mm=0.2)
    path.write_text("errors:\n")
    assert TurntableErrors.from_yaml(path) == TurntableErrors()

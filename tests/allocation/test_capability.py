"""Manufacturing lower bounds: the bundled defaults and clear errors for bad files."""

import numpy as np
import pytest

from turntable_pin import ANGULAR_ERROR_NAMES, InputError
from turntable_pin.allocation.capability import ManufacturingCapability
from turntable_pin.core.units import arcmin_to_rad, arcsec_to_rad


def test_defaults_have_a_reason_for_every_error():
    cap = ManufacturingCapability.default()
    assert cap.lower_bounds_rad.shape == (8,)
    assert np.all(cap.lower_bounds_rad > 0)
    assert np.all(cap.lower_bounds_rad < arcsec_to_rad(5.0))  # good tables: arcsec level
    assert set(cap.reasoning) == set(ANGULAR_ERROR_NAMES)
    assert cap.to_dict()["lower_bounds_arcsec"]["dphi_y1"] == pytest.approx(1.0)


def test_units_and_missing_names(tmp_path):
    path = tmp_path / "lb.yaml"
    path.write_text("lower_bounds:\n  dphi_y1_arcmin: 0.1\n  deps_x: 2\n")
    cap = ManufacturingCapability.from_yaml(path)
    assert cap.lower_bounds_rad[0] == pytest.approx(arcmin_to_rad(0.1))
    assert cap.lower_bounds_rad[6] == pytest.approx(arcsec_to_rad(2.0))
    assert cap.lower_bounds_rad[1] == 0.0  # not given: no lower bound


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("lower_bounds:\n  dphi_y1: -1\n", "negative"),
        ("lower_bounds:\n  dphi_q: 1\n", "unknown error name"),
        ("lower_bounds:\n  deta_mm: 0.1\n", "not an angular error"),
        ("lower_bounds:\n  dphi_y1: abc\n", "expected a number"),
        ("just text\n", "lower_bounds"),
        ("lower_bounds: [1, 2\n", "not valid YAML"),
    ],
)
def test_bad_files_name_the_file_and_the_problem(tmp_path, text, fragment):
    path = tmp_path / "lb.yaml"
    path.write_text(text)
    with pytest.raises(InputError, match=fragment) as info:
        ManufacturingCapability.from_yaml(path)
    assert str(path) in str(info.value)


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="cannot read"):
        ManufacturingCapability.from_yaml(tmp_path / "nope.yaml")

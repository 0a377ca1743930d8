"""The GyroWheel drift model: Table 1 bundled, eq. 1 outputs, regressor rows, coefficient files."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from turntable_pin import InputError
from turntable_pin.calibration.gyrowheel import DriftCoefficients, GyroWheelModel, regressor_matrix

# Paper Table 1, typed from the paper independently of models/gyrowheel_nominal.yaml.
TABLE1_X = {"DF": -93.3, "x": -43.2, "y": 3.5, "z": -1.2, "xx": 2.1, "zz": -0.089, "xy": 17.4}
TABLE1_Y = {"DF": 105.3, "x": 2.2, "y": -33.2, "z": -0.1, "yy": -10.6, "zz": -10.38, "yx": 47.8}


def test_nominal_is_table_1():
    model = GyroWheelModel.nominal()
    assert model.x.to_dict() == TABLE1_X
    assert model.y.to_dict() == TABLE1_Y


finite = st.floats(-1.5, 1.5, allow_nan=False)


@given(ax=finite, ay=finite, az=finite, wx=finite, wy=finite)
@settings(max_examples=50, deadline=None)
def test_outputs_follow_eq_1_written_out(ax, ay, az, wx, wy):
    out = GyroWheelModel.nominal().outputs_dph([ax, ay, az], [wx, wy, 0.0])
    x, y = TABLE1_X, TABLE1_Y
    out_x = (wx + x["DF"] + x["x"] * ax + x["y"] * ay + x["z"] * az + x["xx"] * ax**2
             + x["zz"] * az**2 + x["xy"] * ax * ay)  # fmt: skip
    out_y = (wy + y["DF"] + y["x"] * ax + y["y"] * ay + y["z"] * az + y["yy"] * ay**2
             + y["zz"] * az**2 + y["yx"] * ax * ay)  # fmt: skip
    np.testing.assert_allclose(out, [out_x, out_y], rtol=1e-13, atol=1e-12)


def test_regressor_rows_of_eq_2():
    a = np.array([[0.3, -0.5, 0.8], [1.0, 0.0, 0.0]])
    np.testing.assert_allclose(
        regressor_matrix("x", a),
        [[1, 0.3, -0.5, 0.8, 0.09, 0.64, -0.15], [1, 1, 0, 0, 1, 0, 0]],
    )
    np.testing.assert_allclose(regressor_matrix("y", a)[0], [1, 0.3, -0.5, 0.8, 0.25, 0.64, -0.15])
    with pytest.raises(InputError, match="unknown GyroWheel axis"):
        regressor_matrix("z", a)


def test_user_coefficients_file(tmp_path):
    path = tmp_path / "gw.yaml"
    path.write_text(
        "x: {DF: 1, x: 2, y: 3, z: 4, xx: 5, zz: 6, xy: 7}\n"
        "y: {DF: -1, x: -2, y: -3, z: -4, yy: -5, zz: -6, yx: -7}\n"
    )
    model = GyroWheelModel.from_yaml(path)
    np.testing.assert_array_equal(model.x.as_array(), np.arange(1, 8))
    np.testing.assert_array_equal(model.y.as_array(), -np.arange(1, 8))


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("x: {DF: 1}\ny: {DF: 1}\n", "missing coefficient(s)"),
        ("x: {DF: 1, x: 2, y: 3, z: 4, yy: 5, zz: 6, xy: 7}\n"
         "y: {DF: 1, x: 2, y: 3, z: 4, yy: 5, zz: 6, yx: 7}\n", "unknown coefficient(s) ['yy']"),
        ("x: {DF: a, x: 2, y: 3, z: 4, xx: 5, zz: 6, xy: 7}\n"
         "y: {DF: 1, x: 2, y: 3, z: 4, yy: 5, zz: 6, yx: 7}\n", "'DF': expected a number"),
        ("x: {DF: .nan, x: 2, y: 3, z: 4, xx: 5, zz: 6, xy: 7}\n"
         "y: {DF: 1, x: 2, y: 3, z: 4, yy: 5, zz: 6, yx: 7}\n", "expected a finite number"),
        ("only_x: {}\n", "exactly the keys 'x' and 'y'"),
        ("x: [1,\n", "not valid YAML"),
    ],
)  # fmt: skip
def test_bad_coefficient_files_name_the_problem(tmp_path, text, fragment):
    path = tmp_path / "gw.yaml"
    path.write_text(text)
    with pytest.raises(InputError) as info:
        GyroWheelModel.from_yaml(path)
    assert fragment in str(info.value)
    assert "gw.yaml" in str(info.value)


def test_coefficients_are_frozen_and_checked():
    coefficients = DriftCoefficients("x", (1, 2, 3, 4, 5, 6, 7))
    with pytest.raises(AttributeError):
        coefficients.axis = "y"
    with pytest.raises(InputError, match="7 coefficients"):
        DriftCoefficients("x", (1, 2))

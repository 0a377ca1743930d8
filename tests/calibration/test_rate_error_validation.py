"""Rate error, requirement and positions take only small orientation errors, sensible accuracies,
latitudes and commanded angles (1e308 used to end in a LinAlgError traceback)."""

import math
import re

import pytest

from turntable_pin.calibration.gyrowheel import GyroWheelModel
from turntable_pin.calibration.positions import (
    MAX_COMMANDED_ANGLE_DEG,
    PositionSet,
    position_inputs,
)
from turntable_pin.calibration.rate_error import rate_error
from turntable_pin.calibration.requirement import ACCURACY_RANGE_DPH, orientation_requirement
from turntable_pin.calibration.site import MAX_LATITUDE_DEG
from turntable_pin.core.exceptions import InputError


@pytest.fixture(scope="module")
def inputs():
    return position_inputs(PositionSet.grid(45), math.radians(45))


@pytest.mark.parametrize("angle", ["dpsi", "dtheta", "dgamma"])
def test_rate_error_refuses_large_orientation_errors(inputs, angle):
    values = {"dpsi": 0.0, "dtheta": 0.0, "dgamma": 0.0, angle: 1e308}
    message = f"{angle} = 1e+308 rad is not a small orientation error: it must be within +-5 deg"
    with pytest.raises(InputError, match=re.escape(message)):
        rate_error(GyroWheelModel.nominal(), inputs, values["dpsi"], values["dtheta"],
                   values["dgamma"])  # fmt: skip
    values[angle] = math.radians(5.0)
    result = rate_error(
        GyroWheelModel.nominal(), inputs, values["dpsi"], values["dtheta"], values["dgamma"]
    )
    assert math.isfinite(result.dwx_dph) and math.isfinite(result.dwy_dph)


@pytest.mark.parametrize("accuracy", [1e-7, 1.5, 1e308])
def test_requirement_refuses_accuracies_out_of_range(accuracy):
    assert ACCURACY_RANGE_DPH == (1e-6, 1.0)
    with pytest.raises(InputError, match=r"between 1e-06 and 1 deg/h"):
        orientation_requirement(accuracy, PositionSet.grid(45), math.radians(45))


def test_positions_beyond_ten_turns_and_latitudes_beyond_the_poles():
    assert MAX_COMMANDED_ANGLE_DEG == 3600.0 and MAX_LATITUDE_DEG == 90.0
    with pytest.raises(InputError, match=r"commanded angles must be within \+-3600 deg"):
        PositionSet([0.0, math.radians(3601.0)], [0.0, 0.0])
    assert len(PositionSet([0.0, math.radians(3600.0)], [0.0, 0.0])) == 2
    with pytest.raises(InputError, match=r"latitude must be within \+-90 degrees"):
        position_inputs(PositionSet.grid(90), math.radians(90.5))


def test_a_positions_file_names_row_and_column(tmp_path):
    path = tmp_path / "p.csv"
    path.write_text("phi1_deg,phi2_deg\n0,0\n30,1e308\n")
    with pytest.raises(InputError) as info:
        PositionSet.from_csv(path)
    assert str(info.value).startswith(f"{path}, row 3, column 'phi2_deg': a commanded angle")

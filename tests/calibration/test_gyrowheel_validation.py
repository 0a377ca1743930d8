"""GyroWheel coefficient files: a key given twice or an absurd coefficient is refused."""

import pytest

from turntable_pin.calibration.gyrowheel import (
    MAX_COEFFICIENT_DPH,
    DriftCoefficients,
    GyroWheelModel,
)
from turntable_pin.core.exceptions import InputError
from turntable_pin.core.resources import default_gyrowheel_path


def test_a_duplicated_coefficient_names_file_and_line(tmp_path):
    text = default_gyrowheel_path().read_text().replace("  DF: -93.3\n", "  DF: -93.3\n  DF: 1\n")
    path = tmp_path / "g.yaml"
    path.write_text(text)
    with pytest.raises(InputError, match=r"line \d+: key 'DF' is given twice") as info:
        GyroWheelModel.from_yaml(path)
    assert str(info.value).startswith(str(path))


def test_absurd_coefficients_are_refused(tmp_path):
    assert MAX_COEFFICIENT_DPH == 1e5
    text = default_gyrowheel_path().read_text().replace("  zz: -10.38", "  zz: 1e308")
    path = tmp_path / "g.yaml"
    path.write_text(text)
    with pytest.raises(InputError) as info:
        GyroWheelModel.from_yaml(path)
    assert str(info.value) == (
        f"{path}: axis 'y', coefficient 'zz': 1e+308 is beyond +-100000 deg/h (no rate sensor "
        "drifts that much)"
    )
    with pytest.raises(InputError, match="coefficient 'DF'"):
        DriftCoefficients("x", (2e5, 0, 0, 0, 0, 0, 0))

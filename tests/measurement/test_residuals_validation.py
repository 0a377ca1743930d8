"""The residual analysis refuses a failing threshold that is not a positive number."""

import pytest

from conftest import EXAMPLES_DIR
from turntable_pin.core.exceptions import InputError
from turntable_pin.measurement.data import read_measurements
from turntable_pin.measurement.fit import fit_orientation
from turntable_pin.measurement.residuals import analyse_residuals, orientation_residuals


@pytest.mark.parametrize("k_sigma", [0.0, -1.0, float("nan"), float("inf")])
def test_k_sigma_must_be_positive_and_finite(k_sigma):
    fit = fit_orientation(read_measurements(EXAMPLES_DIR / "measurements_example.csv"))
    with pytest.raises(InputError, match="k_sigma must be a number > 0"):
        analyse_residuals(orientation_residuals(fit), k_sigma)

"""Orientation limits are small angles: a limit of 1e308 degrees used to print 300-digit bounds."""

import math

import pytest

from turntable_pin.allocation.solver import OrientationLimits
from turntable_pin.core.exceptions import InputError


@pytest.mark.parametrize("deg", [5.0001, 90.0, 1e308])
def test_limits_beyond_five_degrees_are_refused(deg):
    with pytest.raises(InputError, match="it must be at most 5 deg"):
        OrientationLimits.from_deg(1.0, deg, 1.0)


def test_five_degrees_is_taken():
    limits = OrientationLimits.from_deg(5.0, 5.0, 5.0)
    assert limits.psi_rad == pytest.approx(math.radians(5.0))
    assert OrientationLimits.from_arcmin(300.0, 1.0, 1.0).psi_rad == pytest.approx(
        math.radians(5.0)
    )

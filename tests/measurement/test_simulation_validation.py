"""The simulator takes only seeds numpy can reproduce, noise and effects a measurement file can
hold, and never an effect that would add nothing."""

import pytest

from turntable_pin.core.exceptions import InputError
from turntable_pin.measurement.simulation import (
    MAX_NOISE_ARCSEC,
    Schedule,
    simulate_measurements,
)
from turntable_pin.model.errors import TurntableErrors

SMALL = Schedule(90, 90)


@pytest.mark.parametrize("seed", [-1, 2**63, 1.5, "1"])
def test_bad_seeds_are_input_errors(seed):
    with pytest.raises(InputError, match=r"seed must be a whole number 0 <= seed < 2\*\*63"):
        simulate_measurements(seed=seed, schedule=SMALL)


def test_the_largest_seed_works():
    assert simulate_measurements(seed=2**63 - 1, schedule=SMALL).seed == 2**63 - 1


@pytest.mark.parametrize(
    "kwargs, fragment",
    [
        ({"noise_arcsec": MAX_NOISE_ARCSEC * 1.01}, "noise_arcsec must be in [1e-09, 1800]"),
        ({"noise_arcsec": 1e-12}, "noise_arcsec must be in"),
        ({"noise_arcsec": 0.0}, "noise_arcsec must be > 0"),
        ({"effects": {"thermal_drift": {}}}, "effect 'thermal_drift' is given without parameters"),
        ({"effects": {"gravity_sag": {"k": 1e308}}},
         "effect 'gravity_sag', parameter 'k' = 1e+308: must be a number within +-18000"),
        ({"effects": {"gravity_sag": {"k": "x"}}}, "must be a number within"),
        ({"schedule": Schedule(90, 90, dwell_s=1e7)},
         "dwell_s 1e+07: the run of 16 measurements would last 1.5e+08 s"),
        ({"errors": TurntableErrors.from_user_units({"dphi_y1_deg": 25, "deps_y_deg": 25},
                                                    max_angle_deg=30)},
         "the simulated orientation errors reach"),
    ],
)  # fmt: skip
def test_what_would_make_an_unreadable_or_empty_run_is_refused(kwargs, fragment):
    kwargs.setdefault("schedule", SMALL)
    with pytest.raises(InputError) as info:
        simulate_measurements(**kwargs)
    assert fragment in str(info.value)

"""A run separation chooses at most its candidates, each once, and says so up front (issue 27,
"Runaway memory and time"): before, ``design --separate A,B --run RUN -n 1000000`` silently
returned all 10,144 candidates after 90 s, where the identify mode refuses."""

import numpy as np
import pytest

from turntable_pin.calibration.positions import PositionSet, position_inputs
from turntable_pin.calibration.run import CalibrationRun
from turntable_pin.core.exceptions import InputError
from turntable_pin.instrument import separate
from turntable_pin.instrument.separate import design_run_separation
from turntable_pin.instrument.simulate import simulate_calibration_run

LATITUDE_RAD = np.radians(45.75)


def _run():
    grid = np.stack(np.meshgrid(np.arange(0, 360, 30.0), np.arange(0, 360, 30.0)), -1)
    positions = PositionSet(np.radians(grid.reshape(-1, 2)))
    sim = simulate_calibration_run(
        positions, LATITUDE_RAD, noise_dph=0.002, seed=1,
        instrument={"g_squared_terms": {"x_xz": 0.02}},
    )  # fmt: skip
    return CalibrationRun(position_inputs(positions, LATITUDE_RAD), sim.outputs_dph,
                          np.full(len(positions), 0.002))  # fmt: skip


def test_more_positions_than_candidates_are_refused_before_any_fit(monkeypatch):
    candidates = np.random.default_rng(0).uniform(-np.pi, np.pi, (40, 2))

    def never(*args, **kwargs):
        raise AssertionError("the run was fitted")

    monkeypatch.setattr(separate, "RunFamily", never)
    with pytest.raises(InputError) as caught:
        design_run_separation(_run(), ("g_squared_terms", "instrument_tilt"), candidates, 41)
    assert str(caught.value) == (
        "n is 41, more than the 40 candidate positions a design chooses among (each once); ask "
        "for fewer, or give more candidates"
    )
    with pytest.raises(InputError, match="^n must be at least 1, got 0$"):
        design_run_separation(_run(), ("g_squared_terms", "instrument_tilt"), candidates, 0)


def test_as_many_positions_as_candidates_are_still_chosen():
    candidates = np.random.default_rng(0).uniform(-np.pi, np.pi, (12, 2))
    result = design_run_separation(_run(), ("g_squared_terms", "instrument_tilt"), candidates, 12)
    assert result.separable
    chosen = np.sort(result.positions_deg, axis=0)  # every candidate, once
    assert np.allclose(chosen, np.sort(np.degrees(candidates), axis=0), rtol=0, atol=1e-6)

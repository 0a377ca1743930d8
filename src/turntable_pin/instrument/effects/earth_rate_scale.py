"""A scale factor on the earth-rate term: the GyroWheel's rate gain is not exactly one."""

from __future__ import annotations

import numpy as np

from .base import INSTRUMENT, ParameterSpec, RunContext, RunEffect, Sensed, plausible

__all__ = ["EarthRateScale"]

PPM = 1e-6


class EarthRateScale(RunEffect):
    """``out_c -> out_c + s_c w_c`` (``s_c`` in ppm, ``w_c`` the earth rate along axis c)."""

    name = "earth_rate_scale"
    side = INSTRUMENT
    limit = 1e5
    plausibility = (  # docs/plausibility.md
        plausible(("x", "y"), "a scale factor wrong by {amplitude}", "ppm", any_machine=5e4),
    )
    title = "a scale-factor error of the GyroWheel's rate outputs"
    definition = "out_x += sx wx, out_y += sy wy (ppm of the earth rate along each axis)"
    explanation = (
        "Eq. 1 takes the outputs' rate gain as exactly one (ky*iy and kx*ix scaled to deg/h). "
        "A gain error -- a rotor speed or a pick-off gain off its nominal value -- scales the "
        "earth rate each axis sees, about 10 deg/h here, by the same fraction at every "
        "position."
    )
    confirm = (
        "Calibrate the scale factor on a rate table (several rates, both directions): the "
        "slope of output against rate is the gain. At the earth rate alone, a gain error shows "
        "as residuals following the earth rate's component along the axis."
    )

    def parameters(self, run) -> tuple[ParameterSpec, ...]:
        """This effect's parameters on ``run`` (their user units and scales)."""
        return tuple(
            ParameterSpec(axis, "ppm", PPM, f"earth-rate scale error of axis {axis}")
            for axis in "xy"
        )

    def columns(self, context: RunContext) -> np.ndarray:
        """``d(out_x, out_y)/d(parameter)`` at each position, (N, 2, p), deg/h per internal unit."""
        w = context.run.inputs.earth_rate_dph
        out = np.zeros((w.shape[0], 2, 2))
        out[:, 0, 0] = w[:, 0]
        out[:, 1, 1] = w[:, 1]
        return out

    def planted_dph(self, values: dict[str, float], sensed: Sensed) -> np.ndarray:
        """``s_c 1e-6 w_c`` on each output, (N, 2) deg/h, ``w`` the sensed earth rate."""
        return np.stack(
            [values[a] * PPM * sensed.rate_dph[:, c] for c, a in enumerate("xy")], axis=1
        )

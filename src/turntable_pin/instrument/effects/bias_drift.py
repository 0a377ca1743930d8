"""The GyroWheel's bias drifting over the run: a term linear in time on each output."""

from __future__ import annotations

import numpy as np

from .base import INSTRUMENT, ParameterSpec, RunContext, RunEffect, Sensed, plausible

__all__ = ["BiasDrift"]

SECONDS_PER_HOUR = 3600.0


class BiasDrift(RunEffect):
    """``out_c -> out_c + d_c t`` (``d_c`` in deg/h per hour, ``t = time_s``)."""

    name = "bias_drift"
    side = INSTRUMENT
    limit = 1e3
    title = "the GyroWheel's bias drifting with time"
    definition = "out_x += dx t, out_y += dy t (deg/h per hour, t = time_s since the start)"
    explanation = (
        "The bias of a rate sensor is not constant after switch-on: the rotor and the "
        "electronics warm up, the bearings run in, and the zero moves slowly over the hours of "
        "a multi-position run. The calibration, which takes one DF per axis, spreads the drift "
        "over the coefficients in the order the positions were measured."
    )
    confirm = (
        "Repeat a few positions at the end of the run (or run the schedule backwards): a drift "
        "makes the same position read differently early and late. A long static record at one "
        "position after switch-on shows it directly."
    )
    required_columns = ("time_s",)
    plausibility = (  # docs/plausibility.md
        plausible(("x", "y"), "a bias drifting by {amplitude}", "deg/h/h", any_machine=20),
    )

    def parameters(self, run) -> tuple[ParameterSpec, ...]:
        """This effect's parameters on ``run`` (their user units and scales)."""
        return tuple(
            ParameterSpec(axis, "deg/h/h", 1.0 / SECONDS_PER_HOUR, f"bias drift of axis {axis}")
            for axis in "xy"
        )

    def columns(self, context: RunContext) -> np.ndarray:
        """``d(out_x, out_y)/d(parameter)`` at each position, (N, 2, p), deg/h per internal unit."""
        t = np.asarray(context.run.time_s, dtype=float)
        out = np.zeros((t.size, 2, 2))
        out[:, 0, 0] = t
        out[:, 1, 1] = t
        return out

    def planted_dph(self, values: dict[str, float], sensed: Sensed) -> np.ndarray:
        """``d_c time_s / 3600`` on each output, (N, 2) deg/h."""
        return np.stack([values[axis] * sensed.time_s / SECONDS_PER_HOUR for axis in "xy"], axis=1)

"""The GyroWheel's drift following its temperature: a coefficient per output."""

from __future__ import annotations

import numpy as np

from .base import INSTRUMENT, ParameterSpec, RunContext, RunEffect, Sensed, plausible

__all__ = ["TEMPERATURE_COLUMN", "TemperatureCoefficient"]

TEMPERATURE_COLUMN = "temperature_c"
"""The run column with the instrument's temperature, degrees Celsius."""


class TemperatureCoefficient(RunEffect):
    """``out_c -> out_c + k_c (T - T_mean)`` (``k_c`` in deg/h per degree C, ``T`` the run's
    ``temperature_c``, ``T_mean`` its mean over the run)."""

    name = "temperature_coefficient"
    side = INSTRUMENT
    limit = 1e3
    plausibility = (  # docs/plausibility.md
        plausible(("x", "y"), "a bias moving by {amplitude} with temperature", "deg/h/degC",
                  any_machine=10),
    )  # fmt: skip
    title = "the GyroWheel's drift following its temperature"
    definition = (
        "out_x += kx (T - T_mean), out_y += ky (T - T_mean) (deg/h per degree C, T = temperature_c)"
    )
    explanation = (
        "Rate sensors drift with temperature: the rotor's speed, the pick-off gains and the "
        "magnetic bias move with it. When the room or the table's motors warm the instrument "
        "over the run, the outputs follow the temperature record, not the positions."
    )
    confirm = (
        "Hold one position and let the temperature change (a thermal chamber, or the warm-up "
        "after switch-on): the output follows the temperature with this coefficient. Repeating "
        "positions at another temperature shows it too."
    )
    required_columns = (TEMPERATURE_COLUMN,)

    def parameters(self, run) -> tuple[ParameterSpec, ...]:
        """This effect's parameters on ``run`` (their user units and scales)."""
        return tuple(
            ParameterSpec(axis, "deg/h/degC", 1.0, f"temperature coefficient of axis {axis}")
            for axis in "xy"
        )

    def columns(self, context: RunContext) -> np.ndarray:
        """``d(out_x, out_y)/d(parameter)`` at each position, (N, 2, p), deg/h per internal unit."""
        t = np.asarray(context.run.column(TEMPERATURE_COLUMN), dtype=float)
        t = t - float(np.mean(t))
        out = np.zeros((t.size, 2, 2))
        out[:, 0, 0] = t
        out[:, 1, 1] = t
        return out

    def planted_dph(self, values: dict[str, float], sensed: Sensed) -> np.ndarray:
        """``k_c (T - T_mean)`` on each output, (N, 2) deg/h."""
        t = sensed.temperature_c
        return np.stack([values[axis] * (t - t.mean()) for axis in "xy"], axis=1)

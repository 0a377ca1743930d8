"""The g-squared terms eq. 1 leaves out: az*ax and az*ay on each output."""

from __future__ import annotations

import numpy as np

from ...calibration.gyrowheel import MAX_COEFFICIENT_DPH
from .base import INSTRUMENT, ParameterSpec, RunContext, RunEffect, Sensed, plausible

__all__ = ["GSquaredTerms"]


class GSquaredTerms(RunEffect):
    """``out_c -> out_c + c_xz ax az + c_yz ay az`` (deg/h/g^2 per output).

    Eq. 1 keeps ``ax^2`` (``ay^2`` on y), ``az^2`` and ``ax ay``; the one squared term it lacks
    that the data can see besides ``ax az`` and ``ay az`` is the third square (``ay^2`` on x),
    and that one is ``1 - ax^2 - az^2`` (gravity is one g): no run can tell it from DF and the
    two squares the model has."""

    name = "g_squared_terms"
    side = INSTRUMENT
    limit = MAX_COEFFICIENT_DPH
    plausibility = (  # docs/plausibility.md
        plausible(("x_xz", "x_yz", "y_xz", "y_yz"), "g-squared terms of {amplitude}",
                  "deg/h/g^2", any_machine=200),
    )  # fmt: skip
    title = "g-squared (anisoelastic) terms the 7-coefficient model leaves out"
    definition = "out_x += x_xz ax az + x_yz ay az, out_y += y_xz ax az + y_yz ay az (deg/h/g^2)"
    explanation = (
        "A rotor on a compliant suspension deflects under gravity by different amounts along "
        "different axes (anisoelasticity), which makes drift terms in products of the gravity "
        "components. Eq. 1 keeps ax^2, az^2 and ax*ay; when the instrument also has ax*az or "
        "ay*az terms, the 7-coefficient calibration cannot follow them and leaves them in the "
        "residuals at the positions where gravity has both a z and a horizontal component."
    )
    confirm = (
        "Tumble the instrument in 45-degree steps about a horizontal axis in the x-z and y-z "
        "planes: a term in ax*az is largest at 45 degrees between x and z and changes sign "
        "with the quadrant."
    )

    def parameters(self, run) -> tuple[ParameterSpec, ...]:
        """This effect's parameters on ``run`` (their user units and scales)."""
        return tuple(
            ParameterSpec(f"{axis}_{term}", "deg/h/g^2", 1.0, f"{term} term on axis {axis}")
            for axis in "xy"
            for term in ("xz", "yz")
        )

    def columns(self, context: RunContext) -> np.ndarray:
        """``d(out_x, out_y)/d(parameter)`` at each position, (N, 2, p), deg/h per internal unit."""
        a = context.run.inputs.specific_force_g
        xz, yz = a[:, 0] * a[:, 2], a[:, 1] * a[:, 2]
        out = np.zeros((a.shape[0], 2, 4))
        out[:, 0, 0], out[:, 0, 1] = xz, yz
        out[:, 1, 2], out[:, 1, 3] = xz, yz
        return out

    def planted_dph(self, values: dict[str, float], sensed: Sensed) -> np.ndarray:
        """``c_xz ax az + c_yz ay az`` on each output, (N, 2) deg/h, ``a`` the sensed force."""
        a = sensed.force_g
        return np.stack(
            [
                values[f"{c}_xz"] * a[:, 0] * a[:, 2] + values[f"{c}_yz"] * a[:, 1] * a[:, 2]
                for c in "xy"
            ],
            axis=1,
        )

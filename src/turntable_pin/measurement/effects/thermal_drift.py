"""``thermal_drift``: a slow rotation of the payload over the run (needs ``time_s``)."""

from __future__ import annotations

import numpy as np

from .base import ARCSEC, POST, ChainTerm, Effect, ParameterSpec, PositionVariables, plausible

_ARCSEC_PER_HOUR = ARCSEC / 3600.0  # rad/s of one arcsec/h

__all__ = ["ThermalDrift"]


class ThermalDrift(Effect):
    """Slow thermal drift: a payload rotation growing linearly with ``time_s`` (arcsec/h)."""

    name = kind = "thermal_drift"
    title = "slow thermal drift of the payload"
    definition = "Rt -> Rt Rz(rz t) Ry(ry t) Rx(rx t), t = time_s"
    explanation = (
        "As motors, electronics and the room warm up, the frames expand unevenly and the payload "
        "slowly rotates with respect to its mount: a rotation that grows with time rather than "
        "with the table angles. Measured in grid order it can masquerade as an angle-dependent "
        "error; in random order it appears as scatter that correlates with time."
    )
    confirm = (
        "Return to one reference position at regular times during the run (or hold a position "
        "for an hour) and log temperatures: the orientation at a fixed position drifts with time. "
        "Randomising the order of positions decouples time from angle."
    )
    required_columns = ("time_s",)
    plausibility = (  # docs/plausibility.md
        plausible(("rz", "ry", "rx"), "a payload turning by {amplitude} as it warms",
                  "arcsec/h", turntable=120, mount=300),
    )  # fmt: skip

    def parameters(self, variables: PositionVariables):
        """The drift rates ``rz``, ``ry`` and ``rx``, arcsec/h."""
        return (
            ParameterSpec("rz", "arcsec/h", _ARCSEC_PER_HOUR, "drift rate about z"),
            ParameterSpec("ry", "arcsec/h", _ARCSEC_PER_HOUR, "drift rate about y"),
            ParameterSpec("rx", "arcsec/h", _ARCSEC_PER_HOUR, "drift rate about x"),
        )

    def chain_terms(self, variables: PositionVariables):
        """The rotations ``Rz(rz t) Ry(ry t) Rx(rx t)`` after ``Rt``, ``t`` the time in s."""
        t = np.asarray(variables.time_s, dtype=float)
        return (
            ChainTerm(POST, "z", {"rz": t}),
            ChainTerm(POST, "y", {"ry": t}),
            ChainTerm(POST, "x", {"rx": t}),
        )

"""``base_tilt``: the turntable base is not level with the measurement reference."""

from __future__ import annotations

import numpy as np

from .base import ARCSEC, PRE, ChainTerm, Effect, ParameterSpec, PositionVariables

__all__ = ["BaseTilt"]


class BaseTilt(Effect):
    """Base not level with the reference: a constant rotation about x and z before ``Rt``."""

    name = "base_tilt"
    title = "base not level with the reference"
    definition = "Rt -> Rx(tx) Rz(tz) Rt"
    explanation = (
        "The table stands on a floor or a pier that is not exactly level, or the reference the "
        "orientation is measured against (a theodolite line, a reference mirror) is tilted with "
        "respect to the base: the whole table, with both axes, is rotated by small angles about "
        "north (tx) and up (tz) before anything turns. A tilt about the outer axis itself (y) is a "
        "shift of phi1, already the outer position error, so only tx and tz are new."
    )
    confirm = (
        "Put a precision level (or electronic inclinometer) on the base mounting surface, or "
        "re-measure the reference direction; re-level the table and repeat a few positions."
    )

    def parameters(self, variables: PositionVariables):
        """``tx`` and ``tz``, arcsec."""
        return (
            ParameterSpec("tx", "arcsec", ARCSEC, "tilt of the base about x (north)"),
            ParameterSpec("tz", "arcsec", ARCSEC, "rotation of the base about z (up)"),
        )

    def chain_terms(self, variables: PositionVariables):
        """The rotations ``Rx(tx) Rz(tz)`` before ``Rt``, the same at every position."""
        one = np.ones(variables.n)
        return (ChainTerm(PRE, "x", {"tx": one}), ChainTerm(PRE, "z", {"tz": one}))

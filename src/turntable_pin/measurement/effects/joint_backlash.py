"""``backlash@<joint>``: the position of one joint depends on the direction it came from."""

from __future__ import annotations

import numpy as np

from .base import ARCSEC, ChainTerm, Effect, ParameterSpec, PositionVariables

__all__ = ["JointBacklash"]


class JointBacklash(Effect):
    """Approach-direction dependence of one joint: half its backlash ``b`` (arcsec) times
    ``dirK``.

    Args:
        joint: the joint's name (the effect is ``backlash@<joint>``).
        index: the joint's place in the chain from the base (K of ``dirK``).
        position_error: the table's name of the joint's position error.
    """

    kind = "backlash"

    def __init__(self, joint: str, index: int, position_error: str) -> None:
        self.joint, self.index, self.site = joint, int(index), position_error
        self.column = f"dir{self.index}"
        self.required_columns = (self.column,)
        self.name = f"{self.kind}@{joint}"
        self.title = f"backlash of {joint} (approach-direction dependence)"
        self.definition = f"{position_error} += b {self.column} / 2"
        self.explanation = (
            f"Gears, couplings and the servo's dead band let {joint} stop a little short of the "
            "commanded angle, on the side it came from: its position error differs by b between "
            f"approaches from below ({self.column} = +1) and from above ({self.column} = -1)."
        )
        self.confirm = (
            "Approach a few positions alternately from both directions and compare: a backlash "
            "flips sign with the approach direction; a unidirectional approach removes it."
        )

    def parameters(self, variables: PositionVariables):
        """The backlash ``b``, arcsec."""
        return (ParameterSpec("b", "arcsec", ARCSEC, f"backlash of {self.joint}"),)

    def chain_terms(self, variables: PositionVariables):
        """``b dirK / 2`` added to the joint's position error."""
        return (ChainTerm(self.site, None, {"b": 0.5 * np.asarray(variables.column(self.column))}),)

"""``backlash@<joint>``: the position of a joint depends on the direction it came from."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .base import (
    ARCSEC,
    ChainTerm,
    Effect,
    EffectText,
    Labels,
    ParameterSpec,
    PositionVariables,
    plausible,
)

__all__ = ["Backlash"]


class Backlash(Effect):
    """Approach-direction dependence of one or more joints: half each one's backlash (arcsec)
    times its ``dirK``. Of several joints, the parameters of the ``dirK`` columns present are
    fitted (one column suffices).

    Args:
        joints: the joints' errors (:class:`~turntable_pin.measurement.table.JointErrors`: name,
            place from the base K of ``dirK``, position error).
        name, text: the table's name and story of it (default ``backlash@<joint>``, one joint).
        labels: ``(parameter, description)`` of each joint (default ``b`` for one joint, ``bK``
            for several; ``"backlash of <joint>"``).
    """

    kind = "backlash"
    any_column = True

    def __init__(self, joints: Sequence, *, name=None, text=None, labels: Labels = ()) -> None:
        self.joints = tuple(j.joint for j in joints)
        self.required_columns = tuple(f"dir{j.index}" for j in joints)
        labels = tuple(labels) or tuple(
            ("b" if len(joints) == 1 else f"b{j.index}", f"backlash of {j.joint}") for j in joints
        )
        self.each = tuple(  # (position error, parameter, description, dirK) of each joint
            (j.position, b, what, f"dir{j.index}")
            for j, (b, what) in zip(joints, labels, strict=True)
        )
        joint, column = " and ".join(self.joints), " / ".join(self.required_columns)
        super().__init__(
            name or f"{self.kind}@{'+'.join(self.joints)}",
            text,
            EffectText(
                title=f"backlash of {joint} (approach-direction dependence)",
                definition=", ".join(f"{s} += {b} {c} / 2" for s, b, _, c in self.each),
                explanation="Gears, couplings and the servo's dead band let "
                f"{joint} stop a little short of the commanded angle, on the side it came "
                "from: its position error differs by b between approaches from below "
                f"({column} = +1) and from above ({column} = -1).",
                confirm="Approach a few positions alternately from both directions and compare: "
                "a backlash flips sign with the approach direction; a unidirectional approach "
                "removes it.",
            ),
        )

        self.plausibility = tuple(  # docs/plausibility.md
            plausible((b,), f"a drive of {j.joint} with {{amplitude}} of lost motion",
                      turntable=300, mount=600)
            for j, (_, b, _, _) in zip(joints, self.each, strict=True)
        )  # fmt: skip

    def parameters(self, variables: PositionVariables):
        """The backlash of each joint whose ``dirK`` the data have, arcsec."""
        return tuple(
            ParameterSpec(b, "arcsec", ARCSEC, what)
            for _, b, what, column in self.each
            if variables.has(column)
        )

    def chain_terms(self, variables: PositionVariables):
        """``b dirK / 2`` added to each joint's position error."""
        return tuple(
            ChainTerm(site, None, {b: 0.5 * np.asarray(variables.column(column))})
            for site, b, _, column in self.each
            if variables.has(column)
        )

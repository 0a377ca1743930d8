"""``base_tilt`` on any table: the base rotated with respect to the measurement reference."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .base import ARCSEC, PRE, ChainTerm, Effect, ParameterSpec, PositionVariables

__all__ = ["BaseRotation"]


class BaseRotation(Effect):
    """Base not aligned with the reference: constant rotations about base x, y, z before ``Rt``.

    Args:
        axes: the base axes kept (default all three; the table's catalogue keeps those that
            orientation data tell apart from the base errors: a rotation about the first joint's
            axis is that joint's position error).
    """

    kind = "base_tilt"

    def __init__(self, axes: Sequence[str] = ("x", "y", "z")) -> None:
        self.axes = tuple(a for a in "xyz" if a in axes)
        self.name = self.kind
        self.title = "base not level with the reference"
        self.definition = "Rt -> " + " ".join(f"R{a}(t{a})" for a in self.axes) + " Rt (base frame)"
        self.explanation = (
            "The table stands on a floor or a pier that is not exactly level, or the reference the "
            "orientation is measured against is rotated with respect to the base: the whole "
            "table is rotated by small constant angles before anything turns."
        )
        self.confirm = (
            "Put a precision level (or electronic inclinometer) on the base mounting surface, or "
            "re-measure the reference direction; re-level the table and repeat a few positions."
        )

    def parameters(self, variables: PositionVariables):
        """``tx``, ``ty``, ``tz`` (those kept), arcsec."""
        return tuple(
            ParameterSpec(f"t{a}", "arcsec", ARCSEC, f"rotation of the base about {a}")
            for a in self.axes
        )

    def chain_terms(self, variables: PositionVariables):
        """Constant rotations about the kept base axes, before ``Rt``."""
        one = np.ones(variables.n)
        return tuple(ChainTerm(PRE, a, {f"t{a}": one}) for a in self.axes)

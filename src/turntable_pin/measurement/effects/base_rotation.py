"""``base_tilt``: the base rotated with respect to the measurement reference, on any table."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .base import (
    ARCSEC,
    PRE,
    ChainTerm,
    Effect,
    EffectText,
    Labels,
    ParameterSpec,
    PositionVariables,
    plausible,
)

__all__ = ["BaseRotation"]


class BaseRotation(Effect):
    """Base not aligned with the reference: constant rotations about base x, y, z before ``Rt``.

    Args:
        axes: the base axes kept (default all three; the table's catalogue keeps those that
            orientation data tell apart from the base errors: a rotation about the first joint's
            axis is that joint's position error).
        name, text: the table's name and story of it (default ``base_tilt``).
        labels: ``(parameter, description)`` of each kept axis (default ``tx``...,
            ``"rotation of the base about x"``...).
    """

    kind = "base_tilt"

    def __init__(self, axes: Sequence[str] = "xyz", *, name=None, text=None, labels: Labels = ()):
        self.axes = tuple(a for a in "xyz" if a in axes)
        self.labels = tuple(labels) or tuple(
            (f"t{a}", f"rotation of the base about {a}") for a in self.axes
        )
        self.plausibility = (  # docs/plausibility.md
            plausible(tuple(t for t, _ in self.labels), "a base set up {amplitude} out of level",
                      turntable=7200, mount=7200),
        )  # fmt: skip
        super().__init__(
            name or self.kind,
            text,
            EffectText(
                title="base not level with the reference",
                definition="Rt -> "
                + " ".join(f"R{a}({t})" for a, (t, _) in zip(self.axes, self.labels, strict=True))
                + " Rt (base frame)",
                explanation="The table stands on a floor or a pier that is not exactly level, "
                "or the reference the orientation is measured against is rotated with respect "
                "to the base: the whole table is rotated by small constant angles before "
                "anything turns.",
                confirm="Put a precision level (or electronic inclinometer) on the base mounting "
                "surface, or re-measure the reference direction; re-level the table and repeat "
                "a few positions.",
            ),
        )

    def parameters(self, variables: PositionVariables):
        """One angle per kept axis (``tx``, ``ty``, ``tz``), arcsec."""
        return tuple(ParameterSpec(t, "arcsec", ARCSEC, what) for t, what in self.labels)

    def chain_terms(self, variables: PositionVariables):
        """Constant rotations about the kept base axes, before ``Rt``."""
        one = np.ones(variables.n)
        return tuple(
            ChainTerm(PRE, a, {t: one}) for a, (t, _) in zip(self.axes, self.labels, strict=True)
        )

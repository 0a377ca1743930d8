"""A table's own names and words for the generic effects, as data a layout carries: which
generic effect a name is (:class:`NamedEffect`), its parameters' names and its story
(:class:`EffectText`). The measurement layer's catalogue builds the effects; nothing here computes.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

__all__ = ["EffectText", "Labels", "NamedEffect"]


@dataclass(frozen=True)
class EffectText:
    """An effect's story as the reports tell it (the attributes of the measurement layer's
    ``Effect`` of the same names); a table may tell an effect in its own words: what it leaves
    ``None`` stays as the effect's class tells it."""

    title: str | None = None
    definition: str | None = None
    explanation: str | None = None
    confirm: str | None = None


Labels = tuple[tuple[str, str], ...]
"""``(parameter name or prefix of a harmonic series, description)`` of each parameter (or series)
of an effect, as a table names them."""


@dataclass(frozen=True)
class NamedEffect:
    """One generic effect under a table's own name.

    Attributes:
        name: the table's name (``outer_encoder_harmonics``); kind: the generic effect
            (``encoder_harmonics``, ``wobble_harmonics``, ``backlash``, ``gravity_sag``, ...).
        joints: the joints of a per-joint kind; labels: the parameters' names and words (empty:
            the class's own); text: its story where the table tells it otherwise.
        axes: ``base_tilt``'s axes; tied: ``gravity_sag``'s parameters as entries of ``K``.
    """

    name: str
    kind: str
    joints: tuple[str, ...] = ()
    labels: Labels = ()
    text: EffectText | None = None
    axes: tuple[str, ...] = ()
    tied: Mapping[str, Mapping[str, float]] = field(default_factory=dict)

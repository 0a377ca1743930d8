"""A table's own names and words for the generic effects, as data a layout carries.

An :class:`~turntable_pin.model.generic_table.ErrorLayout` may name some of the measurement
layer's generic effects (``encoder_harmonics`` of a joint, ``gravity_sag``, ...) in the table's
own terms: :class:`NamedEffect` says which generic effect a name is, how its parameters are called
and, in :class:`EffectText`, how the table tells its story. The measurement layer's catalogue
builds the effects and gives them these names; nothing here computes.
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
        name: the table's name of it (``outer_encoder_harmonics``).
        kind: the generic effect (``encoder_harmonics``, ``wobble_harmonics``, ``backlash``,
            ``gravity_sag``, ``base_tilt``, ``thermal_drift``, ``payload_mount``).
        joints: the joints it is an effect of (per-joint kinds).
        labels: its parameters' names and descriptions (empty: the class's own).
        text: its story where the table tells it otherwise than the class (the definitions of
            the per-joint effects are the class's own: the same words).
        axes: ``base_tilt``: the base axes it rotates about.
        tied: ``gravity_sag``: each parameter as entries of the compliance ``K``.
    """

    name: str
    kind: str
    joints: tuple[str, ...] = ()
    labels: Labels = ()
    text: EffectText | None = None
    axes: tuple[str, ...] = ()
    tied: Mapping[str, Mapping[str, float]] = field(default_factory=dict)

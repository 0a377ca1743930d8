"""The one base class of a candidate effect, of any family of data: name, story, the data columns
it needs, parameters. A family's base (orientation ``Effect``, calibration-run ``RunEffect``)
adds how an effect enters its model and its own story fields (``story_fields``, as data).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

__all__ = ["ANY_MACHINE", "STORY_TEXTS", "CandidateEffect", "Plausibility"]

ANY_MACHINE = "*"
"""The key of :attr:`Plausibility.scale` that holds for every kind of machine."""

STORY_TEXTS = ("title", "definition", "explanation", "confirm")
"""The attributes of an effect's story that are texts, besides its ``name``."""


@dataclass(frozen=True)
class Plausibility:
    """How large a group of an effect's parameters can physically be, per kind of machine.

    The group's amplitude is the root-sum-square of its fitted values in their user unit (a
    harmonic's ``c1, s1`` give its once-per-turn amplitude); beyond ``scale[kind]`` no mechanism
    of its kind on that machine makes it, and the effect is implausible there.

    Attributes:
        parameters: the names of the group's parameters (empty: all of the effect's).
        scale: ``{machine kind: largest plausible amplitude}`` in the parameters' user unit;
            :data:`ANY_MACHINE` holds for kinds not listed. A kind without a scale is not judged.
        belief: what one would have to believe to accept the amplitude, with ``{amplitude}``
            where the amplitude goes (``"an encoder disc off centre by {amplitude} of turn"``).
        unit: the parameters' user unit (how the amplitude is written).
    """

    parameters: tuple[str, ...]
    scale: Mapping[str, float]
    belief: str
    unit: str = ""

    def limit(self, machine: str) -> float | None:
        """The largest plausible amplitude on a ``machine`` kind, or None (not judged)."""
        value = self.scale.get(machine, self.scale.get(ANY_MACHINE))
        return None if value is None else float(value)

    def amplitude(self, values: Mapping[str, float]) -> float | None:
        """The group's amplitude from ``values`` (``{parameter: fitted value}``, user unit), or
        None when none of its parameters was fitted."""
        names = self.parameters or tuple(values)
        found = [values[n] for n in names if n in values]
        return math.sqrt(sum(v * v for v in found)) if found else None


class CandidateEffect:
    """Base class of a candidate effect (a plug-in of a family's catalogue): an effect sets the
    class attributes and implements ``parameters`` and its family's method.

    Attributes:
        name: the catalogue name.
        title: a few words for people.
        definition: how it changes the family's model.
        explanation: one paragraph of physics.
        confirm: how to confirm it on the machine.
        required_columns: data columns it needs; with ``any_column=True`` one of them suffices.
        story_fields: ``{attribute: the values it may take}`` of the family's own story fields.
        plausibility: the physical scale of its parameters per kind of machine
            (:class:`Plausibility`, one per group); empty: its amplitudes are not judged.
    """

    name: str = ""
    title: str = ""
    definition: str = ""
    explanation: str = ""
    confirm: str = ""
    required_columns: tuple[str, ...] = ()
    any_column: bool = False
    story_fields: Mapping[str, tuple[str, ...]] = MappingProxyType({})
    plausibility: tuple[Plausibility, ...] = ()

    def missing_columns(self, data) -> tuple[str, ...]:
        """The required columns ``data`` lacks (``data.column(name)`` is None)."""
        missing = tuple(c for c in self.required_columns if data.column(c) is None)
        if self.any_column and len(missing) < len(self.required_columns):
            return ()
        return missing

    def parameters(self, data) -> tuple:
        """The parameters (``ParameterSpec``) this effect has on ``data``."""
        raise NotImplementedError

    def describe(self) -> dict:
        """The effect's story as the reports show it (name, story fields, texts, columns)."""
        return {
            "effect": self.name,
            **{key: getattr(self, key) for key in self.story_fields},
            **{key: getattr(self, key) for key in STORY_TEXTS},
            "required_columns": list(self.required_columns),
        }

    def amount_words(self, value: float, unit: str) -> str:
        """An amplitude in words (a family's effect base may write large angles in degrees)."""
        return f"{value:.3g} {unit}".strip()

    def implausibility(self, values: Mapping[str, float], machine: str) -> str | None:
        """What one would have to believe to accept the fitted ``values`` (``{parameter: value}``
        in user units) on a ``machine`` kind, when a group's amplitude is beyond its scale
        (:class:`Plausibility`), the largest excess first; else None."""
        worst = None
        for group in self.plausibility:
            limit, amplitude = group.limit(machine), group.amplitude(values)
            if limit is None or amplitude is None or amplitude <= limit:
                continue
            if worst is None or amplitude / limit > worst[0]:
                worst = (amplitude / limit, group, amplitude, limit)
        if worst is None:
            return None
        _, group, amplitude, limit = worst
        belief = group.belief.format(amplitude=self.amount_words(amplitude, group.unit))
        return f"{belief} (where a {machine} reaches about {self.amount_words(limit, group.unit)})"

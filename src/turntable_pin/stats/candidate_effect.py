"""The one base class of a candidate effect, of any family of data: its name and story, the data
columns it needs, its parameters.

A family's effects (``measurement.effects.base.Effect`` for orientation data,
``instrument.effects.base.RunEffect`` for calibration runs) subclass :class:`CandidateEffect` and
add only how an effect enters the family's model, and the fields of its story the family adds
(``story_fields``: a run effect's ``side``), with the values they may take, as data: the reports
and the contract check read them from there.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

__all__ = ["STORY_TEXTS", "CandidateEffect"]

STORY_TEXTS = ("title", "definition", "explanation", "confirm")
"""The attributes of an effect's story that are texts, besides its ``name``."""


class CandidateEffect:
    """Base class of a candidate effect of a model family (a plug-in of the family's catalogue).

    A family's base subclasses it with how an effect enters its model; an effect subclasses
    that, sets the class attributes and implements ``parameters`` and the family's method.

    Attributes:
        name: the catalogue name.
        title: a few words for people.
        definition: how it changes the family's model.
        explanation: one paragraph of physics.
        confirm: how to confirm it on the machine.
        required_columns: data columns it needs; with ``any_column=True`` one of them suffices.
        story_fields: ``{attribute: the values it may take}`` of the fields a family adds to its
            effects' story (class data of the family's base; empty here), told by
            :meth:`describe` after the name.
    """

    name: str = ""
    title: str = ""
    definition: str = ""
    explanation: str = ""
    confirm: str = ""
    required_columns: tuple[str, ...] = ()
    any_column: bool = False
    story_fields: Mapping[str, tuple[str, ...]] = MappingProxyType({})

    def missing_columns(self, data) -> tuple[str, ...]:
        """The required columns ``data`` lacks (``data.column(name)`` is None; empty when the
        effect can be tested on them)."""
        missing = tuple(c for c in self.required_columns if data.column(c) is None)
        if self.any_column and len(missing) < len(self.required_columns):
            return ()
        return missing

    def parameters(self, data) -> tuple:
        """The parameters (``ParameterSpec``) this effect has on ``data``."""
        raise NotImplementedError

    def describe(self) -> dict:
        """The effect's story, as the reports show it: its name, the family's story fields, its
        texts and the columns it needs."""
        return {
            "effect": self.name,
            **{key: getattr(self, key) for key in self.story_fields},
            **{key: getattr(self, key) for key in STORY_TEXTS},
            "required_columns": list(self.required_columns),
        }

"""The one base class of a candidate effect, of any family of data: name, story, the data columns
it needs, parameters. A family's base (orientation ``Effect``, calibration-run ``RunEffect``)
adds how an effect enters its model and its own story fields (``story_fields``, as data).
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

__all__ = ["STORY_TEXTS", "CandidateEffect"]

STORY_TEXTS = ("title", "definition", "explanation", "confirm")
"""The attributes of an effect's story that are texts, besides its ``name``."""


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

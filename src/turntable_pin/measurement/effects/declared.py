"""An effect the user declares: a list of terms (an effect file, or one inline term).

The terms are :class:`~turntable_pin.measurement.effect_terms.EffectTerm` objects; the effect's
parameters are theirs, in order, and its definition is theirs joined by ``;``.
"""

from __future__ import annotations

from collections.abc import Sequence

from .base import ChainTerm, Effect, EffectText, ParameterSpec, PositionVariables

__all__ = ["DeclaredEffect"]


class DeclaredEffect(Effect):
    """An effect made of declared terms.

    Args:
        name: its name (unique among the effects of a run).
        terms: its terms (``EffectTerm``), already checked against the table.
        title, explanation, confirm: its story (``title`` defaults to the definition).
        source: where it was declared (an effect file, ``effects``), for messages.
        plausibility: its parameters' plausible scale per machine kind (an effect file's
            ``plausible``), empty: not judged.
    """

    def __init__(
        self,
        name: str,
        terms: Sequence,
        *,
        title: str = "",
        explanation: str = "",
        confirm: str = "",
        source: str = "",
        plausibility: Sequence = (),
    ) -> None:
        self.terms, self.source = tuple(terms), source
        self.plausibility = tuple(plausibility)
        definition = "; ".join(t.definition() for t in self.terms)
        super().__init__(name, EffectText(title or definition, definition, explanation, confirm))
        self.required_columns = tuple(
            dict.fromkeys(c for t in self.terms for c in t.required_columns())
        )

    def parameters(self, variables: PositionVariables) -> tuple[ParameterSpec, ...]:
        """Every term's parameters, in order."""
        return tuple(spec for t in self.terms for spec in t.parameters())

    def chain_terms(self, variables: PositionVariables) -> tuple[ChainTerm, ...]:
        """One :class:`ChainTerm` per term."""
        return tuple(t.chain_term(variables) for t in self.terms)

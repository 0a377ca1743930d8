"""Terms the user writes on an output itself: ``out_x~h2(phi1)``, ``out_y~poly2(time_s)``.

The same inline shapes as the orientation terms (:mod:`turntable_pin.measurement.effect_terms`:
harmonics of a joint angle or of the sum or difference of two, a polynomial in a column, the sign
of an approach direction), added to ``out_x`` or ``out_y`` in deg/h: what the structure search
of a run names when no catalogued effect has the shape, and what a calibration's ``effects`` add.
A term on a table site (``dphi_z2~h3(phi2)``, ``dpsi~h1(phi2)``) is an orientation term and goes
through the rate sensitivity (:class:`~.table_side.TableEffect`).
"""

from __future__ import annotations

import numpy as np

from ...core.exceptions import InputError
from ...measurement.effect_terms import parse_term
from ...measurement.user_effects import inline_effect
from .base import INSTRUMENT, ParameterSpec, RunContext, RunEffect
from .table_side import TableEffect

__all__ = ["OUTPUT_SITES", "OutputTerm", "run_term"]

OUTPUT_SITES = ("out_x", "out_y")
"""The sites of an output term."""


class OutputTerm(RunEffect):
    """One inline term on an output (module docstring), named by its text."""

    side = INSTRUMENT

    def __init__(self, text: str, table) -> None:
        site, _, shape = str(text).strip().partition("~")
        if site not in OUTPUT_SITES:
            raise InputError(f"term '{text}': an output term's site is out_x or out_y")
        # The shape is read by the orientation terms' parser, on a stand-in site.
        self.term = parse_term(f"dpsi~{shape}", table)
        self.channel = OUTPUT_SITES.index(site)
        self.name = f"{site}~{shape}"
        self.title = f"a term {shape} on {site}"
        self.definition = f"{site} += " + self.term.definition().split("+= ", 1)[1]
        self.explanation = (
            "A shape the structure search found in the outputs that no catalogued effect has: "
            "added as it is, it tells how much of the residual it explains, not what causes it."
        )
        self.confirm = "Look for a cause with this shape on the bench (see the plots)."
        self.required_columns = self.term.required_columns()

    def parameters(self, run) -> tuple[ParameterSpec, ...]:
        """This effect's parameters on ``run`` (their user units and scales)."""
        out = []
        for spec in self.term.parameters():
            unit = spec.unit.replace("arcsec", "deg/h")
            what = spec.description.replace("dpsi", OUTPUT_SITES[self.channel])
            out.append(ParameterSpec(spec.name, unit, 1.0, what))
        return tuple(out)

    def columns(self, context: RunContext) -> np.ndarray:
        """``d(out_x, out_y)/d(parameter)`` at each position, (N, 2, p), deg/h per internal unit."""
        weights = self.term.chain_term(context.variables).weights
        names = [s.name for s in self.term.parameters()]
        out = np.zeros((context.run.n_positions, 2, len(names)))
        for k, name in enumerate(names):
            out[:, self.channel, k] = weights[name]
        return out


def run_term(text: str, table) -> RunEffect:
    """The run effect of one inline term: on an output (:class:`OutputTerm`) or on the table's
    orientation (:class:`~.table_side.TableEffect` of the orientation term)."""
    if str(text).strip().split("~", 1)[0] in OUTPUT_SITES:
        return OutputTerm(text, table)
    return TableEffect(table, inline_effect(text, table))

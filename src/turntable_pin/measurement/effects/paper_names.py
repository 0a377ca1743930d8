"""The paper's nine effect names (:data:`PAPER_EFFECTS`), re-exported from the data its layout
carries (:mod:`turntable_pin.model.paper_table`); :class:`NamedEffect` is the model layer's."""

from __future__ import annotations

from ...model.named_effects import NamedEffect
from ...model.paper_table import PAPER_EFFECTS

__all__ = ["PAPER_EFFECTS", "NamedEffect"]

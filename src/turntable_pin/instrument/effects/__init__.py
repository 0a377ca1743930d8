"""Candidate effects of a calibration run, on the table's side and on the instrument's.

- table side (:mod:`.table_side`): each base error (``table:<error>``) and orientation effect
  (``table:<effect>``) of the table, through eqs. 8-13 (not ``payload_mount``: the instrument's
  tilt and heading are the same rotation);
- instrument side: :mod:`.mount`, :mod:`.bias_drift`, :mod:`.temperature`,
  :mod:`.earth_rate_scale`, :mod:`.g_squared`;
- :mod:`.output_terms`: inline terms on an output (``out_x~h2(phi1)``).

A user's effect is a :class:`~.base.RunEffect` subclass passed in the catalogue.
"""

from __future__ import annotations

from collections.abc import Sequence

from ...core.exceptions import InputError
from ...measurement.catalogue import catalogue
from ...measurement.table import measured_table
from .base import INSTRUMENT, TABLE, RunContext, RunEffect
from .bias_drift import BiasDrift
from .earth_rate_scale import EarthRateScale
from .g_squared import GSquaredTerms
from .mount import InstrumentHeading, InstrumentTilt
from .output_terms import run_term
from .table_side import PREFIX, TableEffect, TableError
from .temperature import TemperatureCoefficient

__all__ = [
    "INSTRUMENT",
    "INSTRUMENT_EFFECTS",
    "TABLE",
    "RunContext",
    "RunEffect",
    "resolve_run_effects",
    "run_catalogue",
]

INSTRUMENT_EFFECTS = (
    InstrumentTilt,
    InstrumentHeading,
    BiasDrift,
    TemperatureCoefficient,
    EarthRateScale,
    GSquaredTerms,
)
"""The instrument-side effect classes, in catalogue order."""

_LEFT_OUT_KINDS = ("payload_mount",)
"""Table effects left out of the run catalogue (the instrument side has them)."""


def run_catalogue(table=None) -> tuple[RunEffect, ...]:
    """The candidate effects of a run on ``table`` (module docstring): the table side first,
    then the instrument's."""
    measured = measured_table(table)
    out: list[RunEffect] = [TableError(measured, name) for name in measured.base_names]
    out += [
        TableEffect(measured, effect)
        for effect in catalogue(measured)
        if getattr(effect, "kind", "") not in _LEFT_OUT_KINDS
    ]
    out += [cls() for cls in INSTRUMENT_EFFECTS]
    return tuple(out)


def resolve_run_effects(names: Sequence[str], table=None, extra=()) -> list[RunEffect]:
    """The effects called ``names`` in the run catalogue of ``table`` (plus ``extra``, the
    user's); a table effect may be named without its ``table:`` prefix; an inline term
    (``out_x~h2(phi1)``, ``dpsi~h1(phi2)``) is :func:`~.output_terms.run_term`'s."""
    known = {e.name: e for e in (*run_catalogue(table), *extra)}
    out = []
    for name in names:
        name = name.strip()
        effect = known.get(name) or known.get(PREFIX + name)
        if effect is None and "~" in name:
            effect = run_term(name.removeprefix(PREFIX), measured_table(table))
        if effect is None:
            raise InputError(f"unknown run effect '{name}'; known: {', '.join(known)}")
        if effect not in out:
            out.append(effect)
    return out

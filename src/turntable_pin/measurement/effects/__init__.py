"""The candidate physical effects for orientation data (``docs/measurements.md``).

Each physical effect is one module holding one :class:`Effect` subclass, for any table; a table's
catalogue of them is :func:`turntable_pin.measurement.catalogue.catalogue`. :data:`EFFECTS` is the
paper's table's catalogue by the paper's names (``model.paper_table.PAPER_EFFECTS``);
:func:`parse_effect_spec` reads the ``NAME:P=V,...`` form the simulator takes.
"""

from __future__ import annotations

# ..catalogue is imported inside _paper_effects: it imports this package (a cycle at import)
import math

import numpy as np

from ...core.exceptions import InputError
from ...model.paper_table import PAPER_EFFECTS
from .base import ChainTerm, Effect, EffectText, ParameterSpec, PositionVariables
from .contract import checked_parameters

EFFECT_NAMES: tuple[str, ...] = tuple(e.name for e in PAPER_EFFECTS)
"""The paper's table's catalogue names, in catalogue order."""


def _paper_effects() -> dict[str, Effect]:
    """:data:`EFFECTS`, built on first use (it reads the paper's table)."""
    if "EFFECTS" not in globals():
        from ..catalogue import catalogue

        globals()["EFFECTS"] = {e.name: e for e in catalogue()}
    return globals()["EFFECTS"]


def __getattr__(name: str):
    if name == "EFFECTS":
        return _paper_effects()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


EFFECTS: dict[str, Effect]
"""The paper's table's catalogue by name, in catalogue order (:data:`EFFECT_NAMES`)."""


def get_effect(name: str) -> Effect:
    """The paper's catalogued effect ``name``; :class:`InputError` listing the known names
    otherwise."""
    try:
        return _paper_effects()[name.strip()]
    except KeyError:
        raise InputError(
            f"unknown effect '{name}'; catalogued effects: {', '.join(EFFECT_NAMES)}"
        ) from None


def parameter_names(effect: Effect) -> tuple[str, ...]:
    """Every parameter ``effect`` can have (those that need ``time_s``/``dir1``/``dir2`` too)."""
    return tuple(spec.name for spec in _every_parameter(effect))


def _every_parameter(effect: Effect):
    one = np.zeros((1, 3))
    dirs = (one[:, 0] + 1,) * 3
    return checked_parameters(effect, PositionVariables(one, one[:, 0], dirs), "one position")


def parse_effect_spec(text: str, resolve=None) -> tuple[str, dict[str, float]]:
    """``"NAME:P=V,P=V"`` -> ``(name, {P: V})`` with values in the effect's user units.

    Refused (:class:`InputError`): an unknown effect; no parameters (the effect would add
    nothing); a ``:`` with nothing after it; an item that is not ``P=V`` (empty items between
    commas are skipped); a parameter given twice; a value that is not a finite number. Whether
    each ``P`` is a parameter of the effect is checked where the data are known
    (:func:`simulate_measurements`). ``resolve`` finds an effect by name (default: the paper's
    catalogue, :func:`get_effect`; a table's ``MeasuredTable.resolve`` for its own names).
    """
    name, colon, rest = str(text).partition(":")
    effect = (resolve or get_effect)(name)
    specs = _every_parameter(effect)
    units = "/".join(dict.fromkeys(spec.unit for spec in specs))
    names = f"{', '.join(spec.name for spec in specs)} in {units}"
    example = f"{effect.name}:{specs[0].name}=1"
    if colon and not rest.strip():
        raise InputError(
            f"a ':' with no parameters after it; give them as {effect.name}:P=V,... "
            f"(parameters: {names})"
        )
    params: dict[str, float] = {}
    for item in filter(None, (x.strip() for x in rest.split(","))):
        key, eq, value = (part.strip() for part in item.partition("="))
        if not eq or not key:
            raise InputError(f"expected NAME:P=V,... , got '{item}' (parameters: {names})")
        if key in params:
            raise InputError(f"parameter '{key}' is given twice")
        try:
            number = float(value)
        except ValueError:
            raise InputError(f"parameter '{key}': expected a number, got '{value}'") from None
        if not math.isfinite(number):
            raise InputError(f"parameter '{key}': expected a finite number, got '{value}'")
        params[key] = number
    if not params:
        raise InputError(
            f"effect '{effect.name}' without parameters would simulate nothing; give at least "
            f"one of {names} (e.g. {example})"
        )
    return effect.name, params


__all__ = [
    "EFFECTS",
    "EFFECT_NAMES",
    "ChainTerm",
    "Effect",
    "EffectText",
    "ParameterSpec",
    "PositionVariables",
    "get_effect",
    "parameter_names",
    "parse_effect_spec",
]

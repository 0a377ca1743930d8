"""The catalogue of candidate physical effects for orientation data (``docs/measurements.md``).

Each effect is one module holding one :class:`Effect` subclass. Adding an effect is a new module
and one line in :data:`_REGISTRY`; nothing else changes. :func:`parse_effect_spec` reads the
``NAME:P=V,...`` form the simulator takes.
"""

from __future__ import annotations

import math

import numpy as np

from ...core.exceptions import InputError
from .backlash import Backlash
from .base import ChainTerm, Effect, ParameterSpec, PositionVariables
from .base_tilt import BaseTilt
from .gravity_sag import GravitySag
from .inner_encoder_harmonics import InnerEncoderHarmonics
from .inner_wobble_harmonics import InnerWobbleHarmonics
from .outer_encoder_harmonics import OuterEncoderHarmonics
from .outer_wobble_harmonics import OuterWobbleHarmonics
from .payload_mount import PayloadMount
from .thermal_drift import ThermalDrift

_REGISTRY: tuple[type[Effect], ...] = (
    OuterEncoderHarmonics,
    InnerEncoderHarmonics,
    OuterWobbleHarmonics,
    InnerWobbleHarmonics,
    GravitySag,
    BaseTilt,
    ThermalDrift,
    Backlash,
    PayloadMount,
)

EFFECTS: dict[str, Effect] = {cls.name: cls() for cls in _REGISTRY}
"""Every catalogued effect by its catalogue name, in catalogue order."""

EFFECT_NAMES: tuple[str, ...] = tuple(EFFECTS)
"""The catalogue names, in catalogue order."""


def get_effect(name: str) -> Effect:
    """The catalogued effect ``name``; :class:`InputError` listing the known names otherwise."""
    try:
        return EFFECTS[name.strip()]
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
    return effect.parameters(PositionVariables(one, one[:, 0], dirs))


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
    "ParameterSpec",
    "PositionVariables",
    "get_effect",
    "parameter_names",
    "parse_effect_spec",
]

"""The catalogue of candidate physical effects for orientation data (``docs/measurements.md``).

Each effect is one module holding one :class:`Effect` subclass. Adding an effect is a new module
and one line in :data:`_REGISTRY`; nothing else changes.
"""

from __future__ import annotations

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


def parse_effect_list(text: str) -> tuple[Effect, ...]:
    """``"a,b"`` -> the effects a and b (duplicates refused, empty items ignored)."""
    names = [item.strip() for item in text.split(",") if item.strip()]
    if len(set(names)) != len(names):
        raise InputError(f"an effect is listed twice in '{text}'")
    return tuple(get_effect(n) for n in names)

__all__ = [
    "EFFECTS",
    "EFFECT_NAMES",
    "ChainTerm",
    "Effect",
    "ParameterSpec",
    "PositionVariables",
    "get_effect",
    "parse_effect_list",
]

"""What a candidate effect of a calibration run is: parameters, how it moves the outputs, story.

A run effect adds to ``out_x, out_y`` terms *linear in its parameters*: its columns are
``d(out_x, out_y)/d(parameter)`` (deg/h per internal unit) in a :class:`RunContext`. The table's
effects reach the outputs through the rate sensitivity (eqs. 8-13), the instrument's directly;
each says on which ``side`` it lives. An instrument effect also says what it plants in a
simulated run along the exact path (:meth:`RunEffect.planted_dph`), up to its ``limit``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from ...measurement.effects.base import ParameterSpec, PositionVariables, angle_words, plausible
from ...stats.candidate_effect import CandidateEffect

__all__ = [
    "INSTRUMENT",
    "TABLE",
    "ParameterSpec",
    "plausible",
    "RunContext",
    "RunEffect",
    "Sensed",
    "run_variables",
]

TABLE = "table"
"""``side`` of an effect of the turntable (its errors reach the outputs through dR)."""
INSTRUMENT = "instrument"
"""``side`` of an effect of the GyroWheel itself."""


@dataclass
class RunContext:
    """What an effect's columns are evaluated with: the ``run``, the ``sensitivity`` (N, 2, 3)
    ``d(out_x, out_y)/d(dpsi, dtheta, dgamma)`` (deg/h per rad) at its ``coefficients`` (2, 7),
    its ``variables`` and a ``memo`` of values its effects share (computed once per run)."""

    run: object
    sensitivity: np.ndarray
    coefficients: np.ndarray
    variables: PositionVariables
    memo: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Sensed:
    """What the GyroWheel senses in a simulated run along the exact path: ``force_g`` and
    ``rate_dph`` (N, 3), ``time_s`` (N,) s and ``temperature_c`` (N,) degC or ``None``."""

    force_g: np.ndarray
    rate_dph: np.ndarray
    time_s: np.ndarray
    temperature_c: np.ndarray | None


def run_variables(run) -> PositionVariables:
    """The run's joint angles, time and extra columns (cached on the run: its effects share it)."""
    cached = run.__dict__.get("_variables")
    if cached is None:
        cached = PositionVariables(
            run.joint_rad, run.time_s, (), dict(run.extra), ignored_columns=run.ignored_columns
        )
        object.__setattr__(run, "_variables", cached)
    return cached


class RunEffect(CandidateEffect):
    """Base class of a candidate effect of a calibration run (a plug-in): a ``CandidateEffect``
    (name, story, required columns) with the ``side`` it lives on (``"table"`` or
    ``"instrument"``, its story field); subclasses implement :meth:`parameters` and
    :meth:`columns`."""

    side: str = INSTRUMENT
    story_fields = MappingProxyType({"side": (TABLE, INSTRUMENT)})
    limit: float = 0.0
    """Largest ``|value|`` of a parameter a simulated run may plant, in its user unit (0: none)."""

    def parameters(self, run) -> tuple[ParameterSpec, ...]:
        """The parameters this effect has on ``run``."""
        raise NotImplementedError

    def amount_words(self, value: float, unit: str) -> str:
        """An amplitude in words (large angles in arc minutes or degrees)."""
        return angle_words(value, unit)

    def columns(self, context: RunContext) -> np.ndarray:
        """``d(out_x, out_y)/d(parameter)``, (N, 2, p), deg/h per internal unit."""
        raise NotImplementedError

    def planted_dph(self, values: dict[str, float], sensed: Sensed) -> np.ndarray:
        """What ``values`` (``{parameter: value}``, user units) add to ``(out_x, out_y)`` of a
        simulated run that ``sensed`` (N, 2) deg/h: the exact form, not the columns' linear one."""
        raise NotImplementedError

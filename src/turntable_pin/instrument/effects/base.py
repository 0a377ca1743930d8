"""What a candidate effect of a calibration run is: parameters, how it moves the outputs, story.

A run effect adds to ``out_x, out_y`` terms *linear in its parameters*: its columns are
``d(out_x, out_y)/d(parameter)`` (deg/h per internal unit) in a :class:`RunContext`. The table's
effects reach the outputs through the rate sensitivity (eqs. 8-13), the instrument's directly;
each says on which ``side`` it lives.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from ...measurement.effects.base import ParameterSpec, PositionVariables
from ...stats.candidate_effect import CandidateEffect

__all__ = ["INSTRUMENT", "TABLE", "ParameterSpec", "RunContext", "RunEffect", "run_variables"]

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

    def parameters(self, run) -> tuple[ParameterSpec, ...]:
        """The parameters this effect has on ``run``."""
        raise NotImplementedError

    def columns(self, context: RunContext) -> np.ndarray:
        """``d(out_x, out_y)/d(parameter)``, (N, 2, p), deg/h per internal unit."""
        raise NotImplementedError

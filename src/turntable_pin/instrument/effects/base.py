"""What a candidate effect of a calibration run is: parameters, how it moves the outputs, story.

A run effect adds to the two outputs ``out_x, out_y`` terms *linear in its parameters*: its
:meth:`RunEffect.columns` are ``d(out_x, out_y)/d(parameter)`` at each position (deg/h per
internal unit), evaluated in a :class:`RunContext` (the run, and the rate sensitivity of the
outputs to an orientation error at the run's calibrated coefficients). Effects of the table
reach the outputs through that sensitivity (eqs. 8-13); the instrument's own add to the outputs
directly. Each effect says on which side it lives (``side``: ``"table"`` or ``"instrument"``),
its physical story and how to confirm it.
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
    """What an effect's columns are evaluated with.

    Attributes:
        run: the :class:`~turntable_pin.calibration.run.CalibrationRun`.
        sensitivity: (N, 2, 3) ``d(out_x, out_y)/d(dpsi, dtheta, dgamma)``, deg/h per rad, at
            the run's calibrated coefficients (:func:`..sensitivity.rate_sensitivity_dph`).
        coefficients: (2, 7) those coefficients.
        variables: the run's :class:`PositionVariables` (joint angles, time, extra columns).
        memo: values computed once per run and shared by the effects (the orientation
            Jacobian of the table's errors).
    """

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
    """Base class of a candidate effect of a calibration run (a plug-in): the one base of every
    family's effects (:class:`~turntable_pin.stats.candidate_effect.CandidateEffect`: name,
    story, required columns, parameters) with the side it lives on and how it moves the outputs.

    Subclasses set the class attributes and implement :meth:`parameters` and :meth:`columns`.

    Attributes:
        name: the catalogue name.
        side: ``"table"`` or ``"instrument"`` (the run family's story field: ``story_fields``).
        title, definition, explanation, confirm: its story for the reports (what it is, how it
            changes the outputs, one paragraph of physics, how to confirm it on the bench).
        required_columns: run columns it needs (``time_s``, ``temperature_c``).
    """

    side: str = INSTRUMENT
    story_fields = MappingProxyType({"side": (TABLE, INSTRUMENT)})

    def parameters(self, run) -> tuple[ParameterSpec, ...]:
        """The parameters this effect has on ``run``."""
        raise NotImplementedError

    def columns(self, context: RunContext) -> np.ndarray:
        """``d(out_x, out_y)/d(parameter)``, (N, 2, p), deg/h per internal unit."""
        raise NotImplementedError

"""Run effects the user writes (Python files of effects modules), checked once where they enter.

:func:`load_run_effects_modules` loads the :class:`~.effects.base.RunEffect` subclasses of Python
files (the file is code that runs) and :func:`check_user_run_effects` checks them before any fit:
their names (none of the run catalogue's, with or without ``table:``; no two alike) and their
contract (:func:`~.effects.contract.check_run_effect`) on a probe of a few of the run's positions
and on the run itself. Every problem is one line naming the file and the effect.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..calibration.positions import PositionSet, position_inputs
from ..calibration.run import CalibrationRun
from ..core.user_code import is_user_code
from ..measurement.effects.base import PositionVariables
from ..measurement.effects.contract import check_story
from ..measurement.user_effects import check_user_effect_names, load_effects_module
from .effects import run_catalogue
from .effects.base import RunContext, RunEffect
from .effects.contract import check_run_effect
from .effects.table_side import PREFIX
from .model import run_context
from .sensitivity import rate_sensitivity_dph

__all__ = ["PROBE_POSITIONS", "check_user_run_effects", "load_run_effects_modules", "probe_context"]

PROBE_POSITIONS = 7
"""Positions of the probe a run effect is first called on (5 when the run has 7)."""


def probe_context(run, coefficients: np.ndarray) -> RunContext:
    """A :class:`RunContext` of a few of ``run``'s positions (:data:`PROBE_POSITIONS`, every
    third row, cycling, with their times and extra columns) at ``coefficients``: a run of another
    size, on which an effect that built its arrays for the run's size shows it."""
    count = PROBE_POSITIONS if run.n_positions != PROBE_POSITIONS else PROBE_POSITIONS - 2
    rows = (3 * np.arange(count)) % run.n_positions
    positions = PositionSet(run.joint_rad[rows], table=run.table, name="probe")

    def taken(values):
        return None if values is None else np.asarray(values)[rows]

    probe = CalibrationRun(
        position_inputs(positions, run.inputs.latitude_rad),
        run.outputs_dph[rows],
        taken(run.sigma_dph),
        taken(run.time_s),
        {name: taken(values) for name, values in run.extra.items()},
        taken(run.rows),
        run.source,
    )
    beta = np.asarray(coefficients, dtype=float)
    return RunContext(
        run=probe,
        sensitivity=rate_sensitivity_dph(probe.inputs, beta),
        coefficients=beta,
        variables=PositionVariables(probe.joint_rad, probe.time_s, (), dict(probe.extra)),
    )


def _catalogue_names(table) -> dict[str, RunEffect]:
    """``{name: effect}`` of the run catalogue, each table effect also without ``table:``
    (``effects`` take it so)."""
    out: dict[str, RunEffect] = {}
    for effect in run_catalogue(table):
        out[effect.name] = effect
        out.setdefault(effect.name.removeprefix(PREFIX), effect)
    return out


def check_user_run_effects(effects: Sequence[RunEffect], run) -> tuple[RunEffect, ...]:
    """``effects`` (the user's run effects) if their names are free and each keeps its contract
    on a probe of the run (:func:`probe_context`) and on ``run`` itself, before any fit.

    Raises:
        InputError: a bad name, a name of the run catalogue, a name two effects share (naming
            both definitions: file and class).
        UserCodeError: an effect that raises or breaks its contract: one line naming the file,
            the effect, the method, what it returned and what was expected.
    """
    for effect in effects:
        if is_user_code(effect):
            check_story(effect, RunEffect)
    check_user_effect_names(effects, taken=_catalogue_names(run.table))
    # the package's own are not checked; an effect a column of which the run lacks cannot be
    # tested on it (the diagnosis says so)
    users = [e for e in effects if is_user_code(e) and not e.missing_columns(run)]
    if users:
        context = run_context(run)
        probe = probe_context(run, context.coefficients)
        on = f"a probe of {probe.run.n_positions} of the run's rows"
        for effect in users:
            check_run_effect(effect, probe, on=on)
            check_run_effect(effect, context)
    return tuple(effects)


def load_run_effects_modules(paths: Sequence[str | Path], run) -> tuple[RunEffect, ...]:
    """The run effects of the Python files ``paths``, in order, checked against ``run``
    (:func:`check_user_run_effects`)."""
    effects = [e for path in paths for e in load_effects_module(path, RunEffect)]
    return check_user_run_effects(effects, run)

"""The table's errors and effects, as a calibration run sees them (eqs. 7-14).

A base error of the table (orthogonality, wobble, position) or an effect of its orientation
catalogue moves the payload by ``(dpsi, dtheta, dgamma)``; the outputs change by the rate
sensitivity times that. The orientation derivatives come from the measurement layer's exact chain
(``OrientationModel``): every table the orientation diagnosis knows, under its names prefixed
``table:``.
"""

from __future__ import annotations

import numpy as np

from ...measurement.effect_model import OrientationModel
from ...measurement.effects.base import ARCSEC, Effect
from .base import TABLE, ParameterSpec, RunContext, RunEffect, plausible, run_variables

__all__ = ["PREFIX", "TableEffect", "TableError", "TableErrors"]

PREFIX = "table:"
"""The prefix of the name of a table-side candidate."""


def _orientation_jacobian(context: RunContext, table, effects=()) -> np.ndarray:
    """``d(dpsi, dtheta, dgamma)/d(parameters)`` of the table's base errors and ``effects`` at
    zero, (N, 3, n) (the base errors' part computed once per run)."""
    model = OrientationModel(context.variables, tuple(effects), table)
    return model.jacobian(np.zeros(model.n_params))


def _base_jacobian(context: RunContext, table) -> np.ndarray:
    """The orientation Jacobian (N, 3, n_base) of the table's base errors, once per run."""
    key = ("table_base", id(table))
    if key not in context.memo:
        context.memo[key] = _orientation_jacobian(context, table)
    return context.memo[key]


class TableError(RunEffect):
    """One of the table's base errors (a constant orientation error of a joint placement).

    Args:
        table: the :class:`~turntable_pin.measurement.table.MeasuredTable`.
        error: the base error's name (``deps_x``).
    """

    side = TABLE

    def __init__(self, table, error: str) -> None:
        self.table = table
        self.error = error
        self.name = f"{PREFIX}{error}"
        what = table.descriptions.get(error, error)
        self.title = f"the table's {what}"
        self.definition = (
            f"{error} (arcsec) in the table's joint placements: the payload turns by "
            f"d(dpsi, dtheta, dgamma)/d{error} x {error} at each position; the outputs by the "
            "rate sensitivity times that (eqs. 8-13)"
        )
        self.explanation = (
            f"The turntable's {what} turns the payload away from the attitude the calibration "
            "assumes, so the GyroWheel sees gravity and the earth rate along slightly other "
            "directions than eq. 3 says. The drift coefficients absorb what moves the outputs "
            "like a change of the coefficients; the rest is left in the residuals with the "
            "pattern of this error over the positions."
        )
        self.confirm = (
            "Measure the table's orientation errors directly (autocollimator and polygon, or "
            f"an inclinometer on the payload) and fit them: `turntable-pin diagnose` of those "
            f"measurements names {error} when it is there; or calibrate again with the table's "
            "error compensated in the positions (eq. 3 computed from the measured attitude)."
        )
        self.plausibility = (  # docs/plausibility.md
            plausible(("value",), f"a table whose {what} is {{amplitude}}", turntable=600),
        )

    def parameters(self, run) -> tuple[ParameterSpec, ...]:
        """This effect's parameters on ``run`` (their user units and scales)."""
        return (ParameterSpec("value", "arcsec", ARCSEC, f"{self.error}: the table error"),)

    def columns(self, context: RunContext) -> np.ndarray:
        """``d(out_x, out_y)/d(parameter)`` at each position, (N, 2, p), deg/h per internal unit."""
        jac = _base_jacobian(context, self.table)
        k = self.table.base_names.index(self.error)
        return np.einsum("nca,na->nc", context.sensitivity, jac[:, :, k])[:, :, None]


class TableEffect(RunEffect):
    """An effect of the table's orientation catalogue (wobble or encoder harmonics, gravity
    sag...), seen through the outputs.

    Args:
        table: the :class:`~turntable_pin.measurement.table.MeasuredTable`.
        effect: the orientation :class:`~turntable_pin.measurement.effects.base.Effect`.
    """

    side = TABLE

    def __init__(self, table, effect: Effect) -> None:
        self.table = table
        self.effect = effect
        self.name = f"{PREFIX}{effect.name}"
        self.title = f"the table's {effect.title}"
        self.definition = (
            f"{effect.definition}; the outputs change by the rate sensitivity times the "
            "orientation it adds (eqs. 8-13)"
        )
        self.explanation = effect.explanation
        self.confirm = effect.confirm
        self.required_columns = tuple(effect.required_columns)
        self.plausibility = tuple(effect.plausibility)

    def missing_columns(self, run) -> tuple[str, ...]:
        """The run columns the orientation effect needs and ``run`` lacks."""
        return self.effect.missing_columns(run_variables(run))

    def parameters(self, run) -> tuple[ParameterSpec, ...]:
        """This effect's parameters on ``run`` (their user units and scales)."""
        return tuple(self.effect.parameters(run_variables(run)))

    def columns(self, context: RunContext) -> np.ndarray:
        """``d(out_x, out_y)/d(parameter)`` at each position, (N, 2, p), deg/h per internal unit."""
        jac = _orientation_jacobian(context, self.table, (self.effect,))
        own = jac[:, :, len(self.table.base_names) :]
        return np.einsum("nca,nap->ncp", context.sensitivity, own)


class TableErrors(RunEffect):
    """All of the table's base errors at once (``table:errors``): what any rigid error set of
    the URDF does to the outputs. Not a catalogue candidate (it would pay for every error);
    the diagnosis asks it whether an instrument effect is one the table's errors make too."""

    side = TABLE
    name = f"{PREFIX}errors"
    title = "the table's errors (any rigid error set of its URDF)"
    definition = "every base error of the table at once, through eqs. 8-13"
    explanation = (
        "Any set of the table's constant errors (orthogonality, wobble constants, position "
        "offsets) turns the payload by a pattern over the positions fixed by the URDF."
    )
    confirm = (
        "Measure the table's orientation errors directly (autocollimator and polygon, or an "
        "inclinometer on the payload) and diagnose them with `turntable-pin diagnose`."
    )

    def __init__(self, table) -> None:
        self.table = table

    def parameters(self, run) -> tuple[ParameterSpec, ...]:
        """This effect's parameters on ``run`` (their user units and scales)."""
        return tuple(
            ParameterSpec(name, "arcsec", ARCSEC, self.table.descriptions.get(name, name))
            for name in self.table.base_names
        )

    def columns(self, context: RunContext) -> np.ndarray:
        """``d(out_x, out_y)/d(parameter)`` at each position, (N, 2, p), deg/h per internal unit."""
        return np.einsum("nca,nap->ncp", context.sensitivity, _base_jacobian(context, self.table))

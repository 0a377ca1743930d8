"""What the two simulators share (orientation data, :mod:`.simulation`; calibration runs,
:mod:`turntable_pin.instrument.simulate`): the checks of the planted effects' values, of the noise,
of the dwell and the time columns, and the CSV under comment lines of what made it.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ..core.csv_table import write_csv_table
from ..core.exceptions import InputError
from ..core.sizes import MAX_TIME_S
from ..core.words import argument
from ..model.errors import MAX_ANGULAR_ERROR_DEG
from .catalogue import resolve_effect
from .effect_model import OrientationModel
from .table import measured_table

__all__ = [
    "MAX_EFFECT_VALUE",
    "SimulatedFile",
    "check_dwell",
    "checked_column",
    "checked_noise",
    "checked_values",
    "planted_model",
    "run_times_s",
]

MAX_EFFECT_VALUE = MAX_ANGULAR_ERROR_DEG * 3600.0
"""Largest ``|value|`` of a planted table effect's parameter in its user unit (arcsec, arcsec/g,
arcsec/h): an effect is a small error."""


def checked_values(what: str, name: str, params, specs: Mapping, limit: float) -> dict[str, float]:
    """``params`` ``{parameter: value}`` of the ``what`` ``name`` checked: at least one, each in
    ``specs`` (``{name: ParameterSpec}``), a number within ``+-limit`` of its user unit."""
    names = ", ".join(specs)
    units = "/".join(dict.fromkeys(spec.unit for spec in specs.values()))
    if not isinstance(params, Mapping) or not params:
        raise InputError(
            f"{what} '{name}' is given without parameters, so it would simulate nothing; give at "
            f"least one of {names} ({units})"
        )
    out = {}
    for pname, value in params.items():
        if pname not in specs:
            raise InputError(f"{what} '{name}' has no parameter '{pname}'; its parameters: {names}")
        try:
            number = float(value)
        except (TypeError, ValueError):
            number = math.nan
        if isinstance(value, bool) or not abs(number) <= limit:
            raise InputError(
                f"{what} '{name}', parameter '{pname}' = {value!r}: must be a number within "
                f"+-{limit:g} {specs[pname].unit}"
            )
        out[pname] = number
    return out


def planted_model(source, vector, effects, variables, catalogue: Sequence, what: str, lacks=""):
    """``(model, parameters, {effect: values})``: the exact chain of the table ``source`` at
    ``variables`` with ``effects`` (``{effect: {parameter: value in its user unit}}``, from the
    table's catalogue and ``catalogue``) planted, its parameters at the errors ``vector`` (rad, m)
    and the effects' checked values (:func:`checked_values`); with ``lacks`` (why, in words) an
    effect needing a column ``variables`` lack is refused."""
    table = measured_table(source)
    objects, given = [], {}
    values = {
        n: float(v) for n, v in zip(source.parameter_names, vector, strict=True)
        if n in table.base_names
    }  # fmt: skip
    for name, params in dict(effects or {}).items():
        effect = resolve_effect(str(name), table, tuple(catalogue))
        missing = effect.missing_columns(variables) if lacks else ()
        if missing:
            raise InputError(f"{what} '{effect.name}' needs {', '.join(missing)}, which {lacks}")
        specs = {s.name: s for s in effect.parameters(variables)}
        given[effect.name] = checked_values(what, effect.name, params, specs, MAX_EFFECT_VALUE)
        objects.append(effect)
        for pname, value in given[effect.name].items():
            values[f"{effect.name}.{pname}"] = value * specs[pname].per_user_unit
    model = OrientationModel(variables, objects, table)
    return model, model.parameter_vector(values), given


def checked_noise(noise, name: str, sizes: tuple[int, str], low: float, high: float) -> np.ndarray:
    """``noise`` as an array of one sigma or ``sizes[0]`` (``sizes[1]`` says which, in words),
    each in [low, high] (and > 0 when ``low`` is)."""
    values = np.atleast_1d(np.asarray(noise, dtype=float))
    if values.size not in (1, sizes[0]):
        raise InputError(f"{name} takes one number or {sizes[1]}, got {values.size}")
    for value in values:
        if low > 0 and not value > 0:
            raise InputError(f"{name} must be > 0, got {value:g}")
        if not low <= value <= high:
            raise InputError(f"{name} must be in [{low:g}, {high:g}], got {value:g}")
    return values


def check_dwell(dwell_s) -> None:
    """InputError unless ``dwell_s`` (the time between measurements, s) is a number > 0."""
    if (
        isinstance(dwell_s, bool)
        or not isinstance(dwell_s, numbers.Real)
        or not 0 < dwell_s < math.inf
    ):
        raise InputError(f"dwell_s must be a number > 0, got {dwell_s!r}")


def run_times_s(n: int, dwell_s: float) -> np.ndarray:
    """``index * dwell_s`` of ``n`` measurements, s; InputError for a run beyond ``MAX_TIME_S``."""
    check_dwell(dwell_s)
    if (n - 1) * dwell_s > MAX_TIME_S:
        raise InputError(
            f"dwell_s {dwell_s:g}: the run of {n} measurements would last "
            f"{(n - 1) * dwell_s:.7g} s, more than {MAX_TIME_S:.7g} s (a year)"
        )
    return np.arange(n) * dwell_s


def checked_column(values, n: int, name: str, low: float, high: float) -> np.ndarray:
    """``values`` as an (n,) array of finite numbers in [low, high]; InputError naming ``name``."""
    array = np.asarray(values, dtype=float).reshape(-1)
    if array.size != n:
        raise InputError(f"{name}: {array.size} values for a run of {n} positions")
    if not np.all(np.isfinite(array)):
        raise InputError(f"{name}: values must be finite numbers")
    if array.min() < low or array.max() > high:
        raise InputError(f"{name}: values must be within [{low:g}, {high:g}]")
    return array


class SimulatedFile:
    """A simulated result as a CSV: its ``columns(with_sigma=)`` under comment lines of what made
    it (``_made()``) and the truth (``_truth()``; with ``hide_truth``: ``_hidden`` not recorded)."""

    _hidden = ""

    def comment(self, *, hide_truth: bool = False) -> str:
        """The comment lines above the CSV header: what made the data, the truth unless hidden."""
        if hide_truth:
            hidden = f"{self._hidden}: not recorded ({argument('hide_truth')})"
            return "\n".join([*self._made(), hidden])
        return "\n".join([*self._made(), *self._truth()])

    def write_csv(
        self, path: str | Path, *, with_sigma: bool = True, hide_truth: bool = False
    ) -> Path:
        """Write the CSV atomically under its :meth:`comment` lines (the sigma ``with_sigma``)."""
        columns = self.columns(with_sigma=with_sigma)
        return write_csv_table(path, columns, comment=self.comment(hide_truth=hide_truth))

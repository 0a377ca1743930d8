"""The contract of an :class:`~.base.Effect` plug-in, checked once where the user's effect enters.

An effect the user writes (a Python module's class, a plug-in, an object from Python) must give,
for the variables of N positions:

- its story as text (``name``, ``title``, ``definition``, ``explanation``, ``confirm``) and its
  ``required_columns`` as a tuple of column names;
- ``parameters(variables)``: a tuple of at least one :class:`~.base.ParameterSpec`, names unique,
  ``per_user_unit`` a finite number > 0;
- ``chain_terms(variables)``: a tuple of :class:`~.base.ChainTerm` on a site of the table (a base
  error, ``pre``/``post`` with axis ``x|y|z``, ``measured`` with axis ``dpsi|dtheta|dgamma``)
  whose ``weights`` map parameters it declared to a finite number or a finite array of shape
  (N,); every declared parameter weighed by some term.

:func:`check_effect` calls the methods (:func:`~turntable_pin.core.user_code.call_user`) on the
data's variables or a probe (:func:`probe_variables`); a one-line ``UserCodeError`` names the
file, the effect, the method, what it returned and what was expected. The package's own effects
are not checked.
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Mapping

import numpy as np

from ...core.exceptions import UserCodeError
from ...core.user_code import call_user, class_file, is_user_code
from ...model.angles import ANGLE_NAMES
from ...stats.candidate_effect import STORY_TEXTS, Plausibility
from .base import MEASURED, POST, PRE, ChainTerm, Effect, ParameterSpec, PositionVariables

__all__ = [
    "PROBE_POSITIONS",
    "STORY_ATTRIBUTES",
    "check_effect",
    "check_effect_on_probe",
    "check_parameters",
    "check_story",
    "checked_parameters",
    "contract_error",
    "described",
    "effect_file",
    "numbers_returned",
    "effect_label",
    "probe_variables",
]

PROBE_POSITIONS = 7
"""Positions of the probe an effect is first called on (a count no data set is likely to share,
so that an effect which built its arrays for one data set's size shows it)."""
STORY_ATTRIBUTES = ("name", *STORY_TEXTS)
"""The attributes of an effect's story, each a text."""
_ROTATION_AXES = ("x", "y", "z")
_JOINT_COLUMN = re.compile(r"^(dir|phi)\d+$")


def effect_label(effect) -> str:
    """How a message names the user's effect: ``effect 'lobes' (class Lobes)``."""
    name = getattr(effect, "name", "")
    shown = f"effect '{name}'" if isinstance(name, str) and name else "an effect without a name"
    return f"{shown} (class {type(effect).__qualname__})"


def contract_error(effect, message: str) -> UserCodeError:
    """The error of the user's ``effect`` breaking its contract: ``FILE: effect 'x' (class X):
    message``."""
    return UserCodeError(f"{effect_label(effect)}: {message}", path=effect_file(effect))


def effect_file(effect) -> str | None:
    """The file the effect came from: its ``source`` (the module it was loaded from) or its
    class's file."""
    source = getattr(effect, "source", "")
    if isinstance(source, str) and source.endswith(".py"):
        return source
    return class_file(type(effect))


def described(value) -> str:
    """A short description of a value the user's code returned."""
    if isinstance(value, np.ndarray):
        return f"an array of shape {value.shape} ({value.dtype})"
    if value is None or isinstance(value, str):
        return repr(value)
    text = repr(value)
    text = text if len(text) <= 60 else text[:57] + "..."
    return f"{type(value).__name__} {text}"


def numbers_returned(value) -> np.ndarray | None:
    """What the user's code returned as a numeric array, or ``None`` when it is not numbers
    (text, objects, an object numpy cannot read)."""
    try:
        array = np.asarray(value)
    except Exception:  # an object numpy cannot read: reported as what it is by the caller
        return None
    return array if array.dtype.kind in "biuf" else None


def check_story(effect, base: type) -> None:
    """Refuse an effect whose story attributes are not text, whose ``required_columns`` is not
    a tuple of column names or whose family story field (``base.story_fields``: a run effect's
    ``side``) is not one of the values it may take; ``base`` is the family's effect class it must
    derive from (:class:`~turntable_pin.stats.candidate_effect.CandidateEffect`'s subclass)."""
    fail = functools.partial(contract_error, effect)
    if not isinstance(effect, base):
        raise fail(f"is {described(effect)}; expected an instance of {base.__qualname__}")
    for key in STORY_ATTRIBUTES:
        value = getattr(effect, key, "")
        if not isinstance(value, str):
            raise fail(f"its {key} is {described(value)}; expected a text")
    columns = getattr(effect, "required_columns", ())
    if isinstance(columns, str):
        raise fail(
            f"its required_columns is the text {columns!r}; expected a tuple of "
            f"column names, ({columns!r},)"
        )
    if not isinstance(columns, tuple | list) or not all(
        isinstance(c, str) and c for c in columns
    ):  # fmt: skip
        raise fail(
            f"its required_columns is {described(columns)}; expected a tuple of "
            "column names such as ('time_s',)"
        )
    scales = getattr(effect, "plausibility", ())
    if not isinstance(scales, tuple | list) or not all(isinstance(p, Plausibility) for p in scales):
        raise fail(
            f"its plausibility is {described(scales)}; expected a tuple of Plausibility "
            "(turntable_pin.stats.candidate_effect), or () when its amplitudes are not judged"
        )
    for key, values in base.story_fields.items():
        value = getattr(effect, key, None)
        if value not in values:
            expected = " or ".join(f"'{v}'" for v in values)
            raise fail(f"its {key} is {described(value)}; expected {expected}")


def check_parameters(effect, specs, call: str, on: str) -> tuple[ParameterSpec, ...]:
    """``specs`` (what ``effect``'s ``call`` returned on ``on``) as a tuple of at least one
    :class:`ParameterSpec`, names unique texts, scales finite and > 0; a
    :class:`UserCodeError` otherwise."""
    fail = functools.partial(contract_error, effect)
    expected = "a tuple of ParameterSpec(name, unit, per_user_unit, description)"
    if not isinstance(specs, tuple | list):
        raise fail(f"{call} returned {described(specs)} on {on}; expected {expected}")
    if not specs:
        raise fail(
            f"{call} returned no parameter on {on}; expected {expected}, at "
            "least one (an effect without parameters adds nothing)"
        )
    seen = set()
    for k, spec in enumerate(specs, 1):
        if not isinstance(spec, ParameterSpec):
            raise fail(
                f"{call} returned {described(spec)} as parameter {k} on {on}; expected a "
                "ParameterSpec(name, unit, per_user_unit, description)"
            )
        name = spec.name
        if not isinstance(name, str) or not name.strip() or any(c.isspace() for c in name):
            raise fail(
                f"{call}: parameter {k} is named {described(name)}; expected a "
                "text without spaces (c1, k, rz)"
            )
        if name in seen:
            raise fail(f"{call} declares the parameter '{name}' twice")
        seen.add(name)
        for key in ("unit", "description"):
            if not isinstance(getattr(spec, key), str):
                raise fail(
                    f"{call}: parameter '{name}': its {key} is "
                    f"{described(getattr(spec, key))}; expected a text"
                )
        scale = spec.per_user_unit
        number = isinstance(scale, int | float | np.number) and not isinstance(scale, bool)
        if not number or not math.isfinite(float(scale)) or float(scale) <= 0:
            raise fail(
                f"{call}: parameter '{name}': per_user_unit is {described(scale)}; expected a "
                "finite number > 0 (the internal value, rad, of one user unit: ARCSEC for arcsec)"
            )
    return tuple(specs)


def checked_parameters(effect, variables: PositionVariables, on: str) -> tuple[ParameterSpec, ...]:
    """``effect.parameters(variables)``; for the user's effect called through
    :func:`~turntable_pin.core.user_code.call_user` and checked (:func:`check_parameters`),
    ``on`` naming the variables in a message."""
    if not is_user_code(effect):
        return tuple(effect.parameters(variables))
    label = effect_label(effect)
    specs = call_user(f"{label}: parameters(variables) on {on}", effect.parameters, variables,
                      path=effect_file(effect))  # fmt: skip
    return check_parameters(effect, specs, "parameters(variables)", on)


def _site_words(base_names) -> str:
    return (f"a base error ({', '.join(base_names)}), 'pre'/'post' with axis x|y|z or "
            f"'measured' with axis {'|'.join(ANGLE_NAMES)}")  # fmt: skip


def _check_site(effect, term: ChainTerm, where: str, base_names) -> None:
    fail = functools.partial(contract_error, effect)
    site, axis = term.site, term.axis
    if site in (PRE, POST):
        if axis not in _ROTATION_AXES:
            raise fail(
                f"{where}: a '{site}' term turns about axis x, y or z; got {described(axis)}"
            )
    elif site == MEASURED:
        if axis not in ANGLE_NAMES:
            raise fail(
                f"{where}: a 'measured' term adds to {', '.join(ANGLE_NAMES)}; "
                f"got axis {described(axis)}"
            )
    elif not isinstance(site, str) or site not in base_names:
        hint = f" (ChainTerm('measured', '{site}', ...))" if site in ANGLE_NAMES else ""
        raise fail(
            f"{where}: site {described(site)} is not one of this table's; expected "
            f"{_site_words(base_names)}{hint}"
        )


def _check_weight(effect, value, where: str, n: int, on: str) -> None:
    """One weight: a finite number, or a finite array of shape (n,)."""
    expected = f"a number or an array of shape ({n},), one value per position"
    array = numbers_returned(value)
    if array is None:
        raise contract_error(effect, f"{where} is {described(value)} on {on}; expected {expected}")
    if array.shape not in ((), (n,)):
        raise contract_error(
            effect, f"{where} has shape {array.shape} on {on}; expected {expected}"
        )
    bad = ~np.isfinite(array.astype(float))
    if bad.any():
        kinds = " and ".join(
            word for word, hit in (("NaN", np.isnan(array.astype(float)).any()),
                                   ("inf", np.isinf(array.astype(float)).any())) if hit
        )  # fmt: skip
        count = f" at {int(bad.sum())} of {n} positions" if array.ndim else ""
        raise contract_error(
            effect, f"{where} is not finite ({kinds}{count}) on {on}; expected finite numbers"
        )


def _check_terms(effect, terms, specs, n: int, base_names, on: str) -> tuple[ChainTerm, ...]:
    fail = functools.partial(contract_error, effect)
    call = "chain_terms(variables)"
    expected = "a tuple of ChainTerm(site, axis, weights)"
    if not isinstance(terms, tuple | list):
        raise fail(f"{call} returned {described(terms)} on {on}; expected {expected}")
    declared = [s.name for s in specs]
    weighed = set()
    for k, term in enumerate(terms, 1):
        where = f"{call}, term {k}"
        if not isinstance(term, ChainTerm):
            raise fail(
                f"{where} is {described(term)} on {on}; expected a ChainTerm(site, axis, weights)"
            )
        _check_site(effect, term, where, base_names)
        axis = f".{term.axis}" if term.site in (PRE, POST, MEASURED) else ""
        where = f"{where} (site {term.site}{axis})"
        if not isinstance(term.weights, Mapping):
            raise fail(
                f"{where}: weights is {described(term.weights)}; expected a dict {{parameter "
                "name: number or array of one value per position}"
            )
        for name, value in term.weights.items():
            if name not in declared:
                raise fail(
                    f"{where}: weight {described(name)} is not a parameter of the effect; "
                    f"parameters(variables) declares {', '.join(declared)}"
                )
            _check_weight(effect, value, f"{where}: weight '{name}'", n, on)
            weighed.add(name)
    unused = [name for name in declared if name not in weighed]
    if unused:
        raise fail(
            f"parameters(variables) declares {', '.join(repr(u) for u in unused)} "
            f"but no term of chain_terms(variables) weighs it on {on}"
        )
    return tuple(terms)


def check_effect(
    effect, variables: PositionVariables, base_names, *, on: str | None = None
) -> tuple[tuple[ParameterSpec, ...], tuple[ChainTerm, ...]]:
    """``(parameters, chain terms)`` of the user's ``effect`` on ``variables``, each checked
    against the contract (module docstring); ``base_names`` are the table's base errors (the
    sites it has), ``on`` how the message names the variables (default: ``the data (N
    positions)``).

    Raises:
        UserCodeError: a method raised, or returned something the contract does not allow: one
            line naming the file, the effect, the method, what it returned and what was expected.
    """
    on = on or f"the data ({variables.n} positions)"
    check_story(effect, Effect)
    path = effect_file(effect)
    label = effect_label(effect)
    missing = call_user(f"{label}: missing_columns(variables)", effect.missing_columns,
                        variables, path=path)  # fmt: skip
    if missing:  # the caller says the effect cannot be tested here
        return (), ()
    specs = call_user(f"{label}: parameters(variables) on {on}", effect.parameters, variables,
                      path=path)  # fmt: skip
    specs = check_parameters(effect, specs, "parameters(variables)", on)
    terms = call_user(f"{label}: chain_terms(variables) on {on}", effect.chain_terms, variables,
                      path=path)  # fmt: skip
    return specs, _check_terms(effect, terms, specs, variables.n, tuple(base_names), on)


def probe_variables(n_joints: int, columns=()) -> PositionVariables:
    """The variables of :data:`PROBE_POSITIONS` positions of a table of ``n_joints`` joints: joint
    angles spread over the turn, ``time_s`` (0 to an hour), an approach direction per joint
    (alternating) and each other column of ``columns`` (20 to 23)."""
    k = np.arange(PROBE_POSITIONS, dtype=float)
    joints = np.radians(np.stack([(37.0 * (j + 1) * k + 11.0 * j) % 360.0
                                  for j in range(n_joints)], axis=1))  # fmt: skip
    dirs = tuple(np.where((k + j) % 2 == 0, 1.0, -1.0) for j in range(n_joints))
    extra = {c: 20.0 + 0.5 * k for c in columns if c != "time_s" and not _JOINT_COLUMN.match(c)}
    return PositionVariables(joints, 600.0 * k, dirs, extra)


def check_effect_on_probe(effect, table, columns=()) -> None:
    """Check the user's ``effect`` (:func:`check_effect`) on :func:`probe_variables` of
    ``table`` (a :class:`~turntable_pin.measurement.table.MeasuredTable`) with its required
    columns and ``columns``."""
    check_story(effect, Effect)
    probe = probe_variables(table.n_joints, (*effect.required_columns, *columns))
    check_effect(effect, probe, table.base_names,
                 on=f"a probe of {PROBE_POSITIONS} positions")  # fmt: skip

"""The contract of a :class:`~.base.RunEffect` plug-in, checked once where the user's effect
enters (a class of an effects module, or an object passed from Python). On a run of N positions:

- its story as text (``name``, ``title``, ``definition``, ``explanation``, ``confirm``), its
  ``side`` (``"table"`` or ``"instrument"``) and its ``required_columns`` as a tuple of names;
- ``parameters(run)``: a tuple of at least one ``ParameterSpec``, names unique,
  ``per_user_unit`` a finite number > 0;
- ``columns(context)``: ``d(out_x, out_y)/d(parameter)``, finite numbers of shape (N, 2, p).

:func:`check_run_effect` calls them (``core.user_code.call_user``) and raises a one-line
``UserCodeError`` naming the file, the effect, the method, what it returned and what was expected.
"""

from __future__ import annotations

import numpy as np

from ...core.user_code import call_user
from ...measurement.effects.contract import (
    check_parameters,
    check_story,
    contract_error,
    described,
    effect_file,
    effect_label,
    numbers_returned,
)
from .base import ParameterSpec, RunContext, RunEffect

__all__ = ["check_run_effect"]


def check_run_effect(
    effect, context: RunContext, *, on: str | None = None
) -> tuple[tuple[ParameterSpec, ...], np.ndarray]:
    """``(parameters, columns)`` of the user's run ``effect`` in ``context``, each checked
    against the contract (module docstring); ``on`` names the run in messages.

    Raises:
        UserCodeError: a method raised, or returned what the contract does not allow.
    """
    run = context.run
    n = run.n_positions
    on = on or f"the run ({n} positions)"
    check_story(effect, RunEffect)
    path, label = effect_file(effect), effect_label(effect)
    specs = call_user(f"{label}: parameters(run) on {on}", effect.parameters, run, path=path)
    specs = check_parameters(effect, specs, "parameters(run)", on)
    columns = call_user(f"{label}: columns(context) on {on}", effect.columns, context, path=path)
    expected = (f"an array of shape ({n}, 2, {len(specs)}): d(out_x, out_y)/d(parameter) at each "
                f"of the {n} positions for its {len(specs)} parameter(s)")  # fmt: skip
    array = numbers_returned(columns)
    if array is None or array.shape != (n, 2, len(specs)):
        raise contract_error(
            effect, f"columns(context) returned {described(columns)} on {on}; expected {expected}"
        )
    array = array.astype(float)
    bad = ~np.isfinite(array)
    if bad.any():
        kinds = " and ".join(w for w, hit in (("NaN", np.isnan(array).any()),
                                              ("inf", np.isinf(array).any())) if hit)  # fmt: skip
        rows = int(bad.any(axis=(1, 2)).sum())
        raise contract_error(
            effect,
            f"columns(context) returned {kinds} at {rows} of {n} positions on "
            f"{on}; expected finite numbers",
        )
    return specs, array

"""What a result object offers a notebook: ``to_json()``, ``_repr_html_()`` and ``plot()``.

A result class of any layer inherits :class:`NotebookResult` and keeps its own ``to_dict()``. Its
HTML and figures are drawn by the report layer, which sits above it: the report layer registers
one :class:`View` per result class (:func:`register_view`, called when
:mod:`turntable_pin.report.notebook` is imported, which the flat API does); the result asks the
registry, never imports the report layer itself.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .exceptions import TurntablePinError

__all__ = ["NotebookResult", "View", "jsonable", "register_view"]


def jsonable(value: Any) -> Any:
    """``value`` as plain JSON types: numpy scalars and arrays as numbers and lists, paths as
    text, tuples as lists, NaN and infinities as ``None``."""
    import numpy as np  # numpy only when a result is serialised: import turntable_pin stays light

    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, (np.floating, float)):
        value = float(value)
        return value if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, Path):
        return str(value)
    return value


@dataclass(frozen=True)
class View:
    """How the report layer shows one result class: ``html(result) -> str`` (an HTML fragment)
    and ``figures(result) -> list`` of matplotlib figures."""

    html: Callable[[Any], str]
    figures: Callable[[Any], list]


_VIEWS: dict[type, View] = {}


def register_view(cls: type, view: View) -> None:
    """Show instances of ``cls`` (and its subclasses) with ``view``."""
    _VIEWS[cls] = view


def _view_of(result: Any) -> View:
    for cls in type(result).__mro__:
        if cls in _VIEWS:
            return _VIEWS[cls]
    raise TurntablePinError(
        f"no view of a {type(result).__name__} is registered: import turntable_pin.report.notebook "
        "(the flat API, turntable_pin.load_table and the rest, does)"
    )


class NotebookResult:
    """Mixin of a result with ``to_dict()``: serialises itself, shows itself in a notebook and
    plots itself (the views of :mod:`turntable_pin.report.notebook`)."""

    __slots__ = ()

    def to_dict(self) -> dict:  # pragma: no cover - every result class defines its own
        """The result as a JSON-ready dict."""
        raise NotImplementedError

    def to_json(self, *, indent: int | None = 2) -> str:
        """The result as JSON text (what the command's ``--json`` prints).

        Parameters
        ----------
        indent : int or None, default 2
            Indentation of the JSON text (``None``: one line).

        Returns
        -------
        str
            :meth:`to_dict` with numpy values as numbers, NaN and infinities as ``null``;
            ``json.loads`` of it gives the dict back.
        """
        return json.dumps(jsonable(self.to_dict()), indent=indent, allow_nan=False)

    def _repr_html_(self) -> str:
        """The result as an HTML fragment (Jupyter shows it)."""
        return _view_of(self).html(self)

    def plot(self) -> list:
        """The result's figures (the ones the command line's ``--plots`` writes as PNG).

        Returns
        -------
        list of matplotlib.figure.Figure
            Open figures: show them, change them, save them (``fig.savefig(path)``) or close
            them (``matplotlib.pyplot.close(fig)``). Nothing is written.

        Raises
        ------
        TurntablePinError
            The result has no figure, or no view is registered for it.
        """
        return _view_of(self).figures(self)

"""Manufacturing capability: the lower bounds ``LB_i`` of a table's angular errors (paper eq. 29).

A turntable cannot be made arbitrarily accurate; the allocation must not ask for an error component
smaller than what manufacturing reaches. A table's layout may name a bundled file of them (the
paper's: ``models/manufacturing_lower_bounds.yaml``, with the reasoning behind each value;
:meth:`ManufacturingCapability.of_table`); users pass their own YAML file of the same form, in
their table's error names (a table with none bundled: 0 unless given).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..core.exceptions import InputError
from ..core.files import read_yaml
from ..core.units import ARCSEC_PER_RAD, DEG_PER_RAD
from ..model.errors import ANGULAR_ERROR_NAMES, MAX_ANGULAR_ERROR_DEG, parse_error_value
from ..model.paper_table import resolve_table

__all__ = ["ManufacturingCapability", "read_lower_bounds_file"]


def read_lower_bounds_file(path: Path) -> Mapping:
    """The YAML file of lower bounds: a mapping ``lower_bounds: {name: value}`` and optionally
    ``reasoning:``, nothing else (the names are the caller's to read).

    Raises:
        InputError: unreadable file, not YAML, not that mapping, an unknown top-level key.
    """
    data = read_yaml(path)
    if not isinstance(data, Mapping) or not isinstance(data.get("lower_bounds"), Mapping):
        raise InputError("expected a mapping 'lower_bounds: {name: value}'", path=path)
    extra = [str(k) for k in data if k not in ("lower_bounds", "reasoning")]
    if extra:
        raise InputError(
            f"unknown top-level key(s) {', '.join(repr(k) for k in extra)}; the file holds "
            "'lower_bounds:' and optionally 'reasoning:'",
            path=path,
        )
    return data


@dataclass(frozen=True)
class ManufacturingCapability:
    """Lower bounds of a table's angular errors and why they are what they are.

    Attributes:
        lower_bounds_rad: (P,) in ``error_names`` order, radians, each in [0, 5 deg].
        reasoning: ``{error name: text}`` saying where each bound comes from.
        source: the file the bounds were read from (or a description).
        error_names: the table's angular errors (default: the paper's eight).
    """

    lower_bounds_rad: np.ndarray
    reasoning: dict[str, str] = field(default_factory=dict)
    source: str = "none"
    error_names: tuple[str, ...] = ANGULAR_ERROR_NAMES

    def __post_init__(self) -> None:
        values = np.array(self.lower_bounds_rad, dtype=float).reshape(-1)
        if values.size != len(self.error_names):
            raise InputError(
                f"expected {len(self.error_names)} lower bounds ({', '.join(self.error_names)}), "
                f"got {values.size}"
            )
        if not np.all(np.isfinite(values)) or np.any(values < 0.0):
            raise InputError("lower bounds must be finite and not negative")
        if float(values.max(initial=0.0)) > MAX_ANGULAR_ERROR_DEG / DEG_PER_RAD:
            raise InputError(f"a lower bound is beyond {MAX_ANGULAR_ERROR_DEG:g} deg")
        values.setflags(write=False)
        object.__setattr__(self, "lower_bounds_rad", values)
        object.__setattr__(self, "error_names", tuple(self.error_names))

    @classmethod
    def none(cls, error_names=ANGULAR_ERROR_NAMES) -> ManufacturingCapability:
        """No manufacturing limit (every lower bound 0)."""
        return cls(np.zeros(len(error_names)), {}, "none (all lower bounds 0)", error_names)

    @classmethod
    def of_table(cls, table=None) -> ManufacturingCapability:
        """The lower bounds bundled with ``table`` (default the bundled table): the file its
        layout names (``GenericTable.lower_bounds_path``; the paper's
        ``models/manufacturing_lower_bounds.yaml``), else none (every lower bound 0)."""
        table = resolve_table(table)
        if table.lower_bounds_path is None:
            return cls.none(tuple(table.angular_names))
        return cls.from_yaml(table.lower_bounds_path, table)

    @classmethod
    def default(cls) -> ManufacturingCapability:
        """The lower bounds bundled with the bundled table (:meth:`of_table`)."""
        return cls.of_table()

    @classmethod
    def from_yaml(cls, path: str | Path, table=None) -> ManufacturingCapability:
        """Read ``lower_bounds: {name[_unit]: value}`` and optional ``reasoning: {name: text}``
        in the names of ``table`` (a :class:`~turntable_pin.model.generic_table.GenericTable`;
        default the bundled table).

        Names without a unit suffix are arc seconds; missing names get no lower bound (0). Values
        are at most ``MAX_ANGULAR_ERROR_DEG`` (5 deg), like every angular error.

        Raises:
            InputError: unreadable file, not YAML, a key given twice (also as two spellings of one
                error), an unknown top-level key, an unknown name, a length (offset), a negative or
                non-numeric value, a value beyond the small-error range, reasoning that is not text.
        """
        path = Path(path)
        data = read_lower_bounds_file(path)
        table = resolve_table(table)
        names, angular = table.parameter_names, table.angular_names
        lengths = [n for n in names if n not in angular]
        values = np.zeros(len(angular))
        given: dict[str, str] = {}
        for key, raw in data["lower_bounds"].items():
            try:
                name, value = parse_error_value(str(key), raw, names=names, length_names=lengths)
            except InputError as exc:
                raise InputError(f"lower_bounds: {exc.detail}", path=path) from None
            if name not in angular:
                raise InputError(f"lower_bounds: '{key}' is not an angular error", path=path)
            if name in given:
                raise InputError(
                    f"lower_bounds: '{key}' and '{given[name]}' both give {name}", path=path
                )
            given[name] = str(key)
            if value < 0.0:
                raise InputError(f"lower_bounds: '{key}' is negative ({raw})", path=path)
            values[angular.index(name)] = value
        reasoning = data.get("reasoning") or {}
        if not isinstance(reasoning, Mapping):
            raise InputError("'reasoning' must map error names to text", path=path)
        for key, text in reasoning.items():
            if str(key) not in angular:
                raise InputError(
                    f"reasoning: '{key}' is not an angular error; known: {', '.join(angular)}",
                    path=path,
                )
            if isinstance(text, (Mapping, list)):
                raise InputError(f"reasoning: '{key}' must be text", path=path)
        return cls(values, {str(k): str(v) for k, v in reasoning.items()}, str(path), angular)

    def arcsec_by_name(self) -> dict[str, float]:
        """``{error: lower bound in arcsec}``."""
        return {
            n: float(v * ARCSEC_PER_RAD)
            for n, v in zip(self.error_names, self.lower_bounds_rad, strict=True)
        }

    def to_dict(self) -> dict:
        """Source, lower bounds by name (arcsec) and reasoning, as a JSON-ready dict."""
        return {
            "source": self.source,
            "lower_bounds_arcsec": self.arcsec_by_name(),
            "reasoning": dict(self.reasoning),
        }

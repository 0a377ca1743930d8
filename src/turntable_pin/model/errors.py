"""The nine error components of a two-axis turntable (paper Table 2) as one frozen parameter set.

Inside the set, the eight angular errors are radians and the intersection error ``deta`` is
metres. Readers take user units: arc seconds (or ``_arcmin``, ``_deg``, ``_rad`` suffixes) for
angles, millimetres (or ``_m``) for ``deta``. Readers refuse values beyond the small-error range
(:data:`MAX_ANGULAR_ERROR_DEG`, :data:`MAX_DETA_M`), or, for a simulated measurement run (the
exact chain), beyond :data:`MAX_ORIENTATION_ERROR_DEG`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np
import yaml

from ..core.exceptions import InputError
from ..core.files import read_yaml, write_text_atomic
from ..core.units import ARCMIN_PER_RAD, ARCSEC_PER_RAD, DEG_PER_RAD, M_PER_MM

__all__ = [
    "read_error_mapping",
    "ANGULAR_ERROR_NAMES",
    "DEFAULT_ANGLE_UNIT",
    "DEFAULT_LENGTH_UNIT",
    "ERROR_DESCRIPTIONS",
    "ERROR_NAMES",
    "MAX_ANGULAR_ERROR_DEG",
    "MAX_DETA_M",
    "MAX_ORIENTATION_ERROR_DEG",
    "TurntableErrors",
    "parse_error_value",
]

ANGULAR_ERROR_NAMES: tuple[str, ...] = (
    "dphi_y1",
    "dphi_z2",
    "dalpha_x1",
    "dalpha_z1",
    "dalpha_x2",
    "dalpha_y2",
    "deps_x",
    "deps_y",
)
"""The eight angular errors in the order of the paper's vector chi (eq. 25)."""

ERROR_NAMES: tuple[str, ...] = (*ANGULAR_ERROR_NAMES, "deta")
"""All nine components of Table 2; ``deta`` (a length) last."""

ERROR_DESCRIPTIONS: dict[str, str] = {
    "dphi_y1": "position error of the outer axis",
    "dphi_z2": "position error of the inner axis",
    "dalpha_x1": "wobble of the outer axis about x",
    "dalpha_z1": "wobble of the outer axis about z",
    "dalpha_x2": "wobble of the inner axis about x",
    "dalpha_y2": "wobble of the inner axis about y",
    "deps_x": "orthogonality error between the axes about x",
    "deps_y": "orthogonality error between the axes about y",
    "deta": "intersection error: offset of the inner axis along x",
}
"""One line saying what each of :data:`ERROR_NAMES` is."""

# Factor that turns a value in the named unit into radians / metres.
_ANGLE_UNITS = {
    "arcsec": 1.0 / ARCSEC_PER_RAD,
    "arcmin": 1.0 / ARCMIN_PER_RAD,
    "deg": 1.0 / DEG_PER_RAD,
    "rad": 1.0,
}
_LENGTH_UNITS = {"mm": M_PER_MM, "um": 1e-6, "m": 1.0}
DEFAULT_ANGLE_UNIT = "arcsec"
"""Unit of an angular error given without a unit suffix."""
DEFAULT_LENGTH_UNIT = "mm"
"""Unit of ``deta`` given without a unit suffix."""

MAX_ANGULAR_ERROR_DEG = 5.0
"""Largest angle the small-error model takes, degrees: a turntable error, an orientation error
(rate error, a measured angle, a noise sigma) and an orientation limit. Eq. 26 drops terms of
order angle^2 (0.4 % at 5 degrees); more is a broken table or a unit mix-up (degrees written as
arc seconds), refused."""
MAX_ORIENTATION_ERROR_DEG = 30.0
"""Largest orientation error the exact chain takes from a measurement run, degrees (a measured
``dpsi/dtheta/dgamma``, an angular error of a simulated run). The fit is nonlinear on the exact
chain, so an offset of several degrees (a mount not synced) is an ordinary fit: Gauss-Newton
converges up to 20 deg, with Levenberg-Marquardt up to 30 deg, and lands in wrong minima beyond
40 deg (``tests/measurement/test_fit.py``). The angles are entries of ``dR`` (sines: 5 % off at
30 deg); a third of a turn is another star, the other pier side or a sign convention."""
MAX_DETA_M = 0.01
"""Largest intersection error ``|deta|``, metres (10 mm): the axes of a bench-top table are
centimetres apart at worst; more is a unit mix-up (metres written as millimetres)."""


def _to_float(value: object, what: str) -> float:
    if isinstance(value, bool):
        raise InputError(f"{what}: expected a number, got {value!r}")
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise InputError(f"{what}: expected a number, got {value!r}") from None
    if not math.isfinite(number):
        raise InputError(f"{what}: expected a finite number, got {value!r}")
    return number


def parse_error_value(
    key: str,
    value: object,
    *,
    names: Sequence[str] = ERROR_NAMES,
    length_names: Sequence[str] = ("deta",),
    max_angle_deg: float = MAX_ANGULAR_ERROR_DEG,
) -> tuple[str, float]:
    """One user entry as ``(name, value in rad or m)``: ``key`` is one of ``names`` (the table's;
    ``length_names`` the lengths), optionally with a unit suffix (``dphi_y1_arcmin``, ``deta_m``;
    default arcsec and mm). :class:`InputError` for an unknown name or unit, a value not finite,
    an angle beyond ``max_angle_deg`` (a simulated run takes :data:`MAX_ORIENTATION_ERROR_DEG`)
    or a length beyond :data:`MAX_DETA_M`."""
    key = key.strip()
    name, unit = key, None
    if key not in names:
        base, _, suffix = key.rpartition("_")
        if base in names:
            name, unit = base, suffix
        else:
            raise InputError(
                f"unknown error name '{key}'; known names: {', '.join(names)} "
                "(optionally with a unit suffix such as _arcsec, _arcmin, _deg, _rad, _mm, _m)"
            )
    is_length = name in length_names
    units = _LENGTH_UNITS if is_length else _ANGLE_UNITS
    unit = unit or (DEFAULT_LENGTH_UNIT if is_length else DEFAULT_ANGLE_UNIT)
    if unit not in units:
        raise InputError(f"'{key}': unit '{unit}' is not one of {', '.join(units)}")
    number = _to_float(value, f"error '{key}'")
    si_value = number * units[unit]
    if is_length:
        if not abs(si_value) <= MAX_DETA_M:
            raise InputError(
                f"error '{key}' = {number:g} {unit} is beyond the range of the model: "
                f"|{name}| must be at most {MAX_DETA_M / M_PER_MM:g} mm"
            )
    elif not abs(si_value) <= max_angle_deg / DEG_PER_RAD:
        what = (
            "a small error" if max_angle_deg <= MAX_ANGULAR_ERROR_DEG else "an error of the table"
        )
        raise InputError(
            f"error '{key}' = {number:g} {unit} is not {what}: an angular error must be "
            f"at most {max_angle_deg:g} deg ({max_angle_deg * 3600:g} arcsec)"
        )
    return name, si_value


def read_error_mapping(path: str | Path) -> Mapping:
    """The ``name[_unit]: value`` mapping of an errors YAML file (optionally under ``errors:``);
    :class:`InputError` for unreadable YAML, a key beside ``errors:`` or not a mapping."""
    path = Path(path)
    data = read_yaml(path)
    if isinstance(data, Mapping) and "errors" in data:
        extra = [str(k) for k in data if k != "errors"]
        if extra:
            raise InputError(
                f"unknown top-level key(s) {', '.join(repr(k) for k in extra)} beside "
                "'errors:'; the file holds either 'errors:' alone or the error names",
                path=path,
            )
        data = data["errors"]
    if data is None:
        data = {}
    if not isinstance(data, Mapping):
        raise InputError("expected a mapping of error names to values", path=path)
    return data


@dataclass(frozen=True)
class TurntableErrors:
    """The nine turntable error components of paper Table 2.

    Attributes (radians, except ``deta`` in metres): see :data:`ERROR_DESCRIPTIONS`.
    """

    dphi_y1: float = 0.0
    dphi_z2: float = 0.0
    dalpha_x1: float = 0.0
    dalpha_z1: float = 0.0
    dalpha_x2: float = 0.0
    dalpha_y2: float = 0.0
    deps_x: float = 0.0
    deps_y: float = 0.0
    deta: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            object.__setattr__(self, f.name, _to_float(value, f.name))

    # ---- constructors -------------------------------------------------------------------
    @classmethod
    def from_array(cls, values: Iterable[float]) -> TurntableErrors:
        """From the nine values in :data:`ERROR_NAMES` order (rad, ``deta`` in m)."""
        values = np.asarray(list(values), dtype=float).ravel()
        if values.size == len(ANGULAR_ERROR_NAMES):
            values = np.append(values, 0.0)
        if values.size != len(ERROR_NAMES):
            raise InputError(f"expected 8 or 9 error values, got {values.size}")
        return cls(*values.tolist())

    @classmethod
    def from_user_units(
        cls, entries: Mapping[str, object], *, max_angle_deg: float = MAX_ANGULAR_ERROR_DEG
    ) -> TurntableErrors:
        """From a mapping ``name[_unit] -> value`` in user units (see :func:`parse_error_value`;
        angles up to ``max_angle_deg``, degrees)."""
        values: dict[str, float] = {}
        for key, value in entries.items():
            name, si_value = parse_error_value(str(key), value, max_angle_deg=max_angle_deg)
            if name in values:
                raise InputError(f"error '{name}' is given twice")
            values[name] = si_value
        return cls(**values)

    @classmethod
    def from_arcsec(cls, deta_mm: float = 0.0, **angles_arcsec: float) -> TurntableErrors:
        """From angular errors in arc seconds and ``deta`` in millimetres."""
        return cls.from_user_units({**angles_arcsec, "deta_mm": deta_mm})

    @classmethod
    def from_yaml(
        cls, path: str | Path, *, max_angle_deg: float = MAX_ANGULAR_ERROR_DEG
    ) -> TurntableErrors:
        """Read a YAML file of ``name[_unit]: value`` (``dphi_y1_arcsec: 3.0``, ``deta_mm: 0.2``),
        optionally under a key ``errors`` (angles up to ``max_angle_deg``, degrees)."""
        path = Path(path)
        data = read_error_mapping(path)
        try:
            return cls.from_user_units(data, max_angle_deg=max_angle_deg)
        except InputError as exc:
            raise InputError(exc.detail, path=path) from None

    # ---- views ---------------------------------------------------------------------------
    def as_array(self) -> np.ndarray:
        """The nine values in :data:`ERROR_NAMES` order (rad, ``deta`` in m)."""
        return np.array([getattr(self, n) for n in ERROR_NAMES], dtype=float)

    def angular_array_rad(self) -> np.ndarray:
        """The eight angular errors in :data:`ANGULAR_ERROR_NAMES` order, radians."""
        return self.as_array()[: len(ANGULAR_ERROR_NAMES)]

    def to_user_units(self) -> dict[str, float]:
        """``{name_arcsec: value, ..., deta_mm: value}``, the form :meth:`from_user_units` reads."""
        out = {f"{n}_arcsec": getattr(self, n) * ARCSEC_PER_RAD for n in ANGULAR_ERROR_NAMES}
        out["deta_mm"] = self.deta / M_PER_MM
        return out

    def scaled(self, factor: float) -> TurntableErrors:
        """Every component multiplied by ``factor``."""
        return TurntableErrors.from_array(self.as_array() * factor)

    def to_yaml(self, path: str | Path) -> None:
        """Write the set in user units (arcsec, mm) as a YAML file that :meth:`from_yaml` reads."""
        write_text_atomic(path, yaml.safe_dump({"errors": self.to_user_units()}, sort_keys=False))

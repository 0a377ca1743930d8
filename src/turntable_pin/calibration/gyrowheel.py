"""The GyroWheel rate-sensing model (paper eq. 1): seven drift coefficients per sensing axis.

The outputs ``out_x = ky*iy`` and ``out_y = kx*ix`` (deg/h) are the input rate plus a drift that
depends on the specific force ``a = (ax, ay, az)`` (in g) along the payload axes::

    out_x = wx + DF + x ax + y ay + z az + xx ax^2 + zz az^2 + xy ax ay
    out_y = wy + DF + x ax + y ay + z az + yy ay^2 + zz az^2 + yx ax ay

One row of the regressor matrix ``A`` of eqs. 2/4/10 is ``[1, ax, ay, az, q1, az^2, ax ay]`` with
``q1 = ax^2`` for the x axis and ``ay^2`` for the y axis. Coefficients are deg/h, deg/h/g and
deg/h/g^2. Paper Table 1 is bundled as ``models/gyrowheel_nominal.yaml``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..core.exceptions import InputError
from ..core.files import read_yaml
from ..core.resources import default_gyrowheel_path

__all__ = [
    "AXES",
    "MAX_COEFFICIENT_DPH",
    "N_COEFFICIENTS",
    "TERM_NAMES",
    "DriftCoefficients",
    "GyroWheelModel",
    "regressor_matrix",
]

AXES: tuple[str, ...] = ("x", "y")
"""The two sensing axes of the GyroWheel."""

TERM_NAMES: dict[str, tuple[str, ...]] = {
    "x": ("DF", "x", "y", "z", "xx", "zz", "xy"),
    "y": ("DF", "x", "y", "z", "yy", "zz", "yx"),
}
"""Coefficient names of each axis in regressor-column order (Table 1 / eq. 2 order)."""

N_COEFFICIENTS = 7
"""Drift coefficients per sensing axis."""

MAX_COEFFICIENT_DPH = 1e5
"""Largest ``|coefficient|`` of a drift model, deg/h (deg/h/g, deg/h/g^2 for the g terms): paper
Table 1 has values up to 105 deg/h; 1e5 deg/h (28 deg/s) of drift is no rate sensor, it is a
unit mix-up (deg/s written as deg/h) or a typo."""


@dataclass(frozen=True)
class DriftCoefficients:
    """The seven drift coefficients of one sensing axis (eq. 1).

    Attributes:
        axis: ``"x"`` or ``"y"``.
        values_dph: the coefficients in :data:`TERM_NAMES` order; DF in deg/h, the g terms in
            deg/h/g, the g^2 terms in deg/h/g^2.
    """

    axis: str
    values_dph: tuple[float, ...]

    def __post_init__(self) -> None:
        if self.axis not in AXES:
            raise InputError(f"unknown GyroWheel axis '{self.axis}'; expected one of {AXES}")
        values = tuple(float(v) for v in self.values_dph)
        if len(values) != N_COEFFICIENTS:
            raise InputError(f"axis {self.axis}: expected 7 coefficients, got {len(values)}")
        if not all(math.isfinite(v) for v in values):
            raise InputError(f"axis {self.axis}: coefficients must be finite, got {values}")
        for name, value in zip(TERM_NAMES[self.axis], values, strict=True):
            if abs(value) > MAX_COEFFICIENT_DPH:
                raise InputError(
                    f"axis '{self.axis}', coefficient '{name}': {value:g} is beyond "
                    f"+-{MAX_COEFFICIENT_DPH:g} deg/h (no rate sensor drifts that much)"
                )
        object.__setattr__(self, "values_dph", values)

    @property
    def names(self) -> tuple[str, ...]:
        """The coefficient names of this axis, in :data:`TERM_NAMES` order."""
        return TERM_NAMES[self.axis]

    @classmethod
    def from_mapping(cls, axis: str, data: Mapping, *, where: str = "") -> DriftCoefficients:
        """Read ``{name: value}`` with exactly the names of :data:`TERM_NAMES` for ``axis``."""
        prefix = f"{where}: " if where else ""
        if not isinstance(data, Mapping):
            raise InputError(f"{prefix}axis '{axis}' must be a mapping of coefficient names")
        names = TERM_NAMES[axis]
        unknown = [str(k) for k in data if str(k) not in names]
        missing = [n for n in names if n not in {str(k) for k in data}]
        if unknown or missing:
            raise InputError(
                f"{prefix}axis '{axis}': "
                + (f"unknown coefficient(s) {unknown}; " if unknown else "")
                + (f"missing coefficient(s) {missing}; " if missing else "")
                + f"expected {list(names)}"
            )
        values = []
        for name in names:
            value = data[name]
            try:
                number = float(value)
            except (TypeError, ValueError):
                raise InputError(
                    f"{prefix}axis '{axis}', coefficient '{name}': expected a number, got {value!r}"
                ) from None
            if isinstance(value, bool) or not math.isfinite(number):
                raise InputError(
                    f"{prefix}axis '{axis}', coefficient '{name}': expected a finite number, "
                    f"got {value!r}"
                )
            values.append(number)
        try:
            return cls(axis, tuple(values))
        except InputError as exc:
            raise InputError(f"{prefix}{exc}") from None

    def as_array(self) -> np.ndarray:
        """The coefficients as a float array of shape (7,), deg/h-based units."""
        return np.array(self.values_dph, dtype=float)

    def to_dict(self) -> dict[str, float]:
        """``{name: value}`` of the seven coefficients (deg/h-based units)."""
        return dict(zip(self.names, self.values_dph, strict=True))


@dataclass(frozen=True)
class GyroWheelModel:
    """The drift models of both sensing axes.

    Attributes:
        x, y: :class:`DriftCoefficients` of the x and the y axis.
        source: where the coefficients came from (a file path or a description).
    """

    x: DriftCoefficients
    y: DriftCoefficients
    source: str = ""

    @classmethod
    def nominal(cls) -> GyroWheelModel:
        """Paper Table 1 (``models/gyrowheel_nominal.yaml``)."""
        return cls.from_yaml(default_gyrowheel_path())

    @classmethod
    def from_yaml(cls, path: str | Path) -> GyroWheelModel:
        """Read ``{x: {DF: .., x: .., ...}, y: {...}}`` (names of :data:`TERM_NAMES`)."""
        path = Path(path)
        data = read_yaml(path)
        if not isinstance(data, Mapping) or set(map(str, data)) != set(AXES):
            raise InputError("expected a mapping with exactly the keys 'x' and 'y'", path=path)
        return cls(
            DriftCoefficients.from_mapping("x", data["x"], where=str(path)),
            DriftCoefficients.from_mapping("y", data["y"], where=str(path)),
            source=str(path),
        )

    def axis(self, name: str) -> DriftCoefficients:
        """The coefficients of axis ``name`` (``"x"`` or ``"y"``)."""
        if name not in AXES:
            raise InputError(f"unknown GyroWheel axis '{name}'; expected one of {AXES}")
        return getattr(self, name)

    def outputs_dph(self, specific_force_g, earth_rate_dph) -> np.ndarray:
        """Eq. 1 outputs ``(out_x, out_y)``, shape S + (2,) for inputs of shape S + (3,)."""
        rate = np.asarray(earth_rate_dph, dtype=float)
        return np.stack(
            [
                rate[..., i] + regressor_matrix(axis, specific_force_g) @ self.axis(axis).as_array()
                for i, axis in enumerate(AXES)
            ],
            axis=-1,
        )

    def to_dict(self) -> dict:
        """Both axes' coefficients by name and the source, as a JSON-ready dict."""
        return {"x": self.x.to_dict(), "y": self.y.to_dict(), "source": self.source}


def regressor_matrix(axis: str, specific_force_g) -> np.ndarray:
    """Rows ``[1, ax, ay, az, q1, az^2, ax ay]`` of eqs. 2/10 (q1 = ax^2 on x, ay^2 on y).

    Args:
        axis: ``"x"`` or ``"y"``.
        specific_force_g: shape S + (3,), the specific force along the payload axes, in g.

    Returns:
        Shape S + (7,).
    """
    a = np.asarray(specific_force_g, dtype=float)
    if axis not in AXES:
        raise InputError(f"unknown GyroWheel axis '{axis}'; expected one of {AXES}")
    rows = np.empty(a.shape[:-1] + (N_COEFFICIENTS,))
    rows[..., 0] = 1.0
    rows[..., 1:4] = a
    squared = a[..., 0] if axis == "x" else a[..., 1]
    np.multiply(squared, squared, out=rows[..., 4])
    np.multiply(a[..., 2], a[..., 2], out=rows[..., 5])
    np.multiply(a[..., 0], a[..., 1], out=rows[..., 6])
    return rows

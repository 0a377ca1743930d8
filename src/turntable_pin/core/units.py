"""Unit conversions at the edges of the package. Inside, angles are radians and lengths metres."""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "ARCMIN_PER_RAD",
    "ARCSEC_PER_RAD",
    "DEG_PER_RAD",
    "M_PER_MM",
    "arcmin_by_name",
    "arcmin_to_rad",
    "arcsec_to_rad",
    "deg_to_rad",
    "rad_to_arcmin",
    "rad_to_arcsec",
    "rad_to_deg",
]

ARCSEC_PER_RAD = 180.0 / math.pi * 3600.0
"""Arc seconds in one radian."""
ARCMIN_PER_RAD = 180.0 / math.pi * 60.0
"""Arc minutes in one radian."""
DEG_PER_RAD = 180.0 / math.pi
"""Degrees in one radian."""
M_PER_MM = 1e-3
"""Metres in one millimetre."""


def _scaled(value, factor: float):
    """``value * factor``, a float for scalars and a float array for arrays."""
    if np.ndim(value):
        return np.asarray(value, dtype=float) * factor
    return float(value) * factor


def arcsec_to_rad(value_arcsec):
    """Arc seconds to radians (scalars or arrays)."""
    return _scaled(value_arcsec, 1.0 / ARCSEC_PER_RAD)


def rad_to_arcsec(value_rad):
    """Radians to arc seconds (scalars or arrays)."""
    return _scaled(value_rad, ARCSEC_PER_RAD)


def arcmin_to_rad(value_arcmin):
    """Arc minutes to radians (scalars or arrays)."""
    return _scaled(value_arcmin, 1.0 / ARCMIN_PER_RAD)


def rad_to_arcmin(value_rad):
    """Radians to arc minutes (scalars or arrays)."""
    return _scaled(value_rad, ARCMIN_PER_RAD)


def deg_to_rad(value_deg):
    """Degrees to radians (scalars or arrays)."""
    return _scaled(value_deg, 1.0 / DEG_PER_RAD)


def rad_to_deg(value_rad):
    """Radians to degrees (scalars or arrays)."""
    return _scaled(value_rad, DEG_PER_RAD)


def arcmin_by_name(names, values_rad) -> dict[str, float]:
    """``{name: value in arc minutes}`` for parallel sequences of names and radian values."""
    return {
        str(n): float(v) * ARCMIN_PER_RAD
        for n, v in zip(names, np.asarray(values_rad, dtype=float).ravel(), strict=True)
    }

"""How the GyroWheel's two outputs change with the payload's orientation error (eqs. 8-13).

An orientation error ``dR = I + [r]x`` (eq. 7, ``r = (dgamma, dpsi, dtheta)`` about the payload
x, y, z axes) turns the sensed row vectors ``a`` (specific force, g) and ``w`` (earth rate,
deg/h) into ``a dR`` and ``w dR`` (eq. 8), that is ``a + a x r`` and ``w + w x r``. To first
order the output of axis c then changes by

    d out_c = (g_c x a + e_c x w) . r,    g_c = d(A_c(a) beta_c)/da

with ``A_c`` the drift regressor of eq. 2 and ``beta_c`` the axis' seven coefficients. The
second-order remainder is below 1e-6 deg/h for errors of an arc minute and Table 1's
coefficients.
"""

from __future__ import annotations

import numpy as np

from ..calibration.gyrowheel import AXES, N_COEFFICIENTS, regressor_matrix

__all__ = ["ANGLE_ORDER", "drift_gradient", "drift_regressor", "rate_sensitivity_dph"]

ANGLE_ORDER = (1, 2, 0)
"""The components of ``r = (rx, ry, rz)`` that are ``(dpsi, dtheta, dgamma)``."""


def drift_gradient(axis: str, specific_force_g: np.ndarray, coefficients) -> np.ndarray:
    """``d(A_axis(a) . beta)/da`` at each position, (N, 3), deg/h per g.

    Args:
        axis: ``"x"`` or ``"y"``.
        specific_force_g: (N, 3) along the payload axes, g.
        coefficients: the axis' seven coefficients in ``TERM_NAMES`` order (deg/h-based units).
    """
    a = np.asarray(specific_force_g, dtype=float)
    _, bx, by, bz, bq, bzz, bxy = np.asarray(coefficients, dtype=float)  # DF has no gradient
    q = 0 if axis == "x" else 1
    grad = np.empty_like(a)
    grad[:, 0] = bx + bxy * a[:, 1]
    grad[:, 1] = by + bxy * a[:, 0]
    grad[:, 2] = bz + 2.0 * bzz * a[:, 2]
    grad[:, q] += 2.0 * bq * a[:, q]
    return grad


def rate_sensitivity_dph(inputs, coefficients: np.ndarray) -> np.ndarray:
    """``d(out_x, out_y)/d(dpsi, dtheta, dgamma)`` at each position, (N, 2, 3), deg/h per rad.

    Args:
        inputs: :class:`~turntable_pin.calibration.positions.PositionInputs` (what the payload
            senses at the ideal orientation).
        coefficients: (2, 7) drift coefficients of the x and y axes (deg/h-based units).
    """
    a = inputs.specific_force_g
    w = inputs.earth_rate_dph
    out = np.empty((a.shape[0], 2, 3))
    for c, axis in enumerate(AXES):
        along = drift_gradient(axis, a, coefficients[c])
        # d out / d r = g x a + e_c x w  (the triple product (g, a x r) = (g x a) . r)
        unit = np.zeros(3)
        unit[c] = 1.0
        d_r = np.cross(along, a) + np.cross(unit, w)
        out[:, c, :] = d_r[:, ANGLE_ORDER]
    return out


def drift_regressor(specific_force_g: np.ndarray) -> np.ndarray:
    """The drift regressor of both axes, (N, 2, 14): the x axis' seven columns (eq. 2) on the
    first output, the y axis' on the second."""
    a = np.asarray(specific_force_g, dtype=float)
    out = np.zeros((a.shape[0], 2, 2 * N_COEFFICIENTS))
    for c, axis in enumerate(AXES):
        out[:, c, c * N_COEFFICIENTS : (c + 1) * N_COEFFICIENTS] = regressor_matrix(axis, a)
    return out

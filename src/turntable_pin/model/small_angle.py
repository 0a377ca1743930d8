"""The small-angle (first-order) orientation error model of the paper, eqs. 7 and 26.

Linear in the eight angular errors chi (Table 2 order, :data:`ANGULAR_ERROR_NAMES`):
``[dpsi, dtheta, dgamma] = S(phi2) chi`` with the 3x8 matrix :func:`small_angle_matrix`. It agrees
with the exact chain to second order in the errors; the intersection error does not enter.
"""

from __future__ import annotations

import numpy as np

from .errors import ANGULAR_ERROR_NAMES, TurntableErrors

__all__ = ["small_angle_matrix", "small_angle_orientation_error", "small_angle_rotation"]


def small_angle_matrix(phi2_rad) -> np.ndarray:
    """``S(phi2)`` of eq. 26, shape S + (3, 8) for ``phi2_rad`` of shape S.

    Rows: dpsi, dtheta, dgamma. Columns: dphi_y1, dphi_z2, dalpha_x1, dalpha_z1, dalpha_x2,
    dalpha_y2, deps_x, deps_y.
    """
    phi2 = np.asarray(phi2_rad, dtype=float)
    c, s = np.cos(phi2), np.sin(phi2)
    one, zero = np.ones_like(phi2), np.zeros_like(phi2)
    rows = (
        #   dphi_y1 dphi_z2 dalpha_x1 dalpha_z1 dalpha_x2 dalpha_y2 deps_x deps_y
        (c, zero, -s, zero, zero, one, -s, c),  # dpsi
        (zero, one, zero, one, zero, zero, zero, zero),  # dtheta
        (s, zero, c, zero, one, zero, c, s),  # dgamma
    )
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


def small_angle_orientation_error(errors: TurntableErrors | np.ndarray, phi2_rad) -> np.ndarray:
    """``(dpsi, dtheta, dgamma)`` of eq. 26 in radians, shape S + (3,) for ``phi2_rad`` of shape S.

    ``errors`` is a :class:`TurntableErrors` or an array whose last axis holds the eight angular
    errors (or all nine; ``deta`` is ignored), radians.
    """
    if isinstance(errors, TurntableErrors):
        chi = errors.angular_array_rad()
    else:
        chi = np.asarray(errors, dtype=float)[..., : len(ANGULAR_ERROR_NAMES)]
    return np.einsum("...ij,...j->...i", small_angle_matrix(phi2_rad), chi)


def small_angle_rotation(dpsi_rad, dtheta_rad, dgamma_rad) -> np.ndarray:
    """The first-order orientation error matrix of eq. 7 (not exactly orthogonal), 3x3."""
    return np.array(
        [
            [1.0, -dtheta_rad, dpsi_rad],
            [dtheta_rad, 1.0, -dgamma_rad],
            [-dpsi_rad, dgamma_rad, 1.0],
        ],
        dtype=float,
    )

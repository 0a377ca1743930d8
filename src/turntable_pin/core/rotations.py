"""Elementary rotations, vectorised over leading dimensions (radians in, 3x3 matrices out)."""

from __future__ import annotations

import numpy as np

__all__ = ["AXIS_INDEX", "axis_rotation", "rot_x", "rot_y", "rot_z"]

AXIS_INDEX = {"x": 0, "y": 1, "z": 2}
"""Axis name -> index of its coordinate (x 0, y 1, z 2)."""


def axis_rotation(axis: str | np.ndarray, angle_rad) -> np.ndarray:
    """Rotation by ``angle_rad`` about ``axis`` ('x', 'y', 'z' or a unit 3-vector).

    ``angle_rad`` may be an array of any shape S; the result has shape S + (3, 3).
    """
    angle = np.asarray(angle_rad, dtype=float)
    c, s = np.cos(angle), np.sin(angle)
    if isinstance(axis, str):
        i = AXIS_INDEX[axis]
        j, k = (i + 1) % 3, (i + 2) % 3
        out = np.zeros(angle.shape + (3, 3))
        out[..., i, i] = 1.0
        out[..., j, j] = c
        out[..., k, k] = c
        out[..., j, k] = -s
        out[..., k, j] = s
        return out
    u = np.asarray(axis, dtype=float)
    u = u / np.linalg.norm(u)
    skew = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
    c = c[..., None, None]
    s = s[..., None, None]
    return np.eye(3) + s * skew + (1.0 - c) * (skew @ skew)


def rot_x(angle_rad) -> np.ndarray:
    """Rotation about x (vectorised)."""
    return axis_rotation("x", angle_rad)


def rot_y(angle_rad) -> np.ndarray:
    """Rotation about y (vectorised)."""
    return axis_rotation("y", angle_rad)


def rot_z(angle_rad) -> np.ndarray:
    """Rotation about z (vectorised)."""
    return axis_rotation("z", angle_rad)

"""The three orientation-error angles: their names and where they sit in ``dR`` (eq. 24).

``dR = Rd^T Rt``; ``dpsi = dR[0,2]`` (a rotation about y), ``dtheta = dR[1,0]`` (about z),
``dgamma = dR[2,1]`` (about x). Every layer takes these names and indices from here.
"""

from __future__ import annotations

__all__ = ["ANGLE_AXES", "ANGLE_ENTRIES", "ANGLE_NAMES", "ANGLE_SYMBOLS"]

ANGLE_NAMES: tuple[str, ...] = ("dpsi", "dtheta", "dgamma")
"""Names of the orientation-error angles, in this order everywhere (arrays, columns, reports)."""

ANGLE_SYMBOLS: tuple[str, ...] = ("psi", "theta", "gamma")
"""The same angles without the ``d``, as used in limit names (``psi_rad``) and axis labels."""

ANGLE_ENTRIES: tuple[tuple[int, int], ...] = ((0, 2), (1, 0), (2, 1))
"""(row, column) of dpsi, dtheta, dgamma in ``dR`` (eq. 24, 0-based)."""

ANGLE_AXES: tuple[str, ...] = ("y", "z", "x")
"""The axis each small angle rotates about: dpsi about y, dtheta about z, dgamma about x."""

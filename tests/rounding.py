"""Rounding bounds that the tests' tolerances near machine precision are derived from.

A tolerance says what the conditioning of the computation allows, not what one machine happened
to reach (the BLAS kernel a fresh install picks changes the rounding). The bounds here are the
first-order a-priori ones:

- :func:`chain_rounding`: an entry of a product of 3x3 rotations (a chain's orientation, or its
  error ``dR = Rd^T Rt``), or a small angle read off one. Every entry is at most 1, so each
  product rounds by at most ``gamma_3 |A| |B| <= 1.5 eps`` (``(|A| |B|)_ij <= 1`` for rotations
  by Cauchy-Schwarz) and each factor's own sines and cosines by an ulp; the error of a small angle
  is therefore absolute, not relative to the angle.
- A central difference ``(f(x + h) - f(x - h)) / 2h`` of such a value rounds by the value's
  rounding over ``h`` (on top of its truncation ``h^2 |f'''| / 6``).
"""

from __future__ import annotations

import numpy as np

EPS = float(np.finfo(float).eps)


def chain_rounding(factors: int) -> float:
    """Bound of the absolute rounding of an entry of a product of ``factors`` 3x3 rotations."""
    return (1.5 * (factors - 1) + factors) * EPS


def chain_factors(table) -> int:
    """The rotations multiplied into a table's orientation (``Rd`` or ``Rt``): its placements
    and joint rotations."""
    return len(table.chain.placements()) + len(table.joint_names)


def error_factors(table) -> int:
    """The rotations multiplied into a table's ``dR = Rd^T Rt``: those of both chains."""
    return 2 * chain_factors(table)

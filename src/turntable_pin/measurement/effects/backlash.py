"""``backlash``: the position depends on the direction the axis approached it from."""

from __future__ import annotations

import numpy as np

from .base import ARCSEC, ChainTerm, Effect, ParameterSpec, PositionVariables

__all__ = ["Backlash"]


class Backlash(Effect):
    """Approach-direction dependence: half the backlash ``b`` (arcsec) times ``dir``, per axis."""

    name = "backlash"
    title = "backlash (approach-direction dependence)"
    definition = "dphi_y1 += b1 dir1 / 2, dphi_z2 += b2 dir2 / 2"
    explanation = (
        "Gears, couplings and the servo's dead band let an axis stop a little short of the "
        "commanded angle, on the side it came from: the position error differs by b between "
        "approaches from below (dir = +1) and from above (dir = -1). Only one of dir1 / dir2 is "
        "needed; the parameter of an absent column is not fitted."
    )
    confirm = (
        "Approach a few positions alternately from both directions (or always from the same side) "
        "and compare: a backlash flips sign with the approach direction; a unidirectional "
        "approach removes it."
    )
    required_columns = ("dir1", "dir2")
    any_column = True

    def parameters(self, variables: PositionVariables):
        """``b1`` and/or ``b2`` (arcsec), for each of ``dir1``/``dir2`` the data have."""
        out = []
        if variables.has("dir1"):
            out.append(ParameterSpec("b1", "arcsec", ARCSEC, "outer-axis backlash"))
        if variables.has("dir2"):
            out.append(ParameterSpec("b2", "arcsec", ARCSEC, "inner-axis backlash"))
        return tuple(out)

    def chain_terms(self, variables: PositionVariables):
        """``b1 dir1 / 2`` added to ``dphi_y1`` and ``b2 dir2 / 2`` to ``dphi_z2``."""
        terms = []
        if variables.has("dir1"):
            terms.append(ChainTerm("dphi_y1", None, {"b1": 0.5 * np.asarray(variables.dir1)}))
        if variables.has("dir2"):
            terms.append(ChainTerm("dphi_z2", None, {"b2": 0.5 * np.asarray(variables.dir2)}))
        return tuple(terms)

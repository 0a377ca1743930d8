"""``gravity_sag``: the payload tilts under its own weight (a compliance per g)."""

from __future__ import annotations

import numpy as np

from .base import ARCSEC, POST, ChainTerm, Effect, ParameterSpec, PositionVariables

__all__ = ["GravitySag"]


class GravitySag(Effect):
    """Payload tilt under gravity: a compliance ``k`` (arcsec/g) times the lateral force."""

    name = "gravity_sag"
    title = "payload sag under gravity"
    definition = (
        "Rt -> Rt Rx(-k ay) Ry(k ax), ax = -sin(phi1) cos(phi2), ay = sin(phi1) sin(phi2) "
        "(specific force in the payload frame, g)"
    )
    explanation = (
        "Frames, bearings and the payload mount are elastic: the component of gravity across the "
        "payload bends them, and the payload tilts by a compliance k (angle per g) times that "
        "component. The tilt follows the gravity direction in the payload frame, so it grows with "
        "sin(phi1) and turns with phi2; on orientation data it looks like a once-per-revolution "
        "outer-encoder term proportional to sin(phi1)."
    )
    confirm = (
        "Repeat a few positions with a heavier (or lighter) payload: a sag scales with the load, "
        "an encoder error does not. A dial indicator on the payload while the table tips to "
        "phi1 = +-90 deg shows the deflection directly."
    )

    def parameters(self, variables: PositionVariables):
        """The compliance ``k``, arcsec/g."""
        return (ParameterSpec("k", "arcsec/g", ARCSEC, "tilt compliance per g of lateral force"),)

    def chain_terms(self, variables: PositionVariables):
        """The rotations ``Rx(-k ay) Ry(k ax)`` after ``Rt`` (``ax``, ``ay``: specific force, g)."""
        s1 = np.sin(variables.phi1_rad)
        ax = -s1 * np.cos(variables.phi2_rad)
        ay = s1 * np.sin(variables.phi2_rad)
        return (ChainTerm(POST, "x", {"k": -ay}), ChainTerm(POST, "y", {"k": ax}))

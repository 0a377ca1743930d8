"""``outer_encoder_harmonics``: once- and twice-per-revolution position error of the outer axis."""

from __future__ import annotations

from .base import ChainTerm, Effect, PositionVariables, harmonic_parameters, harmonic_weights

__all__ = ["OuterEncoderHarmonics"]


class OuterEncoderHarmonics(Effect):
    """Outer-axis encoder eccentricity and ellipticity: a 1/rev and 2/rev error in phi1."""

    name = "outer_encoder_harmonics"
    title = "outer-axis encoder eccentricity and ellipticity"
    definition = "dphi_y1 -> dphi_y1 + h(phi1), h(a) = c1 cos a + s1 sin a + c2 cos 2a + s2 sin 2a"
    explanation = (
        "An angle encoder whose graduated disc is mounted off-centre on the outer axis reads the "
        "angle with an error that varies once per revolution (about 412.5 e[um] / D[mm] arcsec for "
        "an eccentricity e on a disc of diameter D); an elliptical disc or a two-head misalignment "
        "adds a twice-per-revolution term. The table then stops at phi1 + h(phi1) instead of phi1: "
        "the outer-axis position error is no longer a constant."
    )
    confirm = (
        "Measure the outer-axis angle against an independent reference (autocollimator and "
        "optical polygon, or a second encoder read head 180 deg away) over a full turn: the "
        "difference shows the 1/rev and 2/rev curve, independent of the payload load."
    )

    def parameters(self, variables: PositionVariables):
        """The four harmonic coefficients ``c1, s1, c2, s2``, arcsec."""
        return harmonic_parameters("", "outer-axis position error", "phi1")

    def chain_terms(self, variables: PositionVariables):
        """``h(phi1)`` added to ``dphi_y1``."""
        return (ChainTerm("dphi_y1", None, harmonic_weights(variables.phi1_rad)),)

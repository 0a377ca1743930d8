"""``inner_encoder_harmonics``: once- and twice-per-revolution position error of the inner axis."""

from __future__ import annotations

from .base import ChainTerm, Effect, PositionVariables, harmonic_parameters, harmonic_weights

__all__ = ["InnerEncoderHarmonics"]


class InnerEncoderHarmonics(Effect):
    """Inner-axis encoder eccentricity and ellipticity: a 1/rev and 2/rev error in phi2."""

    name = "inner_encoder_harmonics"
    title = "inner-axis encoder eccentricity and ellipticity"
    definition = "dphi_z2 -> dphi_z2 + h(phi2), h(a) = c1 cos a + s1 sin a + c2 cos 2a + s2 sin 2a"
    explanation = (
        "The inner-axis encoder disc is off-centre (1/rev) or elliptical (2/rev), so the inner "
        "axis stops at phi2 + h(phi2): its position error varies with the inner angle. It shows "
        "in the rotation about the inner axis, dtheta, as a harmonic curve in phi2."
    )
    confirm = (
        "Compare the inner-axis angle with an independent reference (autocollimator on an optical "
        "polygon mounted on the inner frame) over a full turn of the inner axis."
    )

    def parameters(self, variables: PositionVariables):
        """The four harmonic coefficients ``c1, s1, c2, s2``, arcsec."""
        return harmonic_parameters("", "inner-axis position error", "phi2")

    def chain_terms(self, variables: PositionVariables):
        """``h(phi2)`` added to ``dphi_z2``."""
        return (ChainTerm("dphi_z2", None, harmonic_weights(variables.phi2_rad)),)

"""``inner_wobble_harmonics``: inner-bearing runout (wobble) that varies with the inner angle."""

from __future__ import annotations

from .base import ChainTerm, Effect, PositionVariables, harmonic_parameters, harmonic_weights

__all__ = ["InnerWobbleHarmonics"]


class InnerWobbleHarmonics(Effect):
    """Inner-bearing runout: the inner wobble angles vary with phi2 (1/rev and 2/rev)."""

    name = "inner_wobble_harmonics"
    title = "angle-dependent wobble of the inner axis"
    definition = (
        "dalpha_x2 -> dalpha_x2 + h_x(phi2), dalpha_y2 -> dalpha_y2 + h_y(phi2) "
        "(two harmonic series of degree 2)"
    )
    explanation = (
        "The inner bearing's runout tilts the inner axis about x and y by amounts that repeat "
        "every turn of the inner axis, so the inner wobble angles vary with phi2 (1/rev and 2/rev) "
        "instead of being constants. It shows in dpsi and dgamma as harmonic curves in phi2."
    )
    confirm = (
        "Mount a mirror or electronic level on the inner frame and record its tilt about the two "
        "axes normal to the inner axis over a slow full turn of the inner axis, the outer axis "
        "held still."
    )

    def parameters(self, variables: PositionVariables):
        """Harmonic coefficients ``x_c1 ... x_s2`` and ``y_c1 ... y_s2``, arcsec."""
        return harmonic_parameters("x_", "inner wobble about x", "phi2") + harmonic_parameters(
            "y_", "inner wobble about y", "phi2"
        )

    def chain_terms(self, variables: PositionVariables):
        """``h_x(phi2)`` added to ``dalpha_x2`` and ``h_y(phi2)`` to ``dalpha_y2``."""
        return (
            ChainTerm("dalpha_x2", None, harmonic_weights(variables.phi2_rad, "x_")),
            ChainTerm("dalpha_y2", None, harmonic_weights(variables.phi2_rad, "y_")),
        )

"""``outer_wobble_harmonics``: outer-bearing runout (wobble) that varies with the outer angle."""

from __future__ import annotations

from .base import ChainTerm, Effect, PositionVariables, harmonic_parameters, harmonic_weights

__all__ = ["OuterWobbleHarmonics"]


class OuterWobbleHarmonics(Effect):
    """Outer-bearing runout: the outer wobble angles vary with phi1 (1/rev and 2/rev)."""

    name = "outer_wobble_harmonics"
    title = "angle-dependent wobble of the outer axis"
    definition = (
        "dalpha_x1 -> dalpha_x1 + h_x(phi1), dalpha_z1 -> dalpha_z1 + h_z(phi1) "
        "(two harmonic series of degree 2)"
    )
    explanation = (
        "A real bearing does not turn about a fixed line: ball or race defects, preload and an "
        "out-of-round journal tilt the outer axis by an amount that repeats every revolution. "
        "The wobble angles about x and z of the outer axis then vary with phi1 (1/rev and 2/rev "
        "terms) instead of being constants. A base that is not level looks, seen from the rotating "
        "outer frame, exactly like a 1/rev outer wobble."
    )
    confirm = (
        "Put an electronic level or autocollimator mirror on the outer frame and record its tilt "
        "about the two axes normal to the outer axis over a full, slow turn: the repeatable part "
        "is the wobble curve. A base tilt instead shows as a tilt of the whole table on a level "
        "placed on the base."
    )

    def parameters(self, variables: PositionVariables):
        """Harmonic coefficients ``x_c1 ... x_s2`` and ``z_c1 ... z_s2``, arcsec."""
        return harmonic_parameters("x_", "outer wobble about x", "phi1") + harmonic_parameters(
            "z_", "outer wobble about z", "phi1"
        )

    def chain_terms(self, variables: PositionVariables):
        """``h_x(phi1)`` added to ``dalpha_x1`` and ``h_z(phi1)`` to ``dalpha_z1``."""
        return (
            ChainTerm("dalpha_x1", None, harmonic_weights(variables.phi1_rad, "x_")),
            ChainTerm("dalpha_z1", None, harmonic_weights(variables.phi1_rad, "z_")),
        )

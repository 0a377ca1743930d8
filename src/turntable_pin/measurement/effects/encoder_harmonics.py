"""``encoder_harmonics@<joint>``: once- and twice-per-revolution position error of any joint."""

from __future__ import annotations

from .base import ChainTerm, Effect, PositionVariables, harmonic_parameters, harmonic_weights

__all__ = ["EncoderHarmonics"]


class EncoderHarmonics(Effect):
    """Encoder eccentricity (1/rev) and ellipticity (2/rev) of one joint: its position error
    varies with its own angle.

    Args:
        joint: the joint's name (the effect is ``encoder_harmonics@<joint>``).
        index: the joint's place in the chain from the base (1 = ``phi1``).
        position_error: the table's name of the joint's position error (the error it adds to).
    """

    kind = "encoder_harmonics"

    def __init__(self, joint: str, index: int, position_error: str) -> None:
        self.joint, self.index, self.site = joint, int(index), position_error
        phi = f"phi{self.index}"
        self.name = f"{self.kind}@{joint}"
        self.title = f"encoder eccentricity and ellipticity of {joint}"
        self.definition = (
            f"{position_error} -> {position_error} + h({phi}), "
            "h(a) = c1 cos a + s1 sin a + c2 cos 2a + s2 sin 2a"
        )
        self.explanation = (
            f"The encoder disc of {joint} is off-centre (1/rev) or elliptical (2/rev), so the "
            f"axis stops at {phi} + h({phi}): its position error varies with its own angle. It "
            "shows as a harmonic curve in that angle in the rotation about the axis."
        )
        self.confirm = (
            f"Compare the angle of {joint} with an independent reference (an autocollimator on "
            "an optical polygon carried by the axis) over a full turn."
        )

    def parameters(self, variables: PositionVariables):
        """The four harmonic coefficients ``c1, s1, c2, s2``, arcsec."""
        return harmonic_parameters("", f"{self.joint} position error", f"phi{self.index}")

    def chain_terms(self, variables: PositionVariables):
        """``h(phiK)`` added to the joint's position error."""
        return (ChainTerm(self.site, None, harmonic_weights(variables.angle(self.index))),)

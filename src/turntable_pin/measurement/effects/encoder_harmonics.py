"""``encoder_harmonics@<joint>``: once- and twice-per-revolution position error of a joint."""

from __future__ import annotations

from .base import (
    ChainTerm,
    Effect,
    EffectText,
    Labels,
    PositionVariables,
    harmonic_parameters,
    harmonic_weights,
    plausible,
)

__all__ = ["EncoderHarmonics"]


class EncoderHarmonics(Effect):
    """Encoder eccentricity (1/rev) and ellipticity (2/rev) of one joint: its position error
    varies with its own angle.

    Args:
        joint: the joint's errors (:class:`~turntable_pin.measurement.table.JointErrors`: its
            name, place from the base, position error).
        name, text: the table's name and story of it (default ``encoder_harmonics@<joint>``).
        labels: ``((prefix, description),)`` of the harmonic series' parameters (default no
            prefix, ``"<joint> position error"``).
    """

    kind = "encoder_harmonics"

    def __init__(self, joint, *, name=None, text=None, labels: Labels = ()) -> None:
        self.joint, self.index, self.site = joint.joint, int(joint.index), joint.position
        self.joints = (self.joint,)
        ((self.prefix, self.what),) = labels or (("", f"{self.joint} position error"),)
        phi, site = f"phi{self.index}", self.site
        super().__init__(
            name or f"{self.kind}@{self.joint}",
            text,
            EffectText(
                title=f"encoder eccentricity and ellipticity of {self.joint}",
                definition=f"{site} -> {site} + h({phi}), "
                "h(a) = c1 cos a + s1 sin a + c2 cos 2a + s2 sin 2a",
                explanation=f"The encoder disc of {self.joint} is off-centre (1/rev) or "
                f"elliptical (2/rev), so the axis stops at {phi} + h({phi}): its position error "
                "varies with its own angle. It shows as a harmonic curve in that angle in the "
                "rotation about the axis.",
                confirm=f"Compare the angle of {self.joint} with an independent reference (an "
                "autocollimator on an optical polygon carried by the axis) over a full turn.",
            ),
        )

        p = self.prefix
        self.plausibility = (  # docs/plausibility.md
            plausible((f"{p}c1", f"{p}s1"), f"an encoder disc of {self.joint} so far off centre "
                      "that it reads {amplitude} wrong once per turn", turntable=300, mount=600),
            plausible((f"{p}c2", f"{p}s2"), f"an encoder disc of {self.joint} so far out of round "
                      "that it reads {amplitude} wrong twice per turn", turntable=100, mount=300),
        )  # fmt: skip

    def parameters(self, variables: PositionVariables):
        """The four harmonic coefficients ``c1, s1, c2, s2``, arcsec."""
        return harmonic_parameters(self.prefix, self.what, f"phi{self.index}")

    def chain_terms(self, variables: PositionVariables):
        """``h(phiK)`` added to the joint's position error."""
        weights = harmonic_weights(variables.angle(self.index), self.prefix)
        return (ChainTerm(self.site, None, weights),)

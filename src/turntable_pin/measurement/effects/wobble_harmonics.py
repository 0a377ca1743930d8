"""``wobble_harmonics@<joint>``: bearing runout of a joint that varies with its angle."""

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

__all__ = ["WobbleHarmonics"]


class WobbleHarmonics(Effect):
    """Bearing runout of one joint: both tilts of its axis vary with its angle (1/rev, 2/rev).

    Args:
        joint: the joint's errors (:class:`~turntable_pin.measurement.table.JointErrors`: its
            name, place from the base, two tilt errors).
        name, text: the table's name and story of it (default ``wobble_harmonics@<joint>``).
        labels: ``(prefix, description)`` of each tilt's harmonic series (default ``a_`` and
            ``b_``, ``"<joint> wobble (<tilt>)"``).
    """

    kind = "wobble_harmonics"

    def __init__(self, joint, *, name=None, text=None, labels: Labels = ()) -> None:
        self.joint, self.index, self.tilts = joint.joint, int(joint.index), tuple(joint.tilts)
        self.joints = (self.joint,)
        labels = labels or tuple(
            (p, f"{self.joint} wobble ({t})") for p, t in zip(("a_", "b_"), self.tilts, strict=True)
        )
        self.series = tuple(  # (tilt error, parameter prefix, description) of each tilt
            (tilt, prefix, what) for tilt, (prefix, what) in zip(self.tilts, labels, strict=True)
        )
        phi = f"phi{self.index}"
        series = (f"{t} -> {t} + h_{p.rstrip('_')}({phi})" for t, p, _ in self.series)
        super().__init__(
            name or f"{self.kind}@{self.joint}",
            text,
            EffectText(
                title=f"angle-dependent wobble of {self.joint}",
                definition=", ".join(series) + " (two harmonic series of degree 2)",
                explanation="A real bearing does not turn about a fixed line: ball or race "
                "defects, preload and an out-of-round journal tilt the axis of "
                f"{self.joint} by an amount that repeats every revolution, so its two tilt "
                f"errors vary with {phi} (1/rev and 2/rev terms) instead of being constants.",
                confirm="Put an electronic level or autocollimator mirror on the frame "
                f"{self.joint} carries and record its tilt about the two directions normal to "
                "the axis over a full, slow turn: the repeatable part is the wobble curve.",
            ),
        )

        names = tuple(f"{p}{k}" for _, p, _ in self.series for k in ("c1", "s1", "c2", "s2"))
        self.plausibility = (  # docs/plausibility.md
            plausible(names, f"a bearing of {self.joint} whose axis wobbles by {{amplitude}} as it "
                      "turns", turntable=300, mount=600),
        )  # fmt: skip

    def parameters(self, variables: PositionVariables):
        """Harmonic coefficients of each tilt (``a_c1 ... a_s2``, ``b_c1 ... b_s2``), arcsec."""
        phi = f"phi{self.index}"
        return tuple(s for _, p, what in self.series for s in harmonic_parameters(p, what, phi))

    def chain_terms(self, variables: PositionVariables):
        """A harmonic series in the joint's angle added to each of its two tilts."""
        angle = variables.angle(self.index)
        return tuple(ChainTerm(t, None, harmonic_weights(angle, p)) for t, p, _ in self.series)

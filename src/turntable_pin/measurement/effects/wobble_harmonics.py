"""``wobble_harmonics@<joint>``: bearing runout of any joint that varies with its angle."""

from __future__ import annotations

from .base import ChainTerm, Effect, PositionVariables, harmonic_parameters, harmonic_weights

__all__ = ["WobbleHarmonics"]


class WobbleHarmonics(Effect):
    """Bearing runout of one joint: both tilts of its axis vary with its angle (1/rev, 2/rev).

    Args:
        joint: the joint's name (the effect is ``wobble_harmonics@<joint>``).
        index: the joint's place in the chain from the base (1 = ``phi1``).
        tilts: the table's names of the joint's two tilt errors.
        prefixes: parameter-name prefixes of the two series (default ``a_``, ``b_``).
    """

    kind = "wobble_harmonics"

    def __init__(
        self,
        joint: str,
        index: int,
        tilts: tuple[str, str],
        prefixes: tuple[str, str] = ("a_", "b_"),
    ) -> None:
        self.joint, self.index = joint, int(index)
        self.tilts, self.prefixes = tuple(tilts), tuple(prefixes)
        phi = f"phi{self.index}"
        self.name = f"{self.kind}@{joint}"
        self.title = f"angle-dependent wobble of {joint}"
        self.definition = (
            ", ".join(
                f"{t} -> {t} + h_{p.rstrip('_')}({phi})"
                for t, p in zip(self.tilts, self.prefixes, strict=True)
            )
            + " (two harmonic series of degree 2)"
        )
        self.explanation = (
            "A real bearing does not turn about a fixed line: ball or race defects, preload and an "
            f"out-of-round journal tilt the axis of {joint} by an amount that repeats every "
            f"revolution, so its two tilt errors vary with {phi} (1/rev and 2/rev terms) instead "
            "of being constants."
        )
        self.confirm = (
            f"Put an electronic level or autocollimator mirror on the frame {joint} carries and "
            "record its tilt about the two directions normal to the axis over a full, slow turn: "
            "the repeatable part is the wobble curve."
        )

    def parameters(self, variables: PositionVariables):
        """Harmonic coefficients of each tilt (``a_c1 ... a_s2``, ``b_c1 ... b_s2``), arcsec."""
        phi = f"phi{self.index}"
        return tuple(
            spec
            for tilt, prefix in zip(self.tilts, self.prefixes, strict=True)
            for spec in harmonic_parameters(prefix, f"{self.joint} wobble ({tilt})", phi)
        )

    def chain_terms(self, variables: PositionVariables):
        """A harmonic series in the joint's angle added to each of its two tilts."""
        angle = variables.angle(self.index)
        return tuple(
            ChainTerm(tilt, None, harmonic_weights(angle, prefix))
            for tilt, prefix in zip(self.tilts, self.prefixes, strict=True)
        )

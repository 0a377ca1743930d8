"""``payload_mount``: the instrument is mounted askew on the frame that carries it."""

from __future__ import annotations

import numpy as np

from .base import ARCSEC, POST, ChainTerm, Effect, ParameterSpec, PositionVariables, plausible

__all__ = ["PayloadMount"]


class PayloadMount(Effect):
    """Payload mounted askew: a constant rotation after ``Rt`` (same as the rotation errors of
    the placement that carries the payload)."""

    name = kind = "payload_mount"
    title = "payload mounted askew"
    plausibility = (  # docs/plausibility.md
        plausible(("mz", "my", "mx"), "a payload mounted {amplitude} askew", turntable=7200,
                  mount=7200),
    )  # fmt: skip
    definition = "Rt -> Rt Rz(mz) Ry(my) Rx(mx)"
    explanation = (
        "The instrument sits on the table's last frame through a fixture whose faces are not "
        "exactly square to that frame, so the payload frame is rotated by small constant angles "
        "with respect to it. Orientation measurements of the payload cannot tell this from the "
        "table's rotation errors of the placement that carries the payload, which are also a "
        "constant rotation at the same place of the chain: three of them together absorb any "
        "mount rotation exactly."
    )
    confirm = (
        "Measure the fixture against the frame that carries it directly (autocollimator on the "
        "mounting face and on the instrument's reference mirror), or remount the instrument "
        "rotated by 180 deg about its axis: a mount error changes sign, a turntable error does "
        "not."
    )

    def parameters(self, variables: PositionVariables):
        """``mz``, ``my`` and ``mx``, arcsec."""
        return (
            ParameterSpec("mz", "arcsec", ARCSEC, "mount rotation about z"),
            ParameterSpec("my", "arcsec", ARCSEC, "mount rotation about y"),
            ParameterSpec("mx", "arcsec", ARCSEC, "mount rotation about x"),
        )

    def chain_terms(self, variables: PositionVariables):
        """The rotations ``Rz(mz) Ry(my) Rx(mx)`` after ``Rt``, the same at every position."""
        one = np.ones(variables.n)
        return (
            ChainTerm(POST, "z", {"mz": one}),
            ChainTerm(POST, "y", {"my": one}),
            ChainTerm(POST, "x", {"mx": one}),
        )

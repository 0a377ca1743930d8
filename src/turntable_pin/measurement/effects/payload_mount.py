"""``payload_mount``: the instrument is mounted askew on the inner frame."""

from __future__ import annotations

import numpy as np

from .base import ARCSEC, POST, ChainTerm, Effect, ParameterSpec, PositionVariables

__all__ = ["PayloadMount"]


class PayloadMount(Effect):
    """Payload mounted askew: a constant rotation after ``Rt`` (same as inner-frame errors)."""

    name = "payload_mount"
    title = "payload mounted askew"
    definition = "Rt -> Rt Rz(mz) Ry(my) Rx(mx)"
    explanation = (
        "The instrument sits on the inner frame through a fixture whose faces are not exactly "
        "square to the inner frame, so the payload frame is rotated by small constant angles "
        "with respect to it. Orientation measurements of the payload cannot tell this from the "
        "inner-frame errors dalpha_y2, dphi_z2, dalpha_x2, which are also a constant rotation at "
        "the same place of the chain: the three together absorb any mount rotation exactly."
    )
    confirm = (
        "Measure the fixture against the inner frame directly (autocollimator on the mounting "
        "face and on the instrument's reference mirror), or remount the instrument rotated by "
        "180 deg about its axis: a mount error changes sign, a turntable error does not."
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

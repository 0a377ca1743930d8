"""``gravity_sag`` on any table: a payload rotation ``K a`` linear in the specific force ``a``."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .base import ARCSEC, POST, ChainTerm, Effect, ParameterSpec, PositionVariables

__all__ = ["COMPLIANCE_ENTRIES", "GravityCompliance"]

COMPLIANCE_ENTRIES = tuple(f"k_{r}{c}" for r in "xyz" for c in "xyz")
"""The nine entries of the compliance ``K`` (``k_xy``: rotation about payload x per g along y)."""


class GravityCompliance(Effect):
    """Payload rotation under gravity: ``Rt -> Rt Rx(t_x) Ry(t_y) Rz(t_z)``, ``t = K a``.

    ``a`` is the specific force in the payload frame (g): the base's +z (up, the URDF
    convention) seen from the payload at the commanded angles. ``K`` is a 3x3 compliance
    (arcsec/g); the paper's sag is ``k_xy = -k``, ``k_yx = k``. A long payload (a telescope tube
    along x) bends with the force across its axis: ``k_yz``, ``k_zy``.

    Args:
        rotation: the nominal payload orientation at joint angles, ``rotation(joint_rad (N, J))
            -> (N, 3, 3)``.
        entries: the entries of ``K`` to fit (default all nine; the table's catalogue keeps those
            orientation data determine beyond the base errors).
    """

    kind = "gravity_sag"

    def __init__(self, rotation, entries: Sequence[str] = COMPLIANCE_ENTRIES) -> None:
        unknown = sorted(set(entries) - set(COMPLIANCE_ENTRIES))
        if unknown:
            raise ValueError(f"not entries of K: {unknown}")
        self.rotation = rotation
        self.entries = tuple(e for e in COMPLIANCE_ENTRIES if e in entries)
        self.name = self.kind
        self.title = "payload sag under gravity"
        self.definition = (
            "Rt -> Rt Rx(t_x) Ry(t_y) Rz(t_z), t = K a, a = Rd^T e_z (specific force in the "
            f"payload frame, g); entries fitted: {', '.join(self.entries)}"
        )
        self.explanation = (
            "Frames, bearings and the payload mount are elastic: the component of gravity across "
            "the payload bends them, and the payload rotates by a compliance K (angle per g) "
            "times the specific force it feels. The rotation follows the gravity direction in "
            "the payload frame, so it changes with every axis that tips the payload."
        )
        self.confirm = (
            "Repeat a few positions with a heavier (or lighter) payload: a sag scales with the "
            "load, an encoder or wobble error does not. A dial indicator on the payload while the "
            "table tips it shows the deflection directly."
        )

    def parameters(self, variables: PositionVariables):
        """The fitted entries of ``K``, arcsec/g."""
        return tuple(
            ParameterSpec(
                e, "arcsec/g", ARCSEC, f"rotation about payload {e[2]} per g along {e[3]}"
            )
            for e in self.entries
        )

    def chain_terms(self, variables: PositionVariables):
        """Rotations about payload x, y, z by ``K a`` after ``Rt``."""
        force = np.asarray(self.rotation(variables.joint_rad))[:, 2, :]  # Rd^T e_z, (N, 3)
        terms = []
        for axis in "xyz":
            weights = {e: force[:, "xyz".index(e[3])] for e in self.entries if e[2] == axis}
            if weights:
                terms.append(ChainTerm(POST, axis, weights))
        return tuple(terms)

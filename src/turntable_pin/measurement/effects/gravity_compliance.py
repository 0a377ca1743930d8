"""``gravity_sag``: a payload rotation ``K a`` linear in the specific force ``a``, on any table."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .base import (
    ARCSEC,
    POST,
    ChainTerm,
    Effect,
    EffectText,
    ParameterSpec,
    PositionVariables,
    plausible,
)

__all__ = ["COMPLIANCE_ENTRIES", "GravityCompliance"]

COMPLIANCE_ENTRIES = tuple(f"k_{r}{c}" for r in "xyz" for c in "xyz")
"""The nine entries of the compliance ``K`` (``k_xy``: rotation about payload x per g along y)."""


class GravityCompliance(Effect):
    """Payload rotation under gravity: ``Rt -> Rt Rx(t_x) Ry(t_y) Rz(t_z)``, ``t = K a``.

    ``a`` is the specific force in the payload frame (g): the base's +z (up, the URDF
    convention) seen from the payload at the commanded angles. ``K`` is a 3x3 compliance
    (arcsec/g); the paper's sag is one parameter ``k`` with ``k_xy = -k``, ``k_yx = k``. A long
    payload (a telescope tube along x) bends with the force across its axis: ``k_yz``, ``k_zy``.

    Args:
        rotation: the nominal payload orientation at joint angles, ``rotation(joint_rad (N, J))
            -> (N, 3, 3)``.
        entries: the entries of ``K`` to fit, each a parameter (default all nine; the table's
            catalogue keeps those orientation data determine beyond the base errors), or
            ``{parameter: {entry: coefficient}}``: entries tied to parameters (the paper's
            ``{"k": {"k_xy": -1, "k_yx": 1}}``).
        name, text: the table's name and story of it (default ``gravity_sag``).
        labels: ``(parameter, description)`` of each parameter (default: what the entry is).
    """

    kind = "gravity_sag"

    def __init__(self, rotation, entries=COMPLIANCE_ENTRIES, *, name=None, text=None, labels=()):
        if not isinstance(entries, Mapping):
            entries = {e: {e: 1.0} for e in COMPLIANCE_ENTRIES if e in entries}
        self.tied = {p: dict(combination) for p, combination in entries.items()}
        used = {e for combination in self.tied.values() for e in combination}
        unknown = sorted(used - set(COMPLIANCE_ENTRIES))
        if unknown:
            raise ValueError(f"not entries of K: {unknown}")
        self.rotation = rotation
        self.entries = tuple(e for e in COMPLIANCE_ENTRIES if e in used)
        self.labels = tuple(labels) or tuple(
            (p, f"rotation about payload {p[2]} per g along {p[3]}") for p in self.tied
        )
        self.plausibility = (  # docs/plausibility.md
            plausible(tuple(self.tied), "a payload and its frames bending by {amplitude} under "
                      "their own weight", "arcsec/g", turntable=300, mount=3600),
        )  # fmt: skip
        if [p for p, _ in self.labels] != list(self.tied):
            raise ValueError(f"labels {self.labels} do not name the parameters {list(self.tied)}")
        super().__init__(
            name or self.kind,
            text,
            EffectText(
                title="payload sag under gravity",
                definition="Rt -> Rt Rx(t_x) Ry(t_y) Rz(t_z), t = K a, a = Rd^T e_z (specific "
                f"force in the payload frame, g); entries fitted: {', '.join(self.entries)}",
                explanation="Frames, bearings and the payload mount are elastic: the component "
                "of gravity across the payload bends them, and the payload rotates by a "
                "compliance K (angle per g) times the specific force it feels. The rotation "
                "follows the gravity direction in the payload frame, so it changes with every "
                "axis that tips the payload.",
                confirm="Repeat a few positions with a heavier (or lighter) payload: a sag "
                "scales with the load, an encoder or wobble error does not. A dial indicator on "
                "the payload while the table tips it shows the deflection directly.",
            ),
        )

    def parameters(self, variables: PositionVariables):
        """The fitted entries of ``K`` (or the parameters they are tied to), arcsec/g."""
        return tuple(ParameterSpec(p, "arcsec/g", ARCSEC, what) for p, what in self.labels)

    def chain_terms(self, variables: PositionVariables):
        """Rotations about payload x, y, z by ``K a`` after ``Rt``."""
        force = np.asarray(self.rotation(variables.joint_rad))[:, 2, :]  # Rd^T e_z, (N, 3)
        terms = []
        for axis in "xyz":
            weights = {}
            for p, combination in self.tied.items():
                parts = [c * force[:, "xyz".index(e[3])] for e, c in combination.items()
                         if e[2] == axis]  # fmt: skip
                if parts:
                    weights[p] = sum(parts[1:], parts[0])
            if weights:
                terms.append(ChainTerm(POST, axis, weights))
        return tuple(terms)

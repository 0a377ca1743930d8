"""TPOINT's flexure terms on a telescope mount: ``TF``, ``TX`` (alt-az); ``TF``, ``FO``, ``DAF``
(equatorial). Named by TPOINT's names; in the catalogue of a mount only
(:func:`~turntable_pin.measurement.catalogue.catalogue`).

- ``TF`` (tube flexure): the tube droops towards the ground, a rotation ``TF (up x b)`` in the
  base frame (``b`` the boresight): in the payload frame ``Rt -> Rt Ry(TF up_z) Rz(-TF up_y)``,
  ``up = Rd^T e_z`` at the commanded angles. To first order this is TPOINT's formula on both mounts
  (alt-az ``dE = -TF cos E``; equatorial the hour-angle and declination parts).
- The others change one axis' coordinate, so they add to that joint's position error (a rotation
  about its own axis moves the boresight along its coordinate exactly): ``TX``: elevation
  ``+= -TX cot E``; ``FO``: declination ``+= FO cos H``; ``DAF``: hour angle
  ``+= -DAF (cos(lat) cos H + sin(lat) tan d)``.
"""

from __future__ import annotations

import numpy as np

from ...core.exceptions import InputError
from ..pointing_terms import coordinate_offsets, mount_kind, mount_terms
from .base import ARCSEC, POST, ChainTerm, Effect, ParameterSpec, PositionVariables, plausible

__all__ = ["GRAVITY_TERMS", "JOINT_TERMS", "MIN_SINE", "PointingFlexure", "pointing_flexures"]

GRAVITY_TERMS = ("TF",)
"""Terms made as the tube's droop under gravity (a rotation after ``Rt``)."""

JOINT_TERMS = {"TX": 1, "FO": 1, "DAF": 0}
"""Terms that change one joint's coordinate: the joint (0 = phi1, 1 = phi2) whose position error
they add to."""

MIN_SINE = 1e-3
"""``TX`` (``cot E``) needs ``|sin E|`` and ``DAF`` (``tan d``) ``|cos d|`` at least this: closer
to the horizon (the pole) the term is infinite."""

_SINGULAR = {"TX": (np.sin, "0"), "DAF": (np.cos, "+-90")}


class PointingFlexure(Effect):
    """One TPOINT flexure term of a mount, with its one coefficient (arcsec).

    Args:
        term: the :class:`~turntable_pin.measurement.pointing_terms.PointingTerm`.
        mount: the :class:`~turntable_pin.measurement.pointing_terms.Mount`.
        table: the :class:`~turntable_pin.measurement.table.MeasuredTable` (its rotation and
            joints' position errors).
    """

    def __init__(self, term, mount, table) -> None:
        self.term, self.mount = term, mount
        self.rotation = table.rotation
        self.positions = tuple(j.position for j in table.joints)
        self.name = term.name
        self.title = f"{term.title} (TPOINT {term.name})"
        if term.name in GRAVITY_TERMS:
            self.definition = (
                f"Rt -> Rt Ry({term.name} up_z) Rz(-{term.name} up_y), up = Rd^T e_z (the tube "
                f"droops towards the ground); first order: {term.formula}"
            )
        else:
            site = self.positions[JOINT_TERMS[term.name]]
            self.definition = f"{site} += the correction of {term.formula}"
        self.explanation = term.explanation
        self.confirm = term.confirm
        self.plausibility = (  # docs/plausibility.md
            plausible((term.name,), f"a {term.title} of {{amplitude}}", mount=3600),
        )

    def parameters(self, variables: PositionVariables):
        """The coefficient, named after the term, arcsec."""
        return (
            ParameterSpec(self.term.name, "arcsec", ARCSEC, f"{self.title}: {self.term.formula}"),
        )

    def chain_terms(self, variables: PositionVariables):
        """The droop after ``Rt`` (TF) or the correction added to a joint's position error."""
        name = self.term.name
        if name in GRAVITY_TERMS:
            up = np.asarray(self.rotation(variables.joint_rad))[:, 2, :]  # Rd^T e_z, (N, 3)
            return (ChainTerm(POST, "y", {name: up[:, 2]}), ChainTerm(POST, "z", {name: -up[:, 1]}))
        if name in _SINGULAR:
            function, where = _SINGULAR[name]
            if np.any(np.abs(function(variables.joint_rad[:, 1])) < MIN_SINE):
                raise InputError(
                    f"effect '{name}' ({self.term.formula}) is infinite at phi2 {where} deg; "
                    "leave those rows out to fit it"
                )
        k = JOINT_TERMS[name]
        offsets = coordinate_offsets(self.term, self.mount, variables.joint_rad)
        return (ChainTerm(self.positions[k], None, {name: offsets[:, k]}),)


def pointing_flexures(table) -> tuple[PointingFlexure, ...]:
    """The flexure effects of a mount (empty on other tables), in TPOINT's order."""
    mount = mount_kind(table)
    if mount is None:
        return ()
    return tuple(PointingFlexure(t, mount, table) for t in mount_terms(mount, rigid=False))

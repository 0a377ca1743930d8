"""The paper's nine effect names as data: each is a generic effect on the paper's joints, told in
the paper's words (``docs/measurements.md``, section 4).

:data:`PAPER_EFFECTS` maps each name to the generic effect it is (its ``kind``, the joints of
``model/paper_table.py``), the names and descriptions of its parameters, and its story. The
catalogue (:func:`~turntable_pin.measurement.catalogue.catalogue`) builds the paper's table's
effects as any table's and gives them these names; no effect class knows the paper.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from ...model.paper_table import INNER_JOINT, OUTER_JOINT
from .base import EffectText, Labels

__all__ = ["PAPER_EFFECTS", "NamedEffect"]


@dataclass(frozen=True)
class NamedEffect:
    """One generic effect under a table's own name.

    Attributes:
        name: the table's name of it (``outer_encoder_harmonics``).
        kind: the generic effect (``encoder_harmonics``, ``wobble_harmonics``, ``backlash``,
            ``gravity_sag``, ``base_tilt``, ``thermal_drift``, ``payload_mount``).
        joints: the joints it is an effect of (per-joint kinds).
        labels: its parameters' names and descriptions (empty: the class's own).
        text: its story where the paper tells it otherwise than the class (the definitions of
            the per-joint effects are the class's own: the same words).
        axes: ``base_tilt``: the base axes it rotates about.
        tied: ``gravity_sag``: each parameter as entries of the compliance ``K``.
    """

    name: str
    kind: str
    joints: tuple[str, ...] = ()
    labels: Labels = ()
    text: EffectText | None = None
    axes: tuple[str, ...] = ()
    tied: Mapping[str, Mapping[str, float]] = field(default_factory=dict)


PAPER_EFFECTS: tuple[NamedEffect, ...] = (
    NamedEffect(
        "outer_encoder_harmonics", "encoder_harmonics", (OUTER_JOINT,),
        labels=(("", "outer-axis position error"),),
        text=EffectText(
            title="outer-axis encoder eccentricity and ellipticity",
            explanation="An angle encoder whose graduated disc is mounted off-centre on the outer "
            "axis reads the angle with an error that varies once per revolution (about 412.5 e[um] "
            "/ D[mm] arcsec for an eccentricity e on a disc of diameter D); an elliptical disc or "
            "a two-head misalignment adds a twice-per-revolution term. The table then stops at "
            "phi1 + h(phi1) instead of phi1: the outer-axis position error is no longer a "
            "constant.",
            confirm="Measure the outer-axis angle against an independent reference (autocollimator "
            "and optical polygon, or a second encoder read head 180 deg away) over a full turn: "
            "the difference shows the 1/rev and 2/rev curve, independent of the payload load.",
        ),
    ),
    NamedEffect(
        "inner_encoder_harmonics", "encoder_harmonics", (INNER_JOINT,),
        labels=(("", "inner-axis position error"),),
        text=EffectText(
            title="inner-axis encoder eccentricity and ellipticity",
            explanation="The inner-axis encoder disc is off-centre (1/rev) or elliptical (2/rev), "
            "so the inner axis stops at phi2 + h(phi2): its position error varies with the inner "
            "angle. It shows in the rotation about the inner axis, dtheta, as a harmonic curve in "
            "phi2.",
            confirm="Compare the inner-axis angle with an independent reference (autocollimator on "
            "an optical polygon mounted on the inner frame) over a full turn of the inner axis.",
        ),
    ),
    NamedEffect(
        "outer_wobble_harmonics", "wobble_harmonics", (OUTER_JOINT,),
        labels=(("x_", "outer wobble about x"), ("z_", "outer wobble about z")),
        text=EffectText(
            title="angle-dependent wobble of the outer axis",
            explanation="A real bearing does not turn about a fixed line: ball or race defects, "
            "preload and an out-of-round journal tilt the outer axis by an amount that repeats "
            "every revolution. The wobble angles about x and z of the outer axis then vary with "
            "phi1 (1/rev and 2/rev terms) instead of being constants. A base that is not level "
            "looks, seen from the rotating outer frame, exactly like a 1/rev outer wobble.",
            confirm="Put an electronic level or autocollimator mirror on the outer frame and "
            "record its tilt about the two axes normal to the outer axis over a full, slow turn: "
            "the repeatable part is the wobble curve. A base tilt instead shows as a tilt of the "
            "whole table on a level placed on the base.",
        ),
    ),
    NamedEffect(
        "inner_wobble_harmonics", "wobble_harmonics", (INNER_JOINT,),
        labels=(("x_", "inner wobble about x"), ("y_", "inner wobble about y")),
        text=EffectText(
            title="angle-dependent wobble of the inner axis",
            explanation="The inner bearing's runout tilts the inner axis about x and y by amounts "
            "that repeat every turn of the inner axis, so the inner wobble angles vary with phi2 "
            "(1/rev and 2/rev) instead of being constants. It shows in dpsi and dgamma as harmonic "
            "curves in phi2.",
            confirm="Mount a mirror or electronic level on the inner frame and record its tilt "
            "about the two axes normal to the inner axis over a slow full turn of the inner axis, "
            "the outer axis held still.",
        ),
    ),
    NamedEffect(
        "gravity_sag", "gravity_sag",
        labels=(("k", "tilt compliance per g of lateral force"),),
        text=EffectText(
            definition="Rt -> Rt Rx(-k ay) Ry(k ax), ax = -sin(phi1) cos(phi2), ay = sin(phi1) "
            "sin(phi2) (specific force in the payload frame, g)",
            explanation="Frames, bearings and the payload mount are elastic: the component of "
            "gravity across the payload bends them, and the payload tilts by a compliance k (angle "
            "per g) times that component. The tilt follows the gravity direction in the payload "
            "frame, so it grows with sin(phi1) and turns with phi2; on orientation data it looks "
            "like a once-per-revolution outer-encoder term proportional to sin(phi1).",
            confirm="Repeat a few positions with a heavier (or lighter) payload: a sag scales with "
            "the load, an encoder error does not. A dial indicator on the payload while the table "
            "tips to phi1 = +-90 deg shows the deflection directly.",
        ),
        tied={"k": {"k_xy": -1.0, "k_yx": 1.0}},
    ),
    NamedEffect(
        "base_tilt", "base_tilt",
        labels=(("tx", "tilt of the base about x (north)"),
                ("tz", "rotation of the base about z (up)")),
        text=EffectText(
            definition="Rt -> Rx(tx) Rz(tz) Rt",
            explanation="The table stands on a floor or a pier that is not exactly level, or the "
            "reference the orientation is measured against (a theodolite line, a reference mirror) "
            "is tilted with respect to the base: the whole table, with both axes, is rotated by "
            "small angles about north (tx) and up (tz) before anything turns. A tilt about the "
            "outer axis itself (y) is a shift of phi1, already the outer position error, so only "
            "tx and tz are new.",
        ),
        axes=("x", "z"),
    ),
    NamedEffect("thermal_drift", "thermal_drift"),
    NamedEffect(
        "backlash", "backlash", (OUTER_JOINT, INNER_JOINT),
        labels=(("b1", "outer-axis backlash"), ("b2", "inner-axis backlash")),
        text=EffectText(
            title="backlash (approach-direction dependence)",
            explanation="Gears, couplings and the servo's dead band let an axis stop a little "
            "short of the commanded angle, on the side it came from: the position error differs by "
            "b between approaches from below (dir = +1) and from above (dir = -1). Only one of "
            "dir1 / dir2 is needed; the parameter of an absent column is not fitted.",
            confirm="Approach a few positions alternately from both directions (or always from the "
            "same side) and compare: a backlash flips sign with the approach direction; a "
            "unidirectional approach removes it.",
        ),
    ),
    NamedEffect(
        "payload_mount", "payload_mount",
        text=EffectText(
            explanation="The instrument sits on the inner frame through a fixture whose faces are "
            "not exactly square to the inner frame, so the payload frame is rotated by small "
            "constant angles with respect to it. Orientation measurements of the payload cannot "
            "tell this from the inner-frame errors dalpha_y2, dphi_z2, dalpha_x2, which are also a "
            "constant rotation at the same place of the chain: the three together absorb any mount "
            "rotation exactly.",
            confirm="Measure the fixture against the inner frame directly (autocollimator on the "
            "mounting face and on the instrument's reference mirror), or remount the instrument "
            "rotated by 180 deg about its axis: a mount error changes sign, a turntable error does "
            "not.",
        ),
    ),
)  # fmt: skip
"""The paper's effects in catalogue order."""

"""The paper's two-axis table as data: its joint and frame names, the Table 3 error factors, the
names and words of its Table 2 errors and of its effects, and the name map over the one generic
table.

The bundled ``models/turntable.urdf`` names its joints ``outer_axis`` (phi1, about y) and
``inner_axis`` (phi2, about z), the fixed ``payload_mount`` and the payload frame ``gyrowheel``.
:data:`PAPER_LAYOUT` is the table as an :class:`~.generic_table.ErrorLayout` (Table 3's factors,
its names and texts, eq. 26, the phi2 intervals of eqs. 31-33, its lower bounds and effects);
:func:`paper_table` is the :class:`~.generic_table.GenericTable` of the URDF under it: no code
elsewhere asks which table it has.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

from ..core.exceptions import InputError
from ..core.resources import default_urdf_path
from .errors import ERROR_DESCRIPTIONS, ERROR_NAMES
from .generic_table import ClosedForm, ErrorLayout, GenericTable
from .named_effects import EffectText, NamedEffect
from .small_angle import small_angle_orientation_error

__all__ = [
    "INNER_JOINT",
    "JOINT_ERRORS",
    "LAYOUTS",
    "OUTER_JOINT",
    "PAPER_EFFECTS",
    "PAPER_LAYOUT",
    "PAYLOAD_FRAME",
    "PAYLOAD_MOUNT",
    "PHI2_INTERVALS_DEG",
    "PLACEMENT_ERROR_FACTORS",
    "PLACEMENT_ORDER",
    "paper_table",
    "resolve_table",
    "table_of",
]

OUTER_JOINT = "outer_axis"
INNER_JOINT = "inner_axis"
PAYLOAD_MOUNT = "payload_mount"
PAYLOAD_FRAME = "gyrowheel"

PLACEMENT_ERROR_FACTORS: dict[str, tuple[tuple[str, str, str], ...]] = {
    OUTER_JOINT: (("rot", "y", "dphi_y1"),),
    INNER_JOINT: (
        ("rot", "z", "dalpha_z1"),
        ("rot", "x", "dalpha_x1"),
        ("trans", "x", "deta"),
        ("rot", "y", "deps_y"),
        ("rot", "x", "deps_x"),
    ),
    PAYLOAD_MOUNT: (
        ("rot", "y", "dalpha_y2"),
        ("rot", "z", "dphi_z2"),
        ("rot", "x", "dalpha_x2"),
    ),
}
"""The paper's Table 3 as data: ``(kind, axis, error name)`` factors of each placement, in order."""

PLACEMENT_ORDER: tuple[str, ...] = (OUTER_JOINT, INNER_JOINT, PAYLOAD_MOUNT)
"""The placements carrying errors, from the base."""

JOINT_ERRORS: dict[str, tuple[str, str, str]] = {
    OUTER_JOINT: ("dphi_y1", "dalpha_x1", "dalpha_z1"),
    INNER_JOINT: ("dphi_z2", "dalpha_x2", "dalpha_y2"),
}
"""Each joint's position error and its two wobble (tilt) errors in the paper's names: what the
generic ``<joint>.position``, ``.tilt_a``, ``.tilt_b`` are called on this table."""

PHI2_INTERVALS_DEG: dict[str, tuple[float, float]] = {
    "gamma": (0.0, 90.0),  # eq. 31
    "theta": (0.0, 360.0),  # eq. 32 has no phi2; the whole turn is the same constraint
    "psi": (270.0, 360.0),  # eq. 33
}
"""The paper's Omega_k, degrees: the phi2 interval of each angle's constraint, where every term of
eq. 26 is non-negative (so the largest first-order error is the paper's ``f_k(phi2, x)``)."""


def _eq26(error_values, angles_rad):
    """Eq. 26 at one position: the paper's closed first-order form (it depends on phi2 only)."""
    return small_angle_orientation_error(error_values, angles_rad[1])


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


PAPER_LAYOUT = ErrorLayout(
    PLACEMENT_ERROR_FACTORS, ERROR_NAMES, ERROR_DESCRIPTIONS, JOINT_ERRORS, "paper", PAYLOAD_FRAME,
    title="the paper's table",
    angle_names=("phi1", "phi2"),
    first_order=ClosedForm("eq. 26", _eq26),
    domains_deg={angle: {INNER_JOINT: interval} for angle, interval in PHI2_INTERVALS_DEG.items()},
    lower_bounds_file="manufacturing_lower_bounds.yaml",
    effects=PAPER_EFFECTS,
)  # fmt: skip
"""The paper's table as a layout over the generic table (see the module docstring)."""

LAYOUTS: tuple[ErrorLayout, ...] = (PAPER_LAYOUT,)
"""The bundled layouts: a URDF whose joints and payload frame one of them is written for is read
under it (:func:`table_of`)."""


@lru_cache(maxsize=8)
def _table_under(urdf: str, layout: ErrorLayout, telescope_mount: str | None = None):
    """The table of a URDF under a bundled layout, read once per file, layout, mount and process."""
    return GenericTable(urdf, layout=layout, telescope_mount=telescope_mount)


def paper_table(urdf_path: str | Path | None = None, telescope_mount: str | None = None):
    """The paper's table: the :class:`~turntable_pin.model.generic_table.GenericTable` of
    ``urdf_path`` (default the bundled ``models/turntable.urdf``) under :data:`PAPER_LAYOUT`
    (read once per file, ``telescope_mount`` and process)."""
    path = Path(urdf_path) if urdf_path is not None else default_urdf_path()
    if not path.is_file():
        raise InputError("no such URDF file", path=path)
    return _table_under(str(path.resolve()), PAPER_LAYOUT, telescope_mount)


def resolve_table(table=None):
    """The table ``table`` stands for, the one place a default table is chosen: ``None``, the
    bundled table (:func:`paper_table`); an object holding a table as ``.table`` (a position
    set), that table; else ``table`` itself."""
    if table is None:
        return paper_table()
    return getattr(table, "table", table)


def table_of(
    urdf_path: str | Path | None = None,
    payload_frame: str | None = None,
    telescope_mount: str | None = None,
):
    """The table of a URDF (default the bundled one) under the first of :data:`LAYOUTS` written
    for its chain, else the generic rule; ``telescope_mount`` overrides the URDF's declaration."""
    table = GenericTable(urdf_path or paper_table().urdf_path, payload_frame,
                         telescope_mount=telescope_mount)  # fmt: skip
    layout = next((x for x in LAYOUTS if x.fits(table.joint_names, table.payload_frame)), None)
    if layout is None:
        return table
    return _table_under(str(Path(table.urdf_path).resolve()), layout, telescope_mount)

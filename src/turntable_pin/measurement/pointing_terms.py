"""TPOINT's pointing terms by name on a telescope mount (``docs/measurements.md``, "TPOINT terms
on a mount").

A telescope mount is a two-axis table whose orientation errors are pointing errors. Two kinds,
in the frames of their bundled URDFs (``models/altaz_mount.urdf``,
``models/german_equatorial_mount.urdf``: base x South, y East, z up; payload x the boresight):

- **alt-az**: first axis vertical, phi1 = azimuth A (South 0, East 90), phi2 = elevation E;
  ``dtheta ~ dA cos E``, ``dpsi ~ -dE``;
- **equatorial**: first axis tilted to the latitude phi, phi1 = hour angle H (positive West),
  phi2 = declination d; ``dtheta ~ -dH cos d``, ``dpsi ~ -dd``.

``dA, dE, dH, dd`` are TPOINT's corrections *observed minus raw* (encoder), first order in the
coefficients, as TPOINT's formulas write them (the published MMT fit's ``obs = raw + D``). A table
is a mount only when it says so (its URDF's ``<turntable_pin mount="altaz"/>`` or
``"equatorial"``, or the caller: :mod:`turntable_pin.model.mount_declaration`), never guessed
from its axes; a declared mount's chain must be the documented one (:func:`mount_kind`).

*Rigid* terms (IA IE NPAE CA AN AW; IH ID CH NP MA ME) are the mount's rigid placement errors
seen on the two measured angles: :func:`rigid_term_map` finds each numerically as a linear
functional of the generic errors (``<joint>.position``, ``.tilt_a``, ``.tilt_b``,
``<mount>.rot_x|y|z``), exact to first order (both span the same space; checked). *Flexure*
terms (TF, TX; TF, FO, DAF) are catalogue effects (:mod:`.effects.pointing_flexure`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..core.exceptions import InputError
from ..core.rotations import axis_rotation
from ..core.units import ARCSEC_PER_RAD
from ..model.angles import ANGLE_NAMES
from ..model.mount_declaration import ALTAZ, EQUATORIAL, declaration_text
from ..stats.least_squares import combination_name
from .effect_model import OrientationModel
from .effects.base import PositionVariables
from .table import measured_table

__all__ = [
    "ALTAZ",
    "EQUATORIAL",
    "INDEX_TERMS",
    "MAP_RTOL",
    "PIER_RULE",
    "POINTING_TERMS",
    "SECOND_ORDER_NOTE",
    "UNOBSERVED_ROLL_NOTE",
    "Mount",
    "PointingTerm",
    "RigidTermMap",
    "coordinate_offsets",
    "fitted_pointing_terms",
    "mount_kind",
    "mount_terms",
    "nominal_orientation",
    "pointing_note",
    "rigid_term_map",
    "term_signature",
    "to_measured",
]

MAP_RTOL = 1e-9
"""Largest relative residual of the rigid map (and of the documented orientation) for a declared
mount's chain: beyond it the table is not that mount in the documented frames (refused)."""

SECOND_ORDER_NOTE = (
    "The chain is exact and TPOINT's formulas are first order, so the terms differ from a "
    "TPOINT fit by second-order products: a pure index offset is exact in both, but its "
    "products with the other terms are not."
)
"""Why fitted terms differ from a TPOINT fit (one sentence; :func:`pointing_note` adds the size
of the products on the data at hand)."""

INDEX_TERMS = ("IA", "IH")
"""The index terms whose products with the others are the largest second-order terms."""

PIER_RULE = (
    "ID, CH and NP are the mechanism's: on the far side of the pier (raw dec beyond +-90 deg) "
    "their effect on the sky changes sign, TPOINT's rule"
)
"""How the equatorial terms read across the pier (stated in the convention of such a mount)."""

UNOBSERVED_ROLL_NOTE = "The roll about the boresight (dgamma) is not observed: its column is empty."
"""Added to the note when, and only when, the data's ``dgamma`` column is empty."""


@dataclass(frozen=True)
class Mount:
    """What kind of mount a table is.

    Attributes:
        kind: :data:`ALTAZ` or :data:`EQUATORIAL`.
        latitude_rad: the site latitude (the polar axis' elevation), rad; 0 for alt-az.
    """

    kind: str
    latitude_rad: float = 0.0

    @property
    def latitude_deg(self) -> float | None:
        """The latitude in degrees (``None`` on an alt-az mount)."""
        return None if self.kind == ALTAZ else float(np.degrees(self.latitude_rad))


@dataclass(frozen=True)
class PointingTerm:
    """One TPOINT term.

    Attributes:
        name: TPOINT's name (``IA``, ``TF``); mount: :data:`ALTAZ` or :data:`EQUATORIAL`.
        rigid: a rigid placement error of the mount (else a flexure: a catalogue effect).
        title: a few words; formula: TPOINT's first-order formula, obs - raw, in words.
        offsets: ``(angle1_rad, angle2_rad, latitude_rad) -> (D1, D2)``: the coordinate
            corrections (``dA, dE`` or ``dH, dd``, rad) per unit coefficient (rad).
        explanation: the physical story; confirm: how to check it on the machine.
    """

    name: str
    mount: str
    rigid: bool
    title: str
    formula: str
    offsets: Callable
    explanation: str
    confirm: str


def _z(a):
    return np.zeros_like(a)


def _one(a):
    return np.ones_like(a)


_ALTAZ_TERMS = (
    PointingTerm(
        "IA",
        ALTAZ,
        True,
        "azimuth index error",
        "dA = -IA",
        lambda a, e, lat: (-_one(a), _z(a)),
        "The azimuth encoder's zero is not South: every azimuth is off by the same angle.",
        "Point at a terrestrial mark of known azimuth.",
    ),
    PointingTerm(
        "IE",
        ALTAZ,
        True,
        "elevation index error",
        "dE = +IE",
        lambda a, e, lat: (_z(a), _one(a)),
        "The elevation encoder's zero is not the horizon: every elevation is off by the same "
        "angle.",
        "Level the tube with an inclinometer at a known encoder elevation.",
    ),
    PointingTerm(
        "NPAE",
        ALTAZ,
        True,
        "azimuth/elevation axes not perpendicular",
        "dA = -NPAE tan E",
        lambda a, e, lat: (-np.tan(e), _z(a)),
        "The elevation axis is not square to the azimuth axis: the boresight sweeps a tilted "
        "circle, a left-right shift growing as sin E.",
        "Measure the elevation axis' tilt with a striding level at two azimuths 180 deg apart.",
    ),
    PointingTerm(
        "CA",
        ALTAZ,
        True,
        "left-right collimation error",
        "dA = -CA sec E",
        lambda a, e, lat: (-1.0 / np.cos(e), _z(a)),
        "The optical axis is not square to the elevation axis: a constant left-right shift on "
        "the sky.",
        "Rotate the instrument 180 deg in its mount, or autocollimate on the elevation axis.",
    ),
    PointingTerm(
        "AN",
        ALTAZ,
        True,
        "azimuth axis tilted north-south",
        "dA = -AN sin A tan E, dE = -AN cos A",
        lambda a, e, lat: (-np.sin(a) * np.tan(e), -np.cos(a)),
        "The azimuth axis leans in the north-south plane (the pier or the azimuth bearing is "
        "not level): a rotation about the East-West axis.",
        "Read a precision level on the azimuth platform at several azimuths.",
    ),
    PointingTerm(
        "AW",
        ALTAZ,
        True,
        "azimuth axis tilted east-west",
        "dA = -AW cos A tan E, dE = +AW sin A",
        lambda a, e, lat: (-np.cos(a) * np.tan(e), np.sin(a)),
        "The azimuth axis leans in the east-west plane: a rotation about the North-South axis.",
        "Read a precision level on the azimuth platform at several azimuths.",
    ),
    PointingTerm(
        "TF",
        ALTAZ,
        False,
        "tube flexure (sin of zenith distance)",
        "dE = -TF cos E",
        lambda a, e, lat: (_z(a), -np.cos(e)),
        "The tube sags under its own weight: the bending grows with the gravity component "
        "across the tube, the sine of the zenith distance, so the boresight droops by TF at "
        "the horizon and not at all at the zenith.",
        "Repeat the run with the tube's balance or mass changed (a weight at the top end): a "
        "flexure changes, an index or axis error does not; or measure the tube's sag with a "
        "collimator at a few elevations.",
    ),
    PointingTerm(
        "TX",
        ALTAZ,
        False,
        "elevation term in cot E (refraction or flexure)",
        "dE = -TX cot E",
        lambda a, e, lat: (_z(a), -1.0 / np.tan(e)),
        "An elevation error growing as cot E towards the horizon: refraction modelled with the "
        "wrong constants (temperature, pressure) or a flexure that grows faster than sin z "
        "near the horizon.",
        "Rerun with the refraction constants from a local weather station's temperature and "
        "pressure: a refraction error goes, a flexure stays.",
    ),
)

_EQUATORIAL_TERMS = (
    PointingTerm(
        "IH",
        EQUATORIAL,
        True,
        "hour angle index error",
        "dH = -IH",
        lambda h, d, lat: (-_one(h), _z(h)),
        "The hour-angle encoder's zero is not the meridian.",
        "Point at a star on the meridian at a known time.",
    ),
    PointingTerm(
        "ID",
        EQUATORIAL,
        True,
        "declination index error",
        "dd = -ID",
        lambda h, d, lat: (_z(h), -_one(h)),
        "The declination encoder's zero is not the equator.",
        "Point at stars of known declination on both sides of the pier.",
    ),
    PointingTerm(
        "CH",
        EQUATORIAL,
        True,
        "east-west collimation error",
        "dH = -CH sec d",
        lambda h, d, lat: (-1.0 / np.cos(d), _z(h)),
        "The optical axis is not square to the declination axis: a constant east-west shift on "
        "the sky.",
        "Rotate the instrument 180 deg in its mount, or compare stars on both sides of the pier.",
    ),
    PointingTerm(
        "NP",
        EQUATORIAL,
        True,
        "polar/declination axes not perpendicular",
        "dH = -NP tan d",
        lambda h, d, lat: (-np.tan(d), _z(h)),
        "The declination axis is not square to the polar axis: an east-west shift growing as "
        "sin d.",
        "Measure the declination axis' tilt with a level at hour angles 6h east and west.",
    ),
    PointingTerm(
        "MA",
        EQUATORIAL,
        True,
        "polar axis misaligned in azimuth",
        "dH = -MA cos H tan d, dd = +MA sin H",
        lambda h, d, lat: (-np.cos(h) * np.tan(d), np.sin(h)),
        "The polar axis points left or right of the celestial pole: a rotation about the vertical.",
        "Drift-align: a star near the meridian drifts in declination when MA is not zero.",
    ),
    PointingTerm(
        "ME",
        EQUATORIAL,
        True,
        "polar axis misaligned in elevation",
        "dH = +ME sin H tan d, dd = +ME cos H",
        lambda h, d, lat: (np.sin(h) * np.tan(d), np.cos(h)),
        "The polar axis points above or below the celestial pole: a rotation about the "
        "East-West axis.",
        "Drift-align: a star low in the east or west drifts in declination when ME is not zero.",
    ),
    PointingTerm(
        "TF",
        EQUATORIAL,
        False,
        "tube flexure (sin of zenith distance)",
        "dH = +TF cos(lat) sin H sec d, dd = +TF (cos(lat) cos H sin d - sin(lat) cos d)",
        lambda h, d, lat: (
            np.cos(lat) * np.sin(h) / np.cos(d),
            np.cos(lat) * np.cos(h) * np.sin(d) - np.sin(lat) * np.cos(d),
        ),
        "The tube sags under its own weight towards the ground, by TF times the sine of the "
        "zenith distance; in hour angle and declination that droop has both components.",
        "Repeat the run with the tube's balance or mass changed: a flexure changes, an index "
        "or axis error does not; or measure the tube's sag with a collimator.",
    ),
    PointingTerm(
        "FO",
        EQUATORIAL,
        False,
        "fork flexure",
        "dd = +FO cos H",
        lambda h, d, lat: (_z(h), np.cos(h)),
        "The fork arms (or the declination housing) bend under the tube's weight, more when "
        "the tube hangs across them: a declination error in cos H.",
        "Repeat the run with the tube's weight changed, or read a dial gauge on the fork tines "
        "while the mount turns in hour angle.",
    ),
    PointingTerm(
        "DAF",
        EQUATORIAL,
        False,
        "declination axis flexure",
        "dH = -DAF (cos(lat) cos H + sin(lat) tan d)",
        lambda h, d, lat: (-(np.cos(lat) * np.cos(h) + np.sin(lat) * np.tan(d)), _z(h)),
        "The declination axis bends under the tube and counterweight, tilting the tube east "
        "or west with the gravity component along the axis.",
        "Change the counterweight and the tube's mass together (the balance kept): a bending of "
        "the declination shaft scales with the load.",
    ),
)

POINTING_TERMS: dict[str, tuple[PointingTerm, ...]] = {
    ALTAZ: _ALTAZ_TERMS,
    EQUATORIAL: _EQUATORIAL_TERMS,
}
"""TPOINT's terms of each mount kind, rigid terms first."""


def mount_terms(mount: Mount, rigid: bool | None = None) -> tuple[PointingTerm, ...]:
    """The terms of ``mount``'s kind (only the rigid or only the flexure ones if asked)."""
    terms = POINTING_TERMS[mount.kind]
    return terms if rigid is None else tuple(t for t in terms if t.rigid == rigid)


def nominal_orientation(mount: Mount, joint_rad: np.ndarray) -> np.ndarray:
    """The documented payload orientation ``Rd`` (N, 3, 3) at joint angles (N, 2):
    alt-az ``Rz(A) Ry(-E)``, equatorial ``Ry(lat - 90 deg) Rz(-H) Ry(-d)``."""
    q1, q2 = np.asarray(joint_rad, dtype=float).T
    if mount.kind == ALTAZ:
        return axis_rotation("z", q1) @ axis_rotation("y", -q2)
    tilt = axis_rotation("y", mount.latitude_rad - np.pi / 2)
    return tilt @ axis_rotation("z", -q1) @ axis_rotation("y", -q2)


def coordinate_offsets(term: PointingTerm, mount: Mount, joint_rad: np.ndarray) -> np.ndarray:
    """TPOINT's coordinate corrections per unit coefficient, (N, 2): ``dA, dE`` or ``dH, dd``."""
    q1, q2 = np.asarray(joint_rad, dtype=float).T
    d1, d2 = term.offsets(q1, q2, mount.latitude_rad)
    return np.stack([np.broadcast_to(d1, q1.shape), np.broadcast_to(d2, q1.shape)], axis=1)


def to_measured(mount: Mount, joint_rad: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Coordinate corrections (N, 2) as the measured ``dpsi, dtheta`` (N, 2), first order:
    ``dpsi = -D2``; ``dtheta = D1 cos(phi2)`` (alt-az) or ``-D1 cos(phi2)`` (equatorial)."""
    q2 = np.asarray(joint_rad, dtype=float)[:, 1]
    sign = 1.0 if mount.kind == ALTAZ else -1.0
    return np.stack([-offsets[:, 1], sign * offsets[:, 0] * np.cos(q2)], axis=1)


def term_signature(term: PointingTerm, mount: Mount, joint_rad: np.ndarray) -> np.ndarray:
    """The first-order ``dpsi, dtheta`` (rad) of a unit coefficient (rad) of ``term``, (N, 2)."""
    return to_measured(mount, joint_rad, coordinate_offsets(term, mount, joint_rad))


def _generic_positions(n: int = 64) -> np.ndarray:
    """Generic positions away from the poles of the second angle (tan and sec are finite)."""
    rng = np.random.default_rng(0)  # generic positions: any random draw is generic
    return np.stack([rng.uniform(-np.pi, np.pi, n), rng.uniform(-1.3, 1.3, n)], axis=1)


def _first_axis_in_base(table) -> np.ndarray:
    rotation = np.eye(3)
    for link in table.chain.links:
        rotation = rotation @ link.nominal[:3, :3]
        if link.is_joint:
            axis = rotation @ np.asarray(link.axis, dtype=float)
            return axis / np.linalg.norm(axis)
    raise AssertionError("a table has at least one joint")


def _undocumented_mount(table, why: str) -> InputError:
    """The refusal of a declared mount whose chain is not the documented one, naming its URDF."""
    kind = table.telescope_mount
    said = (
        f"its {declaration_text(kind)} declares an {kind} mount"
        if table.declared_mount == kind
        else f"it was declared an {kind} mount"
    )
    bundled = "altaz_mount" if kind == ALTAZ else "german_equatorial_mount"
    return InputError(
        f"{said}, but {why}; the documented frames are those of the bundled {bundled}.urdf "
        '(docs/measurements.md, "TPOINT terms on a mount"); a table that declares no mount is a '
        "turntable",
        path=table.urdf_path,
    )


def mount_kind(turntable) -> Mount | None:
    """The mount a table is declared to be, or ``None`` (a turntable: it declares nothing).

    The kind comes from the declaration alone (the table's ``telescope_mount``: its URDF's
    ``<turntable_pin mount="..."/>`` or the caller's word), never from its axes. An equatorial
    mount's latitude is the elevation of its pole, ``asin(-a_z)`` for the first axis ``a``
    (hour angles positive West).

    Raises:
        InputError: naming the URDF, when the declared mount's chain is not the documented one:
            two joints, the nominal payload orientation :func:`nominal_orientation` to
            :data:`MAP_RTOL` at generic positions and the rigid terms mapping exactly onto its
            generic errors (:func:`rigid_term_map`).
    """
    table = measured_table(turntable)
    kind = table.telescope_mount
    if kind is None:
        return None
    if table.n_joints != 2:
        raise _undocumented_mount(table, f"its chain has {table.n_joints} joint(s), a mount two")
    if kind == ALTAZ:
        mount = Mount(ALTAZ)
    else:
        axis = _first_axis_in_base(table)
        mount = Mount(EQUATORIAL, float(np.arcsin(np.clip(-axis[2], -1.0, 1.0))))
    joints = _generic_positions()
    off = np.abs(table.rotation(joints) - nominal_orientation(mount, joints)).max()
    if off > MAP_RTOL:
        formula = "Rz(A) Ry(-E)" if kind == ALTAZ else "Ry(lat - 90 deg) Rz(-H) Ry(-d)"
        why = f"its payload orientation is not {formula} (off by {off:.3g} at generic positions)"
        raise _undocumented_mount(table, why)
    if _rigid_map(table, mount) is None:
        raise _undocumented_mount(table, "its errors do not map exactly onto TPOINT's rigid terms")
    return mount


@dataclass(frozen=True)
class RigidTermMap:
    """The rigid TPOINT terms as linear functionals of a table's base errors.

    Attributes:
        mount: the mount.
        names: the rigid terms (``IA``, ...), in :data:`POINTING_TERMS` order.
        base_names: the table's base errors (the fit's first parameters).
        matrix: (terms, base errors): ``term = matrix @ base errors`` (rad per rad).
        residual: relative residual of the map on generic positions (at most :data:`MAP_RTOL`).
    """

    mount: Mount
    names: tuple[str, ...]
    base_names: tuple[str, ...]
    matrix: np.ndarray
    residual: float

    def combinations(self) -> dict[str, str]:
        """``{term: its combination of base errors in words}`` (``-azimuth.position - ...``)."""
        rows = zip(self.names, self.matrix, strict=True)
        return {n: combination_name(r, self.base_names) for n, r in rows}


def _rigid_map(table, mount: Mount) -> RigidTermMap | None:
    joints = _generic_positions()
    model = OrientationModel(PositionVariables(joints), (), table)
    # d(dpsi, dtheta)/d(base errors) at zero errors, stacked position by position.
    generic = model.jacobian(np.zeros(model.n_params))[:, :2, :].reshape(-1, model.n_params)
    terms = mount_terms(mount, rigid=True)
    tpoint = np.stack([term_signature(t, mount, joints).reshape(-1) for t in terms], axis=1)
    matrix, *_ = np.linalg.lstsq(tpoint, generic, rcond=None)
    residual = np.linalg.norm(generic - tpoint @ matrix) / np.linalg.norm(generic)
    # ... and the other way: every term is a combination of the generic errors (same spans).
    back, *_ = np.linalg.lstsq(generic, tpoint, rcond=None)
    residual = max(residual, np.linalg.norm(tpoint - generic @ back) / np.linalg.norm(tpoint))
    if not residual <= MAP_RTOL:
        return None
    matrix = np.where(np.abs(matrix) < 1e-12, 0.0, matrix)
    return RigidTermMap(
        mount, tuple(t.name for t in terms), tuple(table.base_names), matrix, float(residual)
    )


def rigid_term_map(turntable) -> RigidTermMap | None:
    """The rigid terms of a mount as combinations of its base errors (``None``: not a mount)."""
    mount = mount_kind(turntable)
    return None if mount is None else _rigid_map(measured_table(turntable), mount)


def fitted_pointing_terms(fit) -> dict | None:
    """The TPOINT terms of a fit on a mount (``None`` on other tables), JSON-ready.

    Rigid terms come from the fitted base errors and their covariance through
    :func:`rigid_term_map`; each is a combination the data determine (checked against the fit's
    flat directions, so the minimum-norm split of undetermined combinations does not change it;
    ``std`` is ``null`` and ``determined`` false otherwise). Flexure terms are the parameters of
    the mount's flexure effects the fit includes.

    Returns:
        ``{mount, latitude_deg, convention, terms: [{name, value, std, unit, rigid, determined,
        formula, of}], note}``, values in arcsec; ``of`` is the combination of base errors
        (rigid) or the effect's parameter (flexure); ``note``: :func:`pointing_note`.
    """
    result = fit.result
    mapping = rigid_term_map(fit.model.table)
    if mapping is None:
        return None
    names = result.parameter_names
    n = len(names)
    undetermined = result.identifiability.undetermined
    formulas = {t.name: t.formula for t in mount_terms(mapping.mount)}
    combinations = mapping.combinations()
    rows = []
    for k, name in enumerate(mapping.names):
        row = np.zeros(n)
        row[[names.index(b) for b in mapping.base_names]] = mapping.matrix[k]
        rows.append((name, True, row))
    for effect in fit.effects:
        if isinstance(getattr(effect, "term", None), PointingTerm):  # a flexure effect
            row = np.zeros(n)
            row[names.index(f"{effect.name}.{effect.term.name}")] = 1.0
            rows.append((effect.term.name, False, row))
    terms = []
    for name, rigid, row in rows:
        flat = undetermined @ row if undetermined.size else np.zeros(0)
        scale = np.linalg.norm(row) * max(np.abs(undetermined).max(initial=0.0), 1.0)
        determined = bool(np.all(np.abs(flat) <= 1e-9 * scale))
        std = float(np.sqrt(max(row @ result.covariance @ row, 0.0))) * ARCSEC_PER_RAD
        terms.append(
            {
                "name": name,
                "value": float(row @ result.params) * ARCSEC_PER_RAD,
                "std": std if determined else None,
                "unit": "arcsec",
                "rigid": rigid,
                "determined": determined,
                "formula": formulas[name],
                "of": combinations.get(name, f"{name}.{name}"),
            }
        )
    convention = "TPOINT's first-order formulas, observed minus raw (obs = raw + D)"
    if mapping.mount.kind == EQUATORIAL:
        convention += f"; {PIER_RULE}"
    return {
        "mount": mapping.mount.kind,
        "latitude_deg": mapping.mount.latitude_deg,
        "convention": convention,
        "terms": terms,
        "note": pointing_note(fit.data.measured, terms),
    }


def pointing_note(measured: np.ndarray, terms=()) -> str:
    """The note of :func:`fitted_pointing_terms`: :data:`SECOND_ORDER_NOTE` with the size of the
    largest second-order product on these data (the index term times the largest other term,
    from ``terms``, the rows of :func:`fitted_pointing_terms`), and :data:`UNOBSERVED_ROLL_NOTE`
    when the data's ``dgamma`` column is empty (``measured``: which angles were measured, (N, 3)
    bool, dpsi, dtheta, dgamma)."""
    note = SECOND_ORDER_NOTE
    index = [t for t in terms if t["name"] in INDEX_TERMS]
    others = [abs(t["value"]) for t in terms if t["name"] not in INDEX_TERMS]
    if index and others:
        ia = index[0]
        index_rad = abs(ia["value"]) / ARCSEC_PER_RAD
        largest = max(others)
        note = note[:-1] + (
            f" (here {ia['name']} {np.degrees(index_rad):.2f} deg = {index_rad:.1e} rad times up "
            f"to {largest:.3g} arcsec: up to {index_rad * largest:.2g} arcsec)."
        )
    roll = np.asarray(measured, dtype=bool)[:, ANGLE_NAMES.index("dgamma")]
    return note if roll.any() else f"{note} {UNOBSERVED_ROLL_NOTE}"

"""A table's catalogue of candidate effects, and effects found by name (``docs/measurements.md``).

- Per joint: ``encoder_harmonics@<joint>``, ``wobble_harmonics@<joint>``, ``backlash@<joint>``.
- Table-wide: ``gravity_sag`` (a compliance ``K`` with the entries orientation data determine
  beyond the base errors), ``base_tilt`` (about the base axes the data tell apart from the base
  errors), ``thermal_drift``, ``payload_mount``.
- On a telescope mount (:func:`~.pointing_terms.mount_kind`), TPOINT's flexure terms by name:
  ``TF``, ``TX`` (alt-az); ``TF``, ``FO``, ``DAF`` (equatorial).

Which entries of ``K`` and which base axes are kept is found like the base errors: QR with column
pivoting of the effect's columns, after projecting out the base errors, on generic positions.

A table whose layout names effects (the paper's nine,
:data:`~turntable_pin.model.paper_table.PAPER_EFFECTS`) has the same catalogue under those names;
on any table ``<kind>@<joint>`` is the catalogue's effect of that kind on that joint alone
(``encoder_harmonics@outer_axis`` is ``outer_encoder_harmonics``).
"""

from __future__ import annotations

# scipy.linalg is imported inside _determined: importing the catalogue stays light
import weakref
from collections.abc import Sequence

import numpy as np

from ..core.exceptions import InputError
from ..model.named_effects import NamedEffect
from ..stats.least_squares import RANK_RTOL
from .effect_model import OrientationModel
from .effects.backlash import Backlash
from .effects.base import Effect, PositionVariables
from .effects.base_rotation import BaseRotation
from .effects.encoder_harmonics import EncoderHarmonics
from .effects.gravity_compliance import COMPLIANCE_ENTRIES, GravityCompliance
from .effects.payload_mount import PayloadMount
from .effects.pointing_flexure import pointing_flexures
from .effects.thermal_drift import ThermalDrift
from .effects.wobble_harmonics import WobbleHarmonics
from .table import JointErrors, MeasuredTable, measured_table

__all__ = ["PER_JOINT_EFFECTS", "catalogue", "joint_effect", "resolve_effect"]

PER_JOINT_EFFECTS = ("encoder_harmonics", "wobble_harmonics", "backlash")
"""The kinds of per-joint effects, named ``<kind>@<joint>``."""
_PER_JOINT_TEXT = ", ".join(f"{k}@<joint>" for k in PER_JOINT_EFFECTS)

_CATALOGUES: weakref.WeakKeyDictionary[MeasuredTable, tuple[Effect, ...]] = (
    weakref.WeakKeyDictionary()
)
"""The catalogue of each table in use (found once per table; gone with the table)."""


def catalogue(turntable=None) -> tuple[Effect, ...]:
    """The candidate effects of a table, in catalogue order (module docstring)."""
    table = measured_table(turntable)
    cached = _CATALOGUES.get(table)
    if cached is not None:
        return cached
    names = table.named_effects
    slots = (
        *(("encoder_harmonics", j) for j in table.joints),
        *(("wobble_harmonics", j) for j in table.joints),
        ("gravity_sag", None),
        ("base_tilt", None),
        ("thermal_drift", None),
        *(("backlash", j) for j in table.joints),
        ("payload_mount", None),
    )
    out: list[Effect] = []
    for kind, joint in slots:
        named = next(
            (n for n in names if n.kind == kind and (joint is None or joint.joint in n.joints)),
            None,
        )
        if named is None:
            out.append(_effect(table, kind, (joint,) if joint else ()))
        elif all(e.name != named.name for e in out):  # one effect of several joints: once
            out.append(_effect(table, kind, named=named))
    out.extend(pointing_flexures(table))  # a telescope mount's TPOINT flexure terms (else none)
    _CATALOGUES[table] = tuple(out)
    return _CATALOGUES[table]


def joint_effect(kind: str, joint: JointErrors) -> Effect:
    """The per-joint effect ``kind`` of ``joint``, named ``<kind>@<joint>``."""
    if kind not in PER_JOINT_EFFECTS:
        raise InputError(f"no per-joint effect '{kind}'; per-joint effects: {_PER_JOINT_TEXT}")
    return _effect(None, kind, (joint,))


def _effect(table, kind: str, joints=(), named: NamedEffect | None = None) -> Effect:
    """The generic effect ``kind`` of ``joints`` (:class:`JointErrors`) on ``table`` (a
    :class:`MeasuredTable`; ``None`` for per-joint kinds), or as ``named`` says (its joints,
    name, parameters and story)."""
    story, labelled = {}, {}
    if named is not None:
        by_name = {j.joint: j for j in table.joints}
        joints = tuple(by_name[n] for n in named.joints)
        story = {"name": named.name, "text": named.text}
        labelled = {**story, "labels": named.labels}
    if kind == "encoder_harmonics":
        return EncoderHarmonics(*joints, **labelled)
    if kind == "wobble_harmonics":
        return WobbleHarmonics(*joints, **labelled)
    if kind == "backlash":
        return Backlash(joints, **labelled)
    if kind == "thermal_drift":
        return ThermalDrift(**story)
    if kind == "payload_mount":
        return PayloadMount(**story)
    # Keep the parameters the data determine; when none is, keep the whole effect, so that the
    # diagnosis says it is absorbed by the base errors (a base tilt by the first joint's tilts).
    if kind == "gravity_sag":
        kept = named.tied if named else _determined(table, GravityCompliance(table.rotation))
        return GravityCompliance(table.rotation, kept or COMPLIANCE_ENTRIES, **labelled)
    if kind == "base_tilt":
        kept = named.axes if named else [t[1] for t in _determined(table, BaseRotation())]
        return BaseRotation(kept or "xyz", **labelled)
    raise ValueError(f"no effect of kind '{kind}'")


def _determined(table: MeasuredTable, effect: Effect) -> tuple[str, ...]:
    """The parameters of ``effect`` orientation data determine beyond the base errors."""
    from scipy.linalg import qr

    rng = np.random.default_rng(0)  # generic positions: any random draw is generic
    variables = PositionVariables(rng.uniform(-np.pi, np.pi, (64, table.n_joints)))
    model = OrientationModel(variables, [effect], table)
    jac = model.jacobian(np.zeros(model.n_params)).reshape(-1, model.n_params)
    n_base = len(table.base_names)
    u, s, _ = np.linalg.svd(jac[:, :n_base], full_matrices=False)
    u = u[:, s > RANK_RTOL * s[0]]
    added = jac[:, n_base:]
    norms = np.linalg.norm(added, axis=0)
    live = np.flatnonzero(norms > 1e-12 * max(norms.max(initial=0.0), 1e-300))
    if not live.size:
        return ()
    extra = added[:, live] / norms[live]
    extra = extra - u @ (u.T @ extra)
    _, r, pivots = qr(extra, mode="economic", pivoting=True)
    # Columns have unit norm before the projection, so the threshold is absolute: what is left
    # of a column the base errors span is rounding (1e-16), not a new direction.
    rank = int(np.sum(np.abs(np.diag(r)) > RANK_RTOL))
    pivots = live[pivots]
    names = [spec.name for spec in effect.parameters(variables)]
    return tuple(sorted((names[p] for p in pivots[:rank]), key=names.index))


def resolve_effect(name: str, turntable=None, extra: Sequence[Effect] = ()) -> Effect:
    """The effect called ``name`` on a table: in ``extra`` (the caller's, first), the table's
    catalogue, or a per-joint ``<kind>@<joint>`` (the catalogue's effect of that kind on that
    joint alone, whatever the table names it, else a new one).

    Raises:
        InputError: an unknown name, listing the known ones.
    """
    table = measured_table(turntable)
    name = name.strip()
    known = (*extra, *catalogue(table))
    for effect in known:
        if effect.name == name:
            return effect
    kind, at, joint_name = name.partition("@")
    if at:
        joint = next((j for j in table.joints if j.joint == joint_name), None)
        if joint is None:
            raise InputError(
                f"unknown joint '{joint_name}' in effect '{name}'; this table's joints: "
                f"{', '.join(table.joint_names)}"
            )
        if kind in PER_JOINT_EFFECTS:
            same = (e for e in catalogue(table) if e.kind == kind and e.joints == (joint.joint,))
            return next(same, None) or joint_effect(kind, joint)
    raise InputError(
        f"unknown effect '{name}'; effects of this table: {', '.join(e.name for e in known)} "
        f"(and {_PER_JOINT_TEXT} for joints {', '.join(table.joint_names)})"
    )

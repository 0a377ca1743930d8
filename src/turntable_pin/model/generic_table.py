"""Any turntable from its URDF: a generic error model read off a serial chain of 1 to 3 revolute
joints with free names, axes and nominal origins.

The rule that places the errors (stated once, here):

- every joint ``J`` carries, after its nominal ``<origin>``, rotations about its axis ``a``
  (``J.position``) and about ``u`` then ``v`` perpendicular to it (``J.tilt_a``, ``J.tilt_b``:
  wobble or orthogonality), then translations along ``u`` and ``v`` (``J.offset_a``,
  ``J.offset_b``, metres: the axes missing each other);
- ``u`` is the joint frame's coordinate axis least aligned with ``a`` (x, y, z first on a tie),
  made perpendicular to ``a``; ``v = a x u``;
- the payload mount (the first fixed joint after the last revolute one, else the payload frame)
  carries rotations about its x, y and z axes (``M.rot_x``, ``M.rot_y``, ``M.rot_z``).

Angles are radians, offsets metres. Which combinations orientation data determine is found
numerically (:meth:`GenericTable.identifiable`); no combination is hard-coded. A table may bring
its own :class:`ErrorLayout` instead: the paper's table is this class given
``models/turntable.urdf`` and its Table 3 (:data:`~.paper_table.PAPER_LAYOUT`).
"""

# pinocchio and scipy are imported inside functions: import turntable_pin stays light
from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np

from ..core.exceptions import InputError, ModelError
from ..core.files import check_input_file
from ..core.resources import models_dir
from ..core.rotations import axis_rotation
from ..core.sizes import MAX_URDF_FILE_BYTES
from ..core.units import ARCSEC_PER_RAD, M_PER_MM
from ..core.words import argument
from .angles import ANGLE_ENTRIES
from .chain import (
    ROTATION,
    TRANSLATION,
    ErrorChain,
    apply_chain_errors,
    compose_rotation,
)
from .errors import MAX_ANGULAR_ERROR_DEG, parse_error_value, read_error_mapping
from .mount_declaration import read_mount_declaration, resolve_mount
from .named_effects import NamedEffect
from .urdf_io import write_error_urdf

__all__ = [
    "MAX_JOINTS",
    "ClosedForm",
    "ErrorLayout",
    "GenericTable",
    "Identifiable",
    "JOINT_ERROR_KINDS",
    "OrientationError",
    "generic_length_errors",
    "perpendicular_directions",
]

MAX_JOINTS = 3
"""Most revolute joints a table may have (one to three axes)."""

_REVOLUTE = ("JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned",
             "JointModelRUBX", "JointModelRUBY", "JointModelRUBZ",
             "JointModelRevoluteUnboundedUnaligned")  # fmt: skip


def perpendicular_directions(axis) -> tuple[np.ndarray, np.ndarray]:
    """``(u, v)``: unit directions perpendicular to ``axis`` by the module's stated rule."""
    a = np.asarray(axis, dtype=float).reshape(3)
    a = a / np.linalg.norm(a)
    k = int(np.argmin(np.abs(a)))  # argmin takes the first on a tie: x before y before z
    e = np.zeros(3)
    e[k] = 1.0
    u = e - (e @ a) * a
    u /= np.linalg.norm(u)
    return u, np.cross(a, u)


def _check_urdf_text(path: Path):
    """Refuse what Pinocchio would silently accept: mimic joints, prismatic/floating/planar;
    return the parsed ``<robot>`` element."""
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise ModelError(f"{path}: not a readable URDF (XML error: {exc})") from None
    for joint in root.iter("joint"):
        name, kind = joint.get("name"), joint.get("type")
        if joint.find("mimic") is not None:
            raise ModelError(f"{path}: joint '{name}' is a mimic joint; give every axis its own")
        if kind in ("prismatic", "floating", "planar"):
            raise ModelError(
                f"{path}: joint '{name}' is {kind}; a turntable has revolute (or continuous) "
                "joints and fixed ones only"
            )
    return root


def _payload_frame(model, path: Path, payload_frame: str | None) -> str:
    """The payload frame: the one given, or the only leaf body of the kinematic tree."""
    import pinocchio as pin

    bodies = [f for f in model.frames if f.type == pin.FrameType.BODY]
    if payload_frame is not None:
        if not model.existFrame(payload_frame):
            raise ModelError(
                f"{path}: no frame '{payload_frame}'; bodies are {[f.name for f in bodies]}"
            )
        return payload_frame
    parents = {model.frames[f.parentFrame].name for f in model.frames}
    leaves = [f.name for f in bodies if f.name not in parents]
    if len(leaves) != 1:
        raise ModelError(
            f"{path}: the payload frame is ambiguous ({len(leaves)} leaf bodies: "
            f"{', '.join(leaves)}); name it with {argument('payload_frame')}"
        )
    return leaves[0]


@dataclass(frozen=True)
class ClosedForm:
    """A table's first-order orientation error written out: ``label`` (``eq. 26``) and
    ``orientation_error_rad(error_values, angles_rad) -> (dpsi, dtheta, dgamma)``, radians."""

    label: str
    orientation_error_rad: Callable[[np.ndarray, Sequence[float]], np.ndarray]


@dataclass(frozen=True, eq=False)
class ErrorLayout:
    """Where a table's errors sit and what they are called: the table-specific part as data.
    The fields past ``joint_errors`` are optional (default: the generic rule).

    Attributes:
        factors: ``{placement: ((kind, axis, error name), ...)}``, the motions after each nominal
            ``<origin>``, in order (:class:`~turntable_pin.model.chain.ErrorChain`).
        names: every error, in the order of error vectors; descriptions: ``{error: words}``.
        joint_errors: ``{joint: (position error, tilt a, tilt b)}``, from the base.
        label: how reports name the table; title: how a sentence names it (``the paper's
            table``); payload_frame: the frame it is written for (``None``: any).
        angle_names: each joint's angle in keys and texts (``phi1``, ``phi2``; empty: the joints).
        first_order: the first-order model in closed form (``None``: the regressor).
        domains_deg: ``{psi|theta|gamma: {joint: (lo, hi)}}``, degrees: where the allocation
            bounds that angle (eqs. 31-33; otherwise whole turns).
        lower_bounds_file: the bundled manufacturing lower bounds (``None``: none).
        effects: the catalogue's effects under the table's names (:class:`NamedEffect`).
    """

    factors: Mapping[str, tuple[tuple, ...]]
    names: tuple[str, ...]
    descriptions: Mapping[str, str]
    joint_errors: Mapping[str, tuple[str, str, str]]
    label: str | None = None
    payload_frame: str | None = None
    title: str | None = None
    angle_names: tuple[str, ...] = ()
    first_order: ClosedForm | None = None
    domains_deg: Mapping[str, Mapping[str, tuple[float, float]]] = field(default_factory=dict)
    lower_bounds_file: str | None = None
    effects: tuple[NamedEffect, ...] = ()

    def fits(self, joint_names: Sequence[str], payload_frame: str) -> bool:
        """Whether the layout is written for a chain of these joints to this payload frame."""
        return tuple(joint_names) == tuple(self.joint_errors) and self.payload_frame in (
            None,
            payload_frame,
        )

    @property
    def length_names(self) -> tuple[str, ...]:
        """The errors that are lengths (translation factors, metres)."""
        lengths = {f[2] for fs in self.factors.values() for f in fs if f[0] == TRANSLATION}
        return tuple(n for n in self.names if n in lengths)

    @property
    def angular_names(self) -> tuple[str, ...]:
        """The errors that are angles (rotation factors, radians), in :attr:`names` order."""
        return tuple(n for n in self.names if n not in self.length_names)


JOINT_ERROR_KINDS: tuple[tuple[str, str], ...] = (
    ("position", ROTATION), ("tilt_a", ROTATION), ("tilt_b", ROTATION),
    ("offset_a", TRANSLATION), ("offset_b", TRANSLATION),
)  # fmt: skip
"""The errors every joint ``J`` carries by the module docstring's rule, in order: ``J.<name>``
and its kind (:data:`ROTATION`, radians, or :data:`TRANSLATION`, metres)."""


def generic_length_errors() -> tuple[str, ...]:
    """The lengths among a joint's errors, ``<joint>.offset_a``...: what a user gives in
    millimetres (:data:`JOINT_ERROR_KINDS`)."""
    return tuple(f"<joint>.{name}" for name, kind in JOINT_ERROR_KINDS if kind == TRANSLATION)


def generic_layout(chain: ErrorChain, mount: str) -> ErrorLayout:
    """The layout of the module docstring's rule for the joints of ``chain`` and payload mount
    ``mount``: per joint ``position``, ``tilt_a``, ``tilt_b``, ``offset_a``, ``offset_b``; then
    the mount's ``rot_x``, ``rot_y``, ``rot_z``."""
    factors: dict[str, tuple[tuple, ...]] = {}
    names: list[str] = []
    descriptions: dict[str, str] = {}
    joint_errors: dict[str, tuple[str, str, str]] = {}
    for link in chain.joints:
        a = link.axis / np.linalg.norm(link.axis)
        u, v = perpendicular_directions(a)
        j = link.name
        axes_texts = (
            (a, f"position error of {j} (about its axis)"),
            (u, f"tilt of {j}'s axis about u = {_vec(u)}"),
            (v, f"tilt of {j}'s axis about v = {_vec(v)}"),
            (u, f"offset of {j}'s axis along u (m)"),
            (v, f"offset of {j}'s axis along v (m)"),
        )
        entries = [
            (kind, axis, short, text)
            for (short, kind), (axis, text) in zip(JOINT_ERROR_KINDS, axes_texts, strict=True)
        ]
        factors[j] = tuple((kind, tuple(axis), f"{j}.{short}") for kind, axis, short, _ in entries)
        for _, _, short, text in entries:
            names.append(f"{j}.{short}")
            descriptions[f"{j}.{short}"] = text
        joint_errors[j] = (f"{j}.position", f"{j}.tilt_a", f"{j}.tilt_b")
    factors[mount] = tuple((ROTATION, ax, f"{mount}.rot_{ax}") for ax in ("x", "y", "z"))
    for ax in ("x", "y", "z"):
        names.append(f"{mount}.rot_{ax}")
        descriptions[f"{mount}.rot_{ax}"] = f"payload mount rotation about its {ax} axis"
    return ErrorLayout(factors, tuple(names), descriptions, joint_errors)


@dataclass(frozen=True)
class OrientationError:
    """The orientation error of the payload at one position: ``dR = Rd^T Rt`` (eq. 23), its
    angles ``dR[0,2]``, ``dR[1,0]``, ``dR[2,1]`` (eq. 24, radians) and the payload origin in the
    base frame, metres (zero for a perfect table)."""

    dR: np.ndarray
    dpsi_rad: float
    dtheta_rad: float
    dgamma_rad: float
    payload_origin_m: np.ndarray


@dataclass(frozen=True)
class Identifiable:
    """What orientation data on generic positions determine: ``base`` (the parameters QR with
    column pivoting picks, one per determined combination), the determined ``combinations`` and
    ``undetermined`` flat directions in words, ``no_effect`` (parameters that never turn)."""

    base: tuple[str, ...]
    combinations: tuple[str, ...]
    undetermined: tuple[str, ...]
    no_effect: tuple[str, ...]


class GenericTable:
    """The error model of a URDF turntable (the module docstring's rule, or ``layout``).

    Args:
        urdf_path: the nominal URDF; payload_frame: default the only leaf of the chain.
        telescope_mount: ``"altaz"``, ``"equatorial"`` or ``"none"``, overriding the URDF's
            declaration (:mod:`.mount_declaration`; ``None``: as declared).

    Attributes:
        urdf_path, payload_frame: as given (the payload frame resolved).
        nominal_pin_model: the Pinocchio model without errors (its ``Data``:
            :attr:`nominal_pin_data`); chain (:class:`ErrorChain`), layout.
        declared_mount, telescope_mount: what the URDF declares, what the table is.
        parameter_names: the layout's names (generic: ``<joint>.position``, ``.tilt_a``,
            ``.tilt_b``, ``.offset_a``, ``.offset_b`` per joint, then ``<mount>.rot_x/y/z``).
    """

    def __init__(
        self,
        urdf_path: str | Path,
        payload_frame: str | None = None,
        layout: ErrorLayout | None = None,
        telescope_mount: str | None = None,
    ) -> None:
        import pinocchio as pin

        path = Path(urdf_path)
        if not path.exists():
            raise InputError("no such URDF file", path=path)
        check_input_file(path, "URDF", MAX_URDF_FILE_BYTES)
        root = _check_urdf_text(path)
        self.declared_mount = read_mount_declaration(root, path)
        self.telescope_mount = resolve_mount(self.declared_mount, telescope_mount)
        try:
            model = pin.buildModelFromUrdf(str(path))
        except (RuntimeError, ValueError) as exc:
            raise ModelError(f"{path}: Pinocchio cannot read this URDF: {exc}") from None
        if payload_frame is None and layout is not None:
            payload_frame = layout.payload_frame
        frame = _payload_frame(model, path, payload_frame)
        chain_joints = []
        jid = model.frames[model.getFrameId(frame)].parentJoint
        while jid > 0:
            chain_joints.append(jid)
            jid = model.parents[jid]
        off_chain = sorted(set(range(1, model.njoints)) - set(chain_joints))
        if off_chain:
            names = ", ".join(model.names[j] for j in off_chain)
            raise ModelError(
                f"{path}: not a serial chain to '{frame}': joint(s) {names} are not on the way "
                "from the root to the payload"
            )
        for j in chain_joints:
            if model.joints[j].shortname() not in _REVOLUTE:
                raise ModelError(
                    f"{path}: joint '{model.names[j]}' is {model.joints[j].shortname()}, not "
                    "revolute"
                )
        if not 1 <= len(chain_joints) <= MAX_JOINTS:
            raise ModelError(
                f"{path}: {len(chain_joints)} revolute joints on the chain to '{frame}'; a "
                f"turntable has 1 to {MAX_JOINTS}"
            )
        self.urdf_path = path
        self.payload_frame = frame
        self.nominal_pin_model = model
        probe = ErrorChain.from_pinocchio(model, frame, {}, ())
        self.mount = next((link.name for link in probe.links if not link.is_joint), frame)
        if layout is None:
            layout = generic_layout(probe, self.mount)
        elif tuple(layout.joint_errors) != probe.joint_names:
            raise ModelError(
                f"{path}: the error layout is written for joints "
                f"{', '.join(layout.joint_errors)}; this URDF's chain to '{frame}' has "
                f"{', '.join(probe.joint_names)}"
            )
        self.layout = layout
        self.parameter_names = layout.names
        self.descriptions = dict(layout.descriptions)
        self.chain = ErrorChain.from_pinocchio(model, frame, layout.factors, layout.names)
        self._pinocchio: dict[bytes, tuple] = {}

    # ---- values ---------------------------------------------------------------------------
    @property
    def joint_names(self) -> tuple[str, ...]:
        """The revolute joints from the base (the order of the angles everywhere)."""
        return self.chain.joint_names

    def values(self, errors: Mapping[str, float] | None = None) -> np.ndarray:
        """The error vector (rad, m) in :attr:`parameter_names` order from ``{name: value}``."""
        out = np.zeros(len(self.parameter_names))
        for name, value in (errors or {}).items():
            if name not in self.chain.error_names:
                raise InputError(
                    f"unknown error '{name}' for this table; its errors: "
                    f"{', '.join(self.parameter_names)}"
                )
            out[self.parameter_names.index(name)] = float(value)
        return out

    @property
    def length_names(self) -> tuple[str, ...]:
        """The parameters that are lengths (translation errors: offsets, metres)."""
        return self.layout.length_names

    @property
    def angular_names(self) -> tuple[str, ...]:
        """The parameters that are angles (rotation errors, radians)."""
        return self.layout.angular_names

    @property
    def label(self) -> str:
        """How reports name the table: the layout's label (``paper``) or the URDF file."""
        return self.layout.label or str(self.urdf_path)

    @property
    def title(self) -> str:
        """How a sentence names the table: the layout's title (``the paper's table``) or the
        URDF file's name."""
        return self.layout.title or self.urdf_path.name

    @property
    def angle_names(self) -> tuple[str, ...]:
        """The name of each joint's angle in keys and texts, chain order: the layout's
        (``phi1``, ``phi2``) or the joint names."""
        return tuple(self.layout.angle_names) or self.joint_names

    @property
    def first_order_label(self) -> str:
        """How texts cite the first-order model: the layout's closed form (``eq. 26``) or
        ``first order``."""
        return self.layout.first_order.label if self.layout.first_order else "first order"

    def first_order_error_rad(self, error_values, angles_rad: Sequence[float]) -> np.ndarray:
        """``(dpsi, dtheta, dgamma)`` of the first-order model at one position, radians: the
        layout's closed form (exact zeros where it has them), else the regressor times the
        errors (the same numbers to rounding)."""
        values = np.asarray(error_values, dtype=float)
        angles = [float(a) for a in self._angles(angles_rad)]
        if self.layout.first_order is not None:
            return np.asarray(self.layout.first_order.orientation_error_rad(values, angles))
        return self.regressor([np.array([a]) for a in angles])[0] @ values

    def angle_domains_rad(self, angle: str) -> dict[str, tuple[float, float]]:
        """``{joint: (lo, hi)}``, radians: where the allocation bounds ``angle`` (psi, theta,
        gamma), as the layout gives them; the joints not named turn whole."""
        given = self.layout.domains_deg.get(angle, {})
        return {j: (math.radians(lo), math.radians(hi)) for j, (lo, hi) in given.items()}

    @property
    def lower_bounds_path(self) -> Path | None:
        """The bundled file of the table's manufacturing lower bounds (``None``: none)."""
        if self.layout.lower_bounds_file is None:
            return None
        return models_dir() / self.layout.lower_bounds_file

    def errors_from_user_units(
        self, entries: Mapping[str, object], *, max_angle_deg: float | None = None
    ) -> np.ndarray:
        """The error vector from ``{name[_unit]: value}`` in user units
        (:func:`~turntable_pin.model.errors.parse_error_value`; angles up to ``max_angle_deg``,
        degrees, default ``MAX_ANGULAR_ERROR_DEG``)."""
        if max_angle_deg is None:
            max_angle_deg = MAX_ANGULAR_ERROR_DEG

        out = np.zeros(len(self.parameter_names))
        given: set[str] = set()
        for key, value in entries.items():
            name, si_value = parse_error_value(
                str(key), value, names=self.parameter_names, length_names=self.length_names,
                max_angle_deg=max_angle_deg,
            )  # fmt: skip
            if name in given:
                raise InputError(f"error '{name}' is given twice")
            given.add(name)
            out[self.parameter_names.index(name)] = si_value
        return out

    def errors_from_yaml(
        self, path: str | Path, *, max_angle_deg: float | None = None
    ) -> np.ndarray:
        """:meth:`errors_from_user_units` of a YAML file (optionally under ``errors:``)."""
        try:
            return self.errors_from_user_units(
                read_error_mapping(path), max_angle_deg=max_angle_deg
            )
        except InputError as exc:
            if exc.path is not None:
                raise
            raise InputError(exc.detail, path=Path(path)) from None

    def to_user_units(self, error_values) -> dict[str, float]:
        """``{name_arcsec: value, ..., <joint>.offset_a_mm: value}``: what
        :meth:`errors_from_user_units` reads."""
        out = {}
        for name, value in zip(self.parameter_names, np.asarray(error_values), strict=True):
            if name in self.length_names:
                out[f"{name}_mm"] = float(value) / M_PER_MM
            else:
                out[f"{name}_arcsec"] = float(value) * ARCSEC_PER_RAD
        return out

    def payload_pose(self, error_values, angles_rad: Sequence[float]):
        """The payload pose (a ``pinocchio.SE3``, base frame) at joint angles (chain order,
        radians), these errors in the placements (``None``: the ideal pose)."""
        import pinocchio as pin

        key = b"" if error_values is None else np.asarray(error_values, float).tobytes()
        cached = self._pinocchio.get(key)
        if cached is None:
            if len(self._pinocchio) >= 8:  # a few error sets in use at a time
                self._pinocchio.pop(next(iter(self._pinocchio)))
            model = self.nominal_pin_model if not key else self.pinocchio_model(error_values)
            frame_id = model.getFrameId(self.payload_frame)
            cached = self._pinocchio[key] = (model, model.createData(), frame_id)
        model, data, frame_id = cached
        pin.framesForwardKinematics(model, data, self.chain.joint_vector(*angles_rad))
        return data.oMf[frame_id].copy()

    def payload_origin_m(self, error_values, angles_rad: Sequence[float]) -> np.ndarray:
        """The payload origin in the base frame with these errors (Pinocchio), metres."""
        return np.array(self.payload_pose(error_values, angles_rad).translation)

    def orientation_error(self, error_values, angles_rad: Sequence[float]) -> OrientationError:
        """``dR = Rd^T Rt`` and the three error angles at joint angles (chain order, radians),
        by Pinocchio forward kinematics of the nominal model and the model with errors."""
        for value in angles_rad:
            if not np.isfinite(value):
                raise InputError(f"rotation angles must be finite numbers, got {value!r}")
        actual = self.payload_pose(error_values, angles_rad)
        dR = self.payload_pose(None, angles_rad).rotation.T @ actual.rotation
        dpsi, dtheta, dgamma = (float(dR[i, j]) for i, j in ANGLE_ENTRIES)
        return OrientationError(dR, dpsi, dtheta, dgamma, np.array(actual.translation))

    def _angles(self, angles_rad: Sequence) -> list[np.ndarray]:
        if len(angles_rad) != len(self.joint_names):
            raise InputError(
                f"expected {len(self.joint_names)} joint angle(s) ({', '.join(self.joint_names)})"
                f", got {len(angles_rad)}"
            )
        return [np.asarray(a, dtype=float) for a in angles_rad]

    def rotation_error(self, error_values, angles_rad: Sequence) -> np.ndarray:
        """``dR = Rd^T Rt`` at joint angles (chain order, broadcast), shape S + (3, 3)."""
        q = self._angles(angles_rad)
        rt = compose_rotation(self.chain.placements(np.asarray(error_values, float)), q)
        rd = compose_rotation(self.chain.placements(), q)
        return np.swapaxes(rd, -1, -2) @ rt

    @cached_property
    def nominal_pin_data(self) -> object:
        """Pinocchio's ``Data`` of :attr:`nominal_pin_model` (made on first use, one per table):
        with the model, what ``pinocchio.forwardKinematics`` and the rest take."""
        return self.nominal_pin_model.createData()

    def pinocchio_model(self, error_values) -> object:
        """A Pinocchio model of the table with these errors in its placements."""
        model = self.nominal_pin_model.copy()
        apply_chain_errors(self.chain, self.nominal_pin_model, model, error_values)
        return model

    def write_urdf(self, error_values, path: str | Path) -> Path:
        """Write the URDF with these errors in its joint ``<origin>``s (for plain Pinocchio)."""
        return write_error_urdf(self.urdf_path, self.chain, np.asarray(error_values, float), path)

    # ---- what orientation data determine ---------------------------------------------------
    def regressor(self, angles_rad: Sequence, error_values=None) -> np.ndarray:
        """d(dpsi, dtheta, dgamma)/d(errors), (N, 3, P), exact (analytic): at zero errors (the
        first-order model) or, given ``error_values`` (P,), of the exact chain at those errors."""
        q = [np.atleast_1d(a) for a in self._angles(angles_rad)]
        n = np.broadcast_shapes(*(a.shape for a in q))[0]
        values = None if error_values is None else np.asarray(error_values, dtype=float)
        dR = None if values is None else self.rotation_error(values, q)
        out = np.zeros((n, 3, len(self.parameter_names)))
        # Rt = P R_u(e) S: d(Rd^T Rt)/de = dR [S^T u]x, S the rotations after the factor (walked
        # from the payload back, so that a rotation before the factor never enters).
        suffix = np.broadcast_to(np.eye(3), (n, 3, 3))
        qi = len(q)
        for link in reversed(self.chain.links):
            if link.is_joint:
                qi -= 1
                suffix = axis_rotation(link.axis, q[qi]) @ suffix
            for factor in reversed(link.factors):
                if factor.kind != ROTATION:
                    continue
                col = self.parameter_names.index(factor.error)
                w = np.swapaxes(suffix, -1, -2) @ factor.unit  # (N, 3)
                d = np.swapaxes(np.cross(w[:, None, :], np.eye(3)), -1, -2)  # [w]x
                if dR is not None:
                    d = dR @ d
                    suffix = axis_rotation(factor.axis, values[col]) @ suffix
                out[:, :, col] = np.stack([d[:, i, j] for i, j in ANGLE_ENTRIES], axis=1)
            suffix = link.nominal[:3, :3] @ suffix
        return out

    @cached_property
    def identifiable(self) -> Identifiable:
        """What orientation data on generic positions determine (QR with column pivoting)."""
        from scipy.linalg import qr

        from ..stats.least_squares import RANK_RTOL, analyse_identifiability, combination_name

        rng = np.random.default_rng(0)  # generic positions: any random draw is generic
        angles = [rng.uniform(-np.pi, np.pi, 64) for _ in self.joint_names]
        jac = self.regressor(angles).reshape(-1, len(self.parameter_names))
        norms = np.linalg.norm(jac, axis=0)
        no_effect = tuple(n for n, s in zip(self.parameter_names, norms, strict=True) if s < 1e-12)
        live = np.flatnonzero(norms >= 1e-12)
        _, r, pivots = qr(jac[:, live] / norms[live], mode="economic", pivoting=True)
        diag = np.abs(np.diag(r))
        rank = int(np.sum(diag > RANK_RTOL * diag[0]))
        base = tuple(self.parameter_names[live[p]] for p in pivots[:rank])
        names = tuple(self.parameter_names[i] for i in live)
        ident = analyse_identifiability(jac[:, live], names)
        return Identifiable(
            base=base,
            combinations=tuple(combination_name(c, names) for c in ident.determined),
            undetermined=tuple(combination_name(c, names) for c in ident.undetermined),
            no_effect=no_effect,
        )


def _vec(v: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:.3g}" for x in np.where(np.abs(v) < 1e-12, 0.0, v)) + ")"

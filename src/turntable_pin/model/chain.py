"""The error chain: the one description of a turntable's kinematic chain with its error factors.

A turntable is a serial chain from the base to the payload frame. Each *link* of the chain is a
placement (the nominal URDF ``<origin>``, read off the Pinocchio model) followed by the link's
*error factors* (elementary rotations and translations by error parameters, applied in the moving
frame) and, for a joint, the joint's own rotation about its axis::

    Rt(q) = prod_links  N_link E_link(errors) R_axis(q_link)        (R = I for a fixed link)

Every consumer reads this one object (Pinocchio's placements, the URDF writer, the batch field,
the fit's exact Jacobians, the sensitivities); the factor table, with its names, comes from the
caller.
"""

# pinocchio is imported inside functions: import turntable_pin stays light
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from ..core.exceptions import InputError, ModelError
from ..core.rotations import AXIS_INDEX, axis_rotation

__all__ = [
    "ROTATION",
    "TRANSLATION",
    "ChainLink",
    "ErrorChain",
    "ErrorFactor",
    "apply_chain_errors",
    "joint_axis",
    "skew",
    "unit_vector",
]

ROTATION = "rot"
"""Kind of an error factor that rotates about a coordinate axis of the moving frame."""

TRANSLATION = "trans"
"""Kind of an error factor that translates along a coordinate axis of the moving frame."""


@dataclass(frozen=True)
class ErrorFactor:
    """One elementary motion by an error parameter: ``kind`` (:data:`ROTATION`, radians, or
    :data:`TRANSLATION`, metres) about/along ``axis`` (``"x"``, ``"y"``, ``"z"`` of the moving
    frame, or a unit 3-vector in it) by the parameter ``error``."""

    kind: str
    axis: str | tuple[float, float, float]
    error: str

    @property
    def unit(self) -> np.ndarray:
        """The axis as a unit 3-vector of the moving frame."""
        return unit_vector(self.axis)


@dataclass(frozen=True)
class ChainLink:
    """One link of the chain.

    Attributes:
        name: the joint's (revolute, or fixed and folded into a frame) or the payload frame's.
        nominal: 4x4 placement relative to the previous link's frame (read-only).
        factors: the error factors applied after ``nominal``, in order.
        axis: unit rotation axis of a revolute joint in its own frame (``None``: fixed).
        q_index: the joint's index in Pinocchio's q (-1 when fixed); unbounded: a continuous
            joint (Pinocchio holds ``(cos q, sin q)`` there).
        limits_rad: ``(lower, upper)`` of a joint whose URDF ``<limit>`` spans less than a full
            turn, radians; else ``None``.
    """

    name: str
    nominal: np.ndarray
    factors: tuple[ErrorFactor, ...]
    axis: np.ndarray | None
    q_index: int = -1
    unbounded: bool = False
    limits_rad: tuple[float, float] | None = None

    @property
    def is_joint(self) -> bool:
        """Whether the link rotates with a joint value."""
        return self.axis is not None


def unit_vector(axis) -> np.ndarray:
    """``"x"``, ``"y"``, ``"z"`` or a 3-vector, as a unit 3-vector."""
    if isinstance(axis, str):
        out = np.zeros(3)
        out[AXIS_INDEX[axis]] = 1.0
        return out
    out = np.asarray(axis, dtype=float).reshape(3)
    return out / np.linalg.norm(out)


def skew(vector) -> np.ndarray:
    """The cross-product matrix ``[v]x`` of a 3-vector (the generator of rotations about it)."""
    x, y, z = np.asarray(vector, dtype=float).reshape(3)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def joint_axis(model, joint_id: int) -> np.ndarray:
    """Unit rotation axis of a revolute joint of the Pinocchio ``model``, in the joint frame,
    read off its motion subspace (every revolute type has one; not all have an ``axis``)."""
    import pinocchio as pin

    joint = model.joints[joint_id]
    short = joint.shortname()
    data = joint.createData()
    joint.calc(data, pin.neutral(model))
    subspace = data.S
    subspace = np.asarray(subspace.matrix() if hasattr(subspace, "matrix") else subspace, float)
    if subspace.size == 6:
        subspace = subspace.reshape(6, 1)
    # A revolute joint moves along one twist with no linear part (a helical one has both).
    if subspace.shape != (6, 1) or np.linalg.norm(subspace[:3]) > 1e-12:
        raise ModelError(f"joint '{model.names[joint_id]}' is {short}, not a revolute joint")
    axis = subspace[3:, 0]
    return axis / np.linalg.norm(axis)


def _limits(model, joint_id: int) -> tuple[float, float] | None:
    """``(lower, upper)`` of a bounded revolute joint turning less than a full turn, radians,
    else ``None`` (continuous joints, full-turn limits)."""
    joint = model.joints[joint_id]
    if joint.nq != 1:
        return None
    lower = float(model.lowerPositionLimit[joint.idx_q])
    upper = float(model.upperPositionLimit[joint.idx_q])
    if not (np.isfinite(lower) and np.isfinite(upper)) or upper - lower >= 2 * np.pi - 1e-9:
        return None
    return lower, upper


def _readonly(array: np.ndarray) -> np.ndarray:
    out = np.array(array, dtype=float)
    out.setflags(write=False)
    return out


def _frame_path(model, frame_id: int) -> list[int]:
    """Frame ids after the payload's parent joint frame, down to ``frame_id`` (inclusive)."""
    import pinocchio as pin

    path = [frame_id]
    while True:
        parent = model.frames[path[-1]].parentFrame
        if parent == path[-1] or model.frames[parent].type == pin.FrameType.JOINT:
            return path[::-1]
        if model.frames[parent].parentJoint != model.frames[frame_id].parentJoint:
            return path[::-1]
        path.append(parent)


class ErrorChain:
    """The serial chain from the base to a payload frame, with error factors (build it with
    :meth:`from_pinocchio`): ``links`` from the base, ``error_names`` (the order of the value
    arrays), ``nq`` (Pinocchio's q size), ``frame_path`` (the frames after the last joint, whose
    placements change with the fixed links' errors)."""

    def __init__(
        self,
        links: Sequence[ChainLink],
        error_names: Sequence[str],
        nq: int,
        frame_path: Sequence[str] = (),
    ) -> None:
        self.links = tuple(links)
        self.frame_path = tuple(frame_path)
        self.error_names = tuple(error_names)
        self.nq = int(nq)
        self._index = {name: i for i, name in enumerate(self.error_names)}
        for link in self.links:
            for factor in link.factors:
                if factor.error not in self._index:
                    raise ModelError(f"link '{link.name}': unknown error '{factor.error}'")

    # ---- construction -------------------------------------------------------------------------
    @classmethod
    def from_pinocchio(
        cls,
        model,
        payload_frame: str,
        factors: Mapping[str, Sequence[tuple[str, str, str]]],
        error_names: Sequence[str],
    ) -> ErrorChain:
        """Read the chain ending at ``payload_frame`` off the nominal Pinocchio ``model``, with
        ``factors`` ``{joint or fixed-joint name: ((kind, axis, error name), ...)}``.

        Joints are read from the root to the payload frame's parent joint; the fixed joints
        Pinocchio folded into frames after it become fixed links, and the payload frame closes it.
        """
        import pinocchio as pin

        if not model.existFrame(payload_frame):
            raise ModelError(
                f"no frame '{payload_frame}'; frames are {[f.name for f in model.frames]}"
            )
        frame_id = model.getFrameId(payload_frame)
        joints = []
        jid = model.frames[frame_id].parentJoint
        while jid > 0:
            joints.append(jid)
            jid = model.parents[jid]
        links = []
        for jid in joints[::-1]:
            name = model.names[jid]
            links.append(
                ChainLink(
                    name,
                    _readonly(model.jointPlacements[jid].homogeneous),
                    tuple(ErrorFactor(*f) for f in factors.get(name, ())),
                    _readonly(joint_axis(model, jid)),
                    model.joints[jid].idx_q,
                    model.joints[jid].nq == 2,
                    _limits(model, jid),
                )
            )
        previous = np.eye(4)  # frame placements are relative to the parent joint's frame
        path = _frame_path(model, frame_id)
        for fid in path:
            frame = model.frames[fid]
            if fid != frame_id and frame.type != pin.FrameType.FIXED_JOINT:
                continue  # a body frame sits where its fixed joint is: no placement of its own
            placement = frame.placement.homogeneous
            links.append(
                ChainLink(
                    frame.name,
                    _readonly(np.linalg.solve(previous, placement)),
                    tuple(ErrorFactor(*f) for f in factors.get(frame.name, ())),
                    None,
                )
            )
            previous = placement
        known = {link.name for link in links}
        for name in factors:
            if name not in known:
                raise ModelError(
                    f"error factors for '{name}', which is not on the chain to "
                    f"'{payload_frame}' ({', '.join(link.name for link in links)})"
                )
        return cls(links, error_names, model.nq, [model.frames[f].name for f in path])

    # ---- names and vectors --------------------------------------------------------------------
    @property
    def joints(self) -> tuple[ChainLink, ...]:
        """The joint links, from the base."""
        return tuple(link for link in self.links if link.is_joint)

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Names of the joints, from the base (the order of the angles everywhere)."""
        return tuple(link.name for link in self.joints)

    def link(self, name: str) -> ChainLink:
        """The link ``name``."""
        for link in self.links:
            if link.name == name:
                return link
        raise KeyError(name)

    def joint_vector(self, *angles_rad: float) -> np.ndarray:
        """Pinocchio's configuration vector q for joint angles in chain order, radians."""
        joints = self.joints
        if len(angles_rad) != len(joints):
            raise InputError(f"expected {len(joints)} joint angles, got {len(angles_rad)}")
        q = np.zeros(self.nq)
        for link, value in zip(joints, angles_rad, strict=True):
            if link.unbounded:
                q[link.q_index : link.q_index + 2] = np.cos(value), np.sin(value)
            else:
                q[link.q_index] = value
        return q

    # ---- error transforms ---------------------------------------------------------------------
    def error_transforms(self, error_values: np.ndarray) -> dict[str, np.ndarray]:
        """``{link name: (..., 4, 4)}``: each link's factors multiplied in order (the nominal
        placement comes before them), for ``error_values`` (..., E) in :attr:`error_names` order."""
        values = np.asarray(error_values, dtype=float)
        if values.shape[-1] != len(self.error_names):
            raise ValueError(
                f"expected {len(self.error_names)} error values, got shape {values.shape}"
            )
        lead = values.shape[:-1]
        out = {}
        for link in self.links:
            if not link.factors:
                continue
            total = np.broadcast_to(np.eye(4), lead + (4, 4)).copy()
            for factor in link.factors:
                value = values[..., self._index[factor.error]]
                step = np.broadcast_to(np.eye(4), lead + (4, 4)).copy()
                if factor.kind == ROTATION:
                    step[..., :3, :3] = axis_rotation(factor.axis, value)
                elif isinstance(factor.axis, str):
                    step[..., AXIS_INDEX[factor.axis], 3] = value
                else:
                    step[..., :3, 3] = value[..., None] * factor.unit
                total = total @ step
            out[link.name] = total
        return out

    def placements(self, error_values: np.ndarray | None = None) -> list[tuple[np.ndarray, object]]:
        """``[(placement (..., 4, 4), joint axis or None), ...]`` of every link with its errors.

        ``error_values`` of shape (..., E) (``None``: the nominal chain, each placement (4, 4)).
        """
        if error_values is None:
            return [(link.nominal, link.axis) for link in self.links]
        transforms = self.error_transforms(error_values)
        out = []
        for link in self.links:
            if link.name in transforms:
                out.append((link.nominal @ transforms[link.name], link.axis))
            else:
                lead = np.asarray(error_values).shape[:-1]
                out.append((np.broadcast_to(link.nominal, lead + (4, 4)), link.axis))
        return out


def apply_chain_errors(chain: ErrorChain, nominal, model, error_values: np.ndarray) -> None:
    """Write ``chain``'s error transforms into ``model``, a copy of the Pinocchio model
    ``nominal`` it was read off: joint placements become ``nominal * E``; the frames of the fixed
    joints (relative to the last joint) are composed again in chain order with their errors."""
    import pinocchio as pin

    def _se3(homogeneous: np.ndarray):
        return pin.SE3(np.array(homogeneous[:3, :3]), np.array(homogeneous[:3, 3]))

    transforms = chain.error_transforms(np.asarray(error_values, dtype=float))
    for link in chain.joints:
        if link.name in transforms:
            jid = model.getJointId(link.name)
            model.jointPlacements[jid] = nominal.jointPlacements[jid] * _se3(transforms[link.name])
    actual, previous = pin.SE3.Identity(), pin.SE3.Identity()
    for name in chain.frame_path:
        fid = model.getFrameId(name)
        placement = nominal.frames[fid].placement
        actual = actual * previous.actInv(placement)
        if name in transforms:
            actual = actual * _se3(transforms[name])
        model.frames[fid].placement = actual
        previous = placement


def compose_rotation(chain: Sequence[tuple[np.ndarray, object]], q_rad: Sequence) -> np.ndarray:
    """Rotation of a placement chain (:meth:`ErrorChain.placements`) at joint values ``q_rad``
    (one value or array per joint; broadcast over leading dims)."""
    result = None
    qi = 0
    for placement, axis in chain:
        rot = np.asarray(placement)[..., :3, :3]
        result = rot if result is None else result @ rot
        if axis is not None:
            result = result @ axis_rotation(axis, q_rad[qi])
            qi += 1
    return result


__all__ += ["compose_rotation"]

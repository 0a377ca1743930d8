"""The turntable as the measurement layer sees it: its error chain, base errors, joints, effects.

One class, :class:`MeasuredTable`, serves the paper's table and any URDF table alike; the paper's
table is the same model under the names of its Table 2 and of its effects (its layout,
``model/paper_table.py``).

- The *base errors* are the chain's rotation errors (offsets move the payload, never turn it).
- Each joint has a *position error* and two *tilts* (generic: ``<joint>.position``,
  ``.tilt_a``, ``.tilt_b``; the paper: ``dphi_y1, dalpha_x1, dalpha_z1`` for ``outer_axis`` and
  ``dphi_z2, dalpha_x2, dalpha_y2`` for ``inner_axis``).

Its candidate effects are in :mod:`turntable_pin.measurement.catalogue`.
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..model.chain import ROTATION, ErrorChain, compose_rotation
from ..model.paper_table import resolve_table

__all__ = ["JointErrors", "MeasuredTable", "measured_table"]


@dataclass(frozen=True)
class JointErrors:
    """One joint's errors in the table's names.

    Attributes:
        joint: the joint's name; index: its place from the base (1 = ``phi1``);
        position: its position error; tilts: its two tilt (wobble) errors.
    """

    joint: str
    index: int
    position: str
    tilts: tuple[str, str]


class MeasuredTable:
    """A turntable for fitting and diagnosing orientation data.

    Args:
        chain: the table's error chain (nominal placements, joint axes, error factors).
        joints: each joint's errors, from the base.
        descriptions: ``{base error: what it is}``.
        label: how reports name the table (``paper`` or the URDF file).
        title: how a sentence names the table (``the paper's table``, or the URDF file's name).
        named_effects: the catalogue's effects under the table's own names (its layout's
            :class:`~turntable_pin.model.named_effects.NamedEffect`; none: the generic names).
        angle_names: the layout's name of each joint's angle (the paper's ``phi1``, ``phi2``;
            none: its data files name the joints).
        urdf_path: the nominal URDF the chain was read from.
        telescope_mount: the telescope mount kind the table is (``"altaz"``, ``"equatorial"``;
            ``None``: a turntable), as declared (``model/mount_declaration.py``), never guessed.
        declared_mount: the kind its URDF declares (``None``: none), which ``telescope_mount``
            may override.
    """

    def __init__(
        self,
        chain: ErrorChain,
        joints: Sequence[JointErrors],
        descriptions: dict[str, str],
        *,
        label: str,
        title: str = "",
        named_effects: Sequence = (),
        angle_names: Sequence[str] = (),
        urdf_path=None,
        telescope_mount: str | None = None,
        declared_mount: str | None = None,
    ) -> None:
        self.chain = chain
        self.urdf_path = urdf_path
        self.telescope_mount = telescope_mount
        self.declared_mount = declared_mount
        self.joints = tuple(joints)
        self.descriptions = dict(descriptions)
        self.label = label
        self.title = title or label
        self.named_effects = tuple(named_effects)
        self.angle_names = tuple(angle_names)
        rotations = [f.error for link in chain.links for f in link.factors if f.kind == ROTATION]
        self.base_names = tuple(n for n in chain.error_names if n in rotations)

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The revolute joints from the base."""
        return tuple(j.joint for j in self.joints)

    @property
    def n_joints(self) -> int:
        """Number of revolute joints."""
        return len(self.joints)

    def rotation(self, joint_rad: np.ndarray) -> np.ndarray:
        """The nominal payload orientation ``Rd`` at joint angles (N, J), (N, 3, 3)."""
        q = [np.asarray(joint_rad, dtype=float)[:, k] for k in range(self.n_joints)]
        return compose_rotation(self.chain.placements(), q)

    @property
    def joint_limits_rad(self) -> tuple[tuple[float, float] | None, ...]:
        """Each joint's ``(lower, upper)`` when its URDF limits span less than a full turn,
        radians, else ``None`` (see :class:`~turntable_pin.model.chain.ChainLink`)."""
        return tuple(link.limits_rad for link in self.chain.joints)

    @property
    def data_joint_names(self) -> tuple[str, ...]:
        """The joints its data files and results name: none when its layout names the angles
        (the paper's ``phi1_deg, phi2_deg``), else its joints (``phiK_deg`` or ``<joint>_deg``)."""
        return () if self.angle_names else self.joint_names

    def angle_label(self, k: int) -> str:
        """``phiK``, the name of joint K's angle in data files and reports."""
        return f"phi{k}"


_MEASURED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
"""The :class:`MeasuredTable` of each table in use (built once per table; gone with it)."""


def measured_table(turntable=None) -> MeasuredTable:
    """The :class:`MeasuredTable` of ``turntable``: ``None`` (the bundled paper table), a
    :class:`~turntable_pin.model.generic_table.GenericTable` (in its layout's names: the paper's
    on the paper's table) or a :class:`MeasuredTable` (returned as it is)."""
    if isinstance(turntable, MeasuredTable):
        return turntable
    table = resolve_table(turntable)
    cached = _MEASURED.get(table)
    if cached is None:
        joints = [
            JointErrors(name, k, errors[0], tuple(errors[1:]))
            for k, (name, errors) in enumerate(table.layout.joint_errors.items(), start=1)
        ]
        cached = _MEASURED[table] = MeasuredTable(
            table.chain, joints, table.descriptions, label=table.label, title=table.title,
            named_effects=table.layout.effects, angle_names=table.layout.angle_names,
            urdf_path=table.urdf_path,
            telescope_mount=table.telescope_mount, declared_mount=table.declared_mount,
        )  # fmt: skip
    return cached

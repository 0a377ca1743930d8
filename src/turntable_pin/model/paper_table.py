"""The paper's two-axis table as data: its joint and frame names and the Table 3 error factors.

The bundled ``models/turntable.urdf`` names its joints ``outer_axis`` (phi1, about y) and
``inner_axis`` (phi2, about z), the fixed ``payload_mount`` and the payload frame ``gyrowheel``;
:data:`PLACEMENT_ERROR_FACTORS` says which of the nine errors of Table 2 sit in which placement, in
which order. :class:`~turntable_pin.model.chain.ErrorChain` turns this table and the URDF into the
one chain every layer reads; no code elsewhere needs to know the factor order.
"""

from __future__ import annotations

__all__ = [
    "INNER_JOINT",
    "JOINT_ERRORS",
    "OUTER_JOINT",
    "PAYLOAD_FRAME",
    "PAYLOAD_MOUNT",
    "PLACEMENT_ERROR_FACTORS",
    "PLACEMENT_ORDER",
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

"""The paper's two-axis table as data: its joint and frame names, the Table 3 error factors and
the name map over the one generic table.

The bundled ``models/turntable.urdf`` names its joints ``outer_axis`` (phi1, about y) and
``inner_axis`` (phi2, about z), the fixed ``payload_mount`` and the payload frame ``gyrowheel``;
:data:`PLACEMENT_ERROR_FACTORS` says which of the nine errors of Table 2 sit in which placement, in
which order. :data:`PAPER_LAYOUT` is that table as an
:class:`~turntable_pin.model.generic_table.ErrorLayout`: :func:`paper_table` is the generic
:class:`~turntable_pin.model.generic_table.GenericTable` of the URDF under this layout, the one
table class every layer reads; no code elsewhere needs to know the factor order.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

from .errors import ERROR_DESCRIPTIONS, ERROR_NAMES
from .generic_table import ErrorLayout

__all__ = [
    "INNER_JOINT",
    "JOINT_ERRORS",
    "OUTER_JOINT",
    "PAPER_LAYOUT",
    "PAYLOAD_FRAME",
    "PAYLOAD_MOUNT",
    "PLACEMENT_ERROR_FACTORS",
    "PLACEMENT_ORDER",
    "has_paper_names",
    "is_paper_table",
    "paper_table",
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


PAPER_LAYOUT = ErrorLayout(
    PLACEMENT_ERROR_FACTORS, ERROR_NAMES, ERROR_DESCRIPTIONS, JOINT_ERRORS, "paper", PAYLOAD_FRAME
)
"""The paper's table as a layout over the generic table: Table 3's factors under Table 2's names."""


@lru_cache(maxsize=8)
def _paper_table(urdf: str, telescope_mount: str | None = None):
    from .generic_table import GenericTable

    return GenericTable(urdf, layout=PAPER_LAYOUT, telescope_mount=telescope_mount)


def paper_table(urdf_path: str | Path | None = None, telescope_mount: str | None = None):
    """The paper's table: the :class:`~turntable_pin.model.generic_table.GenericTable` of
    ``urdf_path`` (default the bundled ``models/turntable.urdf``) under :data:`PAPER_LAYOUT`
    (read once per file, ``telescope_mount`` and process)."""
    from ..core.exceptions import InputError
    from ..core.resources import default_urdf_path

    path = Path(urdf_path) if urdf_path is not None else default_urdf_path()
    if not path.is_file():
        raise InputError("no such URDF file", path=path)
    return _paper_table(str(path.resolve()), telescope_mount)


def is_paper_table(table) -> bool:
    """Whether ``table`` is the paper's: under :data:`PAPER_LAYOUT` (its angles go by the
    paper's names phi1, phi2 in reports, and its reports carry no table keys)."""
    return getattr(table, "layout", None) is PAPER_LAYOUT


def has_paper_names(table) -> bool:
    """Whether a generic table has the paper's joints and payload frame (so its errors can go
    by the paper's names)."""
    return table.joint_names == (OUTER_JOINT, INNER_JOINT) and table.payload_frame == PAYLOAD_FRAME


def table_of(
    urdf_path: str | Path | None = None,
    payload_frame: str | None = None,
    telescope_mount: str | None = None,
):
    """The table of a URDF: the paper's (:func:`paper_table`) when it is the bundled table or has
    the paper's joints and payload frame, else the generic table under the generic rule;
    ``telescope_mount`` says what it is, overriding its URDF (``None``: as the URDF declares;
    :class:`~turntable_pin.model.generic_table.GenericTable`)."""
    from .generic_table import GenericTable

    if urdf_path is None and payload_frame in (None, PAYLOAD_FRAME):
        return paper_table(telescope_mount=telescope_mount)
    if payload_frame not in (None, PAYLOAD_FRAME):
        return GenericTable(urdf_path or paper_table().urdf_path, payload_frame,
                            telescope_mount=telescope_mount)  # fmt: skip
    table = GenericTable(urdf_path, payload_frame, telescope_mount=telescope_mount)
    return paper_table(urdf_path, telescope_mount) if has_paper_names(table) else table

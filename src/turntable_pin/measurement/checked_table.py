"""The table of a URDF as the commands and the flat API load it: a declared telescope mount is
checked against the documented frames before any work.

Light on purpose: the pointing-term machinery is imported only for a table that declares a mount,
so that a command on a plain turntable (``orientation``) starts fast.
"""

from __future__ import annotations

__all__ = ["checked_table"]


def checked_table(urdf_path=None, payload_frame: str | None = None, telescope_mount=None):
    """The table of a URDF (:func:`~turntable_pin.model.paper_table.table_of`; default the
    paper's), a telescope mount checked against the documented frames
    (:func:`~turntable_pin.measurement.pointing_terms.mount_kind`) before any work.

    Args:
        urdf_path: the URDF (default: the bundled paper's table).
        payload_frame: the payload frame (default: the only leaf of the chain).
        telescope_mount: ``"altaz"``, ``"equatorial"`` or ``"none"``, overriding the URDF's
            declaration (``None``: as declared).
    """
    from ..model.paper_table import table_of

    table = table_of(urdf_path, payload_frame, telescope_mount)
    if table.telescope_mount is not None:
        from .pointing_terms import mount_kind

        mount_kind(table)  # refuses a declared mount whose chain is not the documented one
    return table

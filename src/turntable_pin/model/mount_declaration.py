"""What a table says it is: a telescope mount of a named kind, or (saying nothing) a turntable.

A table is a telescope mount only when it says so, never guessed from its axes (a turntable
may have an alt-az mount's axes). Its URDF says it with a child of ``<robot>`` that Pinocchio and
yourdfpy ignore::

    <turntable_pin mount="altaz"/>          (or mount="equatorial")

The caller may override it (``GenericTable(..., telescope_mount=...)``: a kind, or
:data:`NO_MOUNT`). The chain is checked where the mount's terms are used
(:func:`turntable_pin.measurement.pointing_terms.mount_kind`).
"""

from __future__ import annotations

from pathlib import Path

from ..core.exceptions import InputError

__all__ = [
    "ALTAZ",
    "DECLARATION_ELEMENT",
    "EQUATORIAL",
    "MOUNT_ATTRIBUTE",
    "MOUNT_KINDS",
    "NO_MOUNT",
    "declaration_text",
    "read_mount_declaration",
    "resolve_mount",
]

ALTAZ = "altaz"
"""An alt-azimuth mount (phi1 = azimuth, phi2 = elevation)."""
EQUATORIAL = "equatorial"
"""An equatorial mount (phi1 = hour angle positive West, phi2 = declination)."""
MOUNT_KINDS = (ALTAZ, EQUATORIAL)
"""The kinds of telescope mount a table may declare."""
NO_MOUNT = "none"
"""The caller's word for a turntable, whatever its URDF declares."""

DECLARATION_ELEMENT = "turntable_pin"
"""The element, a child of ``<robot>``, that declares what the table is."""
MOUNT_ATTRIBUTE = "mount"
"""Its attribute naming the mount kind."""


def declaration_text(kind: str) -> str:
    """The declaration of a mount of ``kind`` as it is written in a URDF."""
    return f'<{DECLARATION_ELEMENT} {MOUNT_ATTRIBUTE}="{kind}"/>'


def read_mount_declaration(root, path: str | Path) -> str | None:
    """The mount kind the URDF at ``path`` (its ``<robot>`` element ``root``) declares, or
    ``None``; :class:`InputError` for a declaration that is not one child of ``<robot>`` with
    exactly ``mount`` set to one of :data:`MOUNT_KINDS`."""
    found = list(root.iter(DECLARATION_ELEMENT))
    if not found:
        return None
    expected = f"expected one {declaration_text('|'.join(MOUNT_KINDS))} as a child of <robot>"
    if len(found) > 1 or found[0] not in list(root):
        where = "twice" if len(found) > 1 else "inside another element"
        raise InputError(f"<{DECLARATION_ELEMENT}> {where}: {expected}", path=path)
    attributes = dict(found[0].attrib)
    kind = attributes.pop(MOUNT_ATTRIBUTE, None)
    if attributes or kind not in MOUNT_KINDS:
        given = " ".join(f'{k}="{v}"' for k, v in found[0].attrib.items())
        raise InputError(f"<{DECLARATION_ELEMENT} {given}/>: {expected}", path=path)
    return kind


def resolve_mount(declared: str | None, given: str | None) -> str | None:
    """What a table is (``None``: a turntable): ``given`` (a kind, or :data:`NO_MOUNT`) unless
    ``None``, else ``declared`` (its URDF's); :class:`InputError` for any other ``given``."""
    if given is None:
        return declared
    if given not in (*MOUNT_KINDS, NO_MOUNT):
        raise InputError(
            f"telescope_mount {given!r}: expected {', '.join(MOUNT_KINDS)} or {NO_MOUNT!r} "
            "(a turntable), or None (as the URDF declares)"
        )
    return None if given == NO_MOUNT else given

"""The meshcat viewer: the 3-D setup scene of any table, the meshcat server, headless Chromium
and PNG snapshots."""

from ..core.lazy import lazy_exports

_EXPORTS = {
    "Exaggeration": "scene",
    "SetupScene": "scene",
    "render_snapshot": "snapshot",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)

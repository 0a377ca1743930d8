"""Presentation: the one PNG saver, figures, and the HTML report rendered from structured results.
"""

from ..core.lazy import lazy_exports

_EXPORTS = {
    "write_report": "html_report",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)

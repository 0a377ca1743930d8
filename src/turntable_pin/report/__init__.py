"""Presentation: the one PNG saver, figures, and the text and HTML reports, each rendered from the
structured results (``to_dict()``) of the layers below, never from another renderer's output.
"""

from ..core.lazy import lazy_exports

_EXPORTS = {
    "diagnosis_html": "html_report",
    "diagnosis_lines": "diagnosis_text",
    "save_png": "figures",
    "write_report": "html_report",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)

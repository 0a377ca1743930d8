"""The one way figures leave the package: matplotlib on the Agg backend and :func:`save_png`.

Every PNG of the package (allocation, requirement, residual and report figures) goes through
:func:`save_png`, at one resolution, written atomically when a path is given.
"""

# matplotlib is imported inside pyplot(): import turntable_pin stays light
from __future__ import annotations

import io
from pathlib import Path
from typing import Any

from ..core.files import write_atomic

__all__ = ["FIGURE_DPI", "pyplot", "save_png"]

FIGURE_DPI = 110
"""Resolution of every PNG the package writes, dots per inch."""


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the non-interactive Agg backend (imported on first use)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_png(fig: Any, path: str | Path | None = None, *, dpi: int = FIGURE_DPI) -> Any:
    """Render the matplotlib ``fig`` to PNG at ``dpi`` and close it: written atomically to
    ``path`` (returned), or the PNG bytes when ``path`` is ``None``."""
    try:
        if path is None:
            buffer = io.BytesIO()
            fig.savefig(buffer, format="png", dpi=dpi, bbox_inches="tight")
            return buffer.getvalue()
        return write_atomic(
            path, lambda tmp: fig.savefig(tmp, format="png", dpi=dpi, bbox_inches="tight")
        )
    finally:
        pyplot().close(fig)

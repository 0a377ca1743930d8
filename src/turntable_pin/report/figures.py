"""The one way figures leave the package: matplotlib on the Agg backend and :func:`save_png`.

Every PNG of the package (allocation, requirement, residual and report figures) goes through
:func:`save_png`, at one resolution, written atomically when a path is given.
"""

# matplotlib is imported inside pyplot(): import turntable_pin stays light
from __future__ import annotations

import io
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path
from typing import Any

from ..core.files import write_atomic

__all__ = ["FIGURE_DPI", "figures_written", "kept_figures", "pyplot", "save_png"]

FIGURE_DPI = 110
"""Resolution of every PNG the package writes, dots per inch."""


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the non-interactive Agg backend (imported on first use)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


_KEPT: ContextVar[list | None] = ContextVar("kept_figures", default=None)


@contextmanager
def kept_figures() -> Iterator[list]:
    """Inside the block, every figure :func:`save_png` renders is also kept open and appended
    to the list this yields (instead of being closed)."""
    kept: list = []
    token = _KEPT.set(kept)
    try:
        yield kept
    finally:
        _KEPT.reset(token)


def figures_written(write: Callable[[Path], object]) -> list:
    """The matplotlib figures ``write(folder)`` renders, open, in order: it writes into a
    temporary folder, removed afterwards (the figures of a result are the ones its command
    writes, drawn by the one code)."""
    with tempfile.TemporaryDirectory(prefix="turntable-pin-figures-") as folder:
        with kept_figures() as figures:
            write(Path(folder))
    return figures


def save_png(fig: Any, path: str | Path | None = None, *, dpi: int = FIGURE_DPI) -> Any:
    """Render the matplotlib ``fig`` to PNG at ``dpi`` and close it (inside
    :func:`kept_figures`: keep it open and listed): written atomically to ``path`` (returned), or
    the PNG bytes when ``path`` is ``None``."""
    try:
        if path is None:
            buffer = io.BytesIO()
            fig.savefig(buffer, format="png", dpi=dpi, bbox_inches="tight")
            return buffer.getvalue()
        return write_atomic(
            path, lambda tmp: fig.savefig(tmp, format="png", dpi=dpi, bbox_inches="tight")
        )
    finally:
        kept = _KEPT.get()
        if kept is None:
            pyplot().close(fig)
        else:
            kept.append(fig)

"""D-optimal positions that identify the base errors and the chosen effects (issue 19, item 1).

Being written: the skeleton of the ``design`` command runs against this placeholder.
"""

from __future__ import annotations

from ..core.exceptions import InputError

__all__ = ["design_identify"]


def design_identify(space, n_positions: int, **options):
    """D-optimal positions (being written)."""
    raise InputError("design: the identify mode is being written (issue 19, item 1)")

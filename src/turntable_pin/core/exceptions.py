"""Exception hierarchy of turntable_pin: one base class, each error carrying where it happened.

The CLI turns every :class:`TurntablePinError` into a one-line message and exit status 2.
"""

from __future__ import annotations

from pathlib import Path

__all__ = [
    "IdentifiabilityError",
    "InfeasibleError",
    "InputError",
    "ModelError",
    "TurntablePinError",
]


class TurntablePinError(Exception):
    """Base class of every error this package raises on purpose."""


class InputError(TurntablePinError, ValueError):
    """Bad user input: a value, a name, a file, a row or a column that cannot be used.

    The message names where the problem is (file, row, column) when that is known. Rows are
    counted as a spreadsheet shows them: the header is row 1, the first data row is row 2.
    """

    def __init__(
        self,
        message: str,
        *,
        path: str | Path | None = None,
        row: int | None = None,
        column: str | None = None,
    ) -> None:
        self.path = None if path is None else str(path)
        self.row = row
        self.column = column
        self.detail = message
        where = []
        if self.path is not None:
            where.append(self.path)
        if row is not None:
            where.append(f"row {row}")
        if column is not None:
            where.append(f"column '{column}'")
        prefix = ", ".join(where)
        super().__init__(f"{prefix}: {message}" if prefix else message)


class ModelError(TurntablePinError):
    """The URDF does not describe the two-axis turntable this package expects."""


class IdentifiabilityError(TurntablePinError, ValueError):
    """A set of positions or measurements cannot determine the requested parameters."""


class InfeasibleError(TurntablePinError, ValueError):
    """An optimisation problem has no solution (e.g. lower bounds already exceed a limit)."""

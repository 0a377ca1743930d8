"""Exception hierarchy of turntable_pin: one base class, each error carrying where it happened.

The CLI turns every :class:`TurntablePinError` into a one-line message and exit status 2. The seed
check every random process shares (:func:`check_seed`) lives here too.
"""

from __future__ import annotations

from pathlib import Path

__all__ = [
    "SEED_LIMIT",
    "IdentifiabilityError",
    "InfeasibleError",
    "InputError",
    "ModelError",
    "TurntablePinError",
    "UserCodeError",
    "check_seed",
    "one_line",
]


def one_line(text: str) -> str:
    """``text`` with every unprintable character (newline, carriage return, tab, ...) escaped.

    Messages quote user input (a cell, a key, an option value); escaping keeps each message on one
    line of the terminal whatever that input holds.
    """
    if text.isprintable():
        return text
    return "".join(ch if ch.isprintable() else repr(ch)[1:-1] for ch in text)


class TurntablePinError(Exception):
    """Base class of every error this package raises on purpose (its message is one line)."""

    def __init__(self, *args: object) -> None:
        super().__init__(*(one_line(a) if isinstance(a, str) else a for a in args))


class InputError(TurntablePinError, ValueError):
    """Bad user input: a value, a name, a file, a row or a column that cannot be used.

    The message names where the problem is (file, row or line, column) when that is known. Rows
    are counted as a spreadsheet shows them: the header is row 1, the first data row is row 2;
    ``line`` is a line of a text file such as a YAML file (1 = first line).
    """

    def __init__(
        self,
        message: str,
        *,
        path: str | Path | None = None,
        row: int | None = None,
        column: str | None = None,
        line: int | None = None,
    ) -> None:
        self.path = None if path is None else str(path)
        self.row = row
        self.column = column
        self.line = line
        self.detail = message
        where = []
        if self.path is not None:
            where.append(self.path)
        if row is not None:
            where.append(f"row {row}")
        if line is not None:
            where.append(f"line {line}")
        if column is not None:
            where.append(f"column '{column}'")
        prefix = ", ".join(where)
        super().__init__(f"{prefix}: {message}" if prefix else message)


class UserCodeError(TurntablePinError):
    """Code the user brought (a Python effect module, an installed plug-in) raised an exception
    or broke its contract (a shape, a non-finite value, a parameter name).

    Not an :class:`InputError`: the fits that skip a candidate they cannot evaluate on the data
    (``except InputError``) must not hide a broken plug-in as "cannot be fitted". The message
    names the file (and the line when known), the effect and what went wrong; an exception raised
    inside the user's code is kept as ``__cause__``, with its traceback.
    """

    def __init__(
        self, message: str, *, path: str | Path | None = None, line: int | None = None
    ) -> None:
        self.path = None if path is None else str(path)
        self.line = line
        self.detail = message
        where = ", ".join(
            [*([self.path] if self.path else []), *([f"line {line}"] if line else [])]
        )
        super().__init__(f"{where}: {message}" if where else message)


class ModelError(TurntablePinError):
    """The URDF does not describe the two-axis turntable this package expects."""


class IdentifiabilityError(TurntablePinError, ValueError):
    """A set of positions or measurements cannot determine the requested parameters."""


class InfeasibleError(TurntablePinError, ValueError):
    """An optimisation problem has no solution (e.g. lower bounds already exceed a limit)."""


SEED_LIMIT = 2**63
"""Seeds are whole numbers ``0 <= seed < SEED_LIMIT`` (what a signed 64-bit integer holds)."""


def check_seed(seed: object, what: str = "seed") -> int:
    """``seed`` as an int, or :class:`InputError` unless it is a whole number in [0, 2**63).

    Every random process of the package takes its seed through this check (numpy would refuse a
    negative seed with a traceback and take a float or a huge number without a word).
    """
    import numbers

    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral):
        raise InputError(f"{what} must be a whole number 0 <= seed < 2**63, got {seed!r}")
    value = int(seed)
    if not 0 <= value < SEED_LIMIT:
        raise InputError(f"{what} must be a whole number 0 <= seed < 2**63, got {value}")
    return value

"""Exception hierarchy of turntable_pin: one base class, each error carrying where it happened.

The CLI turns every :class:`TurntablePinError` into a one-line message and exit status 2. The seed
check every random process shares (:func:`check_seed`) lives here too.
"""

from __future__ import annotations

import numbers
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
    """``text`` with every unprintable character (newline, tab, ...) escaped: a message quoting
    user input (a cell, a key, an option value) stays on one line of the terminal."""
    if text.isprintable():
        return text
    return "".join(ch if ch.isprintable() else repr(ch)[1:-1] for ch in text)


def _located(message: str, path: str | None, **where) -> str:
    """``message`` after where it happened: ``path, row R, line L, column 'C': message``."""
    words = {"row": "row {}", "line": "line {}", "column": "column '{}'"}
    parts = [path] if path is not None else []
    parts += [words[key].format(value) for key, value in where.items() if value is not None]
    return f"{', '.join(parts)}: {message}" if parts else message


class TurntablePinError(Exception):
    """Base class of every error this package raises on purpose (its message is one line)."""

    def __init__(self, *args: object) -> None:
        super().__init__(*(one_line(a) if isinstance(a, str) else a for a in args))


class InputError(TurntablePinError, ValueError):
    """Bad user input: a value, a name, a file, a row or a column that cannot be used.

    The message names where the problem is (file, row or line, column) when that is known. A
    CSV row is the file's line number, comment and blank lines counted (the header is row 1
    unless ``#`` lines come first; :mod:`~turntable_pin.core.csv_table`); ``line`` is a line of
    a text file such as a YAML file (1 = first line).
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
        super().__init__(_located(message, self.path, row=row, line=line, column=column))


class UserCodeError(TurntablePinError):
    """Code the user brought (an effect module, a plug-in) raised an exception or broke its
    contract: file (and line), effect and what went wrong; the exception is the ``__cause__``.

    Not an :class:`InputError`: fits that skip a candidate they cannot evaluate (``except
    InputError``) must not hide a broken plug-in as "cannot be fitted".
    """

    def __init__(
        self, message: str, *, path: str | Path | None = None, line: int | None = None
    ) -> None:
        self.path = None if path is None else str(path)
        self.line = line
        self.detail = message
        super().__init__(_located(message, self.path or None, line=line or None))


class ModelError(TurntablePinError):
    """The URDF does not describe the two-axis turntable this package expects."""


class IdentifiabilityError(TurntablePinError, ValueError):
    """A set of positions or measurements cannot determine the requested parameters."""


class InfeasibleError(TurntablePinError, ValueError):
    """An optimisation problem has no solution (e.g. lower bounds already exceed a limit)."""


SEED_LIMIT = 2**63
"""Seeds are whole numbers ``0 <= seed < SEED_LIMIT`` (what a signed 64-bit integer holds)."""


def check_seed(seed: object, what: str = "seed") -> int:
    """``seed`` as an int, or :class:`InputError` unless it is a whole number in [0, 2**63): the
    check of every random process (numpy would take a float or a huge number without a word)."""
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral):
        raise InputError(f"{what} must be a whole number 0 <= seed < 2**63, got {seed!r}")
    value = int(seed)
    if not 0 <= value < SEED_LIMIT:
        raise InputError(f"{what} must be a whole number 0 <= seed < 2**63, got {value}")
    return value

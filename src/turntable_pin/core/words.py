"""How the library names an argument or a command it suggests: in Python's words, or the CLI's.

A library text (an error message, a verdict's advice) names the Python argument, ``limits_deg``,
and a next step as a call, ``design(separate='A,B', from_data='run.csv')``. While the command line
runs a command it installs its own words (:func:`speaking`): the same texts then name the flag,
``--limits-deg``, and the shell command, ``turntable-pin design --separate A,B --from run.csv``. So
no library line names a flag or builds a shell command, and the CLI's output is what it always was.
"""

from __future__ import annotations

import shlex
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field

__all__ = ["Command", "CommandLineWords", "argument", "command", "speaking"]


@dataclass(frozen=True)
class CommandLineWords:
    """The command line's words: its program name and the flags whose names are not the Python
    argument's (``--`` + the name with ``-`` for ``_`` otherwise)."""

    program: str
    flags: Mapping[str, str] = field(default_factory=dict)

    def flag(self, name: str) -> str:
        """The flag of the Python argument ``name``."""
        return self.flags.get(name, "--" + name.replace("_", "-"))


_WORDS: ContextVar[CommandLineWords | None] = ContextVar("turntable_pin_words", default=None)


@contextmanager
def speaking(words: CommandLineWords) -> Iterator[None]:
    """Within the block, :func:`argument` and :class:`Command` speak the command line's words."""
    token = _WORDS.set(words)
    try:
        yield
    finally:
        _WORDS.reset(token)


def argument(name: str) -> str:
    """The Python argument ``name`` as the user who called knows it: ``name`` itself from Python,
    its flag from the command line."""
    words = _WORDS.get()
    return name if words is None else words.flag(name)


@dataclass(frozen=True)
class Command:
    """A next step the library suggests: the entry point ``name``, its positional values, then its
    keyword arguments in order (``True``: a switch; ``None``: left out). ``str()`` renders it as a
    Python call, or as a shell command while the command line speaks."""

    name: str
    positional: tuple[str, ...] = ()
    keywords: tuple[tuple[str, object], ...] = ()

    def __str__(self) -> str:
        words = _WORDS.get()
        given = [(k, v) for k, v in self.keywords if v is not None and v is not False]
        if words is None:
            args = [repr(v) for v in self.positional] + [f"{k}={v!r}" for k, v in given]
            return f"{self.name}({', '.join(args)})"
        tokens = [words.program, self.name, *self.positional]
        for key, value in given:
            tokens += [words.flag(key)] if value is True else [words.flag(key), str(value)]
        return " ".join(shlex.quote(t) for t in tokens)


def command(name: str, *positional: str, **keywords: object) -> Command:
    """The :class:`Command` ``name(*positional, **keywords)`` (keywords in the order given)."""
    return Command(name, tuple(str(p) for p in positional), tuple(keywords.items()))

"""Code the user brings (a Python effect module, an installed plug-in): imported and called so
that whatever goes wrong inside it is reported as theirs, in one line.

A Python effect module is code that runs: importing it runs its top level, and the package calls
its classes' methods. :func:`import_module_file` imports one from its path and :func:`call_user`
calls a method of it; an exception raised inside (or a ``sys.exit`` there) becomes a
:class:`~.exceptions.UserCodeError` naming the file, the line in it and the exception's message,
with the exception kept as its ``__cause__``. ``KeyboardInterrupt`` (Ctrl-C, and the package's
own interruptions) passes through: an interrupted command still ends as interrupted. With the
environment variable ``TURNTABLE_PIN_TRACEBACK=1`` the command line prints the full traceback
before the one line (:data:`TRACEBACK_ENV`).
"""

from __future__ import annotations

import os
import sys
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any

from .exceptions import InputError, UserCodeError

__all__ = [
    "PACKAGE",
    "TRACEBACK_ENV",
    "TRACEBACK_HINT",
    "call_user",
    "class_file",
    "import_module_file",
    "is_user_code",
    "show_traceback",
]

PACKAGE = "turntable_pin"
"""The package's top-level name: classes defined below it are not the user's."""
TRACEBACK_ENV = "TURNTABLE_PIN_TRACEBACK"
"""Environment variable: ``1`` makes the command line print the traceback of an error."""
TRACEBACK_HINT = f"({TRACEBACK_ENV}=1 shows the traceback)"
"""The words an error raised inside the user's code ends with."""
_MESSAGE_CHARACTERS = 300
"""Longest part of an exception's message quoted (the line stays readable)."""


def is_user_code(obj: object) -> bool:
    """Whether ``obj`` (a class, or an instance of one) is defined outside this package."""
    cls = obj if isinstance(obj, type) else type(obj)
    module = getattr(cls, "__module__", "") or ""
    return not (module == PACKAGE or module.startswith(PACKAGE + "."))


def class_file(cls: type) -> str | None:
    """The file that defines ``cls``, or ``None`` when it is not known (built in the shell)."""
    import inspect

    try:
        return inspect.getsourcefile(cls) or inspect.getfile(cls)
    except (TypeError, OSError):
        return None


def show_traceback() -> bool:
    """Whether :data:`TRACEBACK_ENV` asks for tracebacks (any value but empty or ``0``)."""
    return os.environ.get(TRACEBACK_ENV, "").strip() not in ("", "0")


def _line_in(exc: BaseException, path: str | Path | None) -> int | None:
    """The line of ``path`` the exception last passed through (the innermost frame there)."""
    if path is None:
        return None
    target = os.path.realpath(path)
    line = None
    for frame in traceback.extract_tb(exc.__traceback__):
        if frame.filename and os.path.realpath(frame.filename) == target:
            line = frame.lineno
    return line


def _happened(exc: BaseException) -> str:
    """What the user's code did: ``raised ValueError: its message`` or ``called sys.exit(0)``."""
    if isinstance(exc, SystemExit):
        return f"called sys.exit({exc.code!r})"
    text = next((t.strip() for t in str(exc).splitlines() if t.strip()), "")
    if len(text) > _MESSAGE_CHARACTERS:
        text = text[:_MESSAGE_CHARACTERS] + "..."
    return f"raised {type(exc).__name__}" + (f": {text}" if text else "")


def call_user(what: str, function: Callable, *args: Any, path: str | Path | None = None) -> Any:
    """``function(*args)``, a piece of the user's code described by ``what`` (``effect 'x'
    (class X): chain_terms(variables)``), defined in the file ``path``.

    Raises:
        UserCodeError: ``function`` raised an exception or called ``sys.exit``: the file, the
            line of it the exception passed through last, ``what`` and the exception's message
            (the exception is the error's ``__cause__``). ``KeyboardInterrupt`` passes.
    """
    import numpy as np

    try:
        # a NaN or inf it computes is reported by the contract's check of what it returned,
        # not as numpy's warnings on stderr
        with np.errstate(all="ignore"):
            return function(*args)
    except KeyboardInterrupt:
        raise
    except (Exception, SystemExit) as exc:
        raise UserCodeError(
            f"{what} {_happened(exc)} {TRACEBACK_HINT}", path=path, line=_line_in(exc, path)
        ) from exc


def import_module_file(path: str | Path, module_name: str):
    """The module of the Python file ``path``, imported (its top level run) as ``module_name``.

    No ``__pycache__`` is written beside the file.

    Raises:
        InputError: the file cannot be loaded as a Python module.
        UserCodeError: importing it raised an exception (a syntax error, a missing import...)
            or called ``sys.exit``: one line naming the file and the line. ``KeyboardInterrupt``
            passes (the module is forgotten first).
    """
    import importlib.util

    path = Path(path)
    spec = importlib.util.spec_from_file_location(module_name, path)
    if spec is None or spec.loader is None:
        raise InputError("cannot be loaded as a Python module (expected FILE.py)", path=path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    # Reading a file leaves no trace beside it: no __pycache__ folder in the user's folder.
    writes_bytecode, sys.dont_write_bytecode = sys.dont_write_bytecode, True
    try:
        spec.loader.exec_module(module)
    except KeyboardInterrupt:
        sys.modules.pop(module_name, None)
        raise
    except (Exception, SystemExit) as exc:
        sys.modules.pop(module_name, None)
        if isinstance(exc, SyntaxError) and exc.filename and Path(exc.filename) == path:
            line, what = exc.lineno, f"SyntaxError: {exc.msg}"
        elif isinstance(exc, SystemExit):
            line = _line_in(exc, path)
            what = (f"it called sys.exit({exc.code!r}) while being imported (a module of "
                    "effects defines them; it runs no program)")  # fmt: skip
        else:
            line, what = _line_in(exc, path), _happened(exc).removeprefix("raised ")
        hint = "" if isinstance(exc, SyntaxError) else f" {TRACEBACK_HINT}"
        raise UserCodeError(f"cannot import it: {what}{hint}", path=path, line=line) from exc
    finally:
        sys.dont_write_bytecode = writes_bytecode
    return module

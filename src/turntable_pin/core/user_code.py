"""Code the user brings (a Python effect module, an installed plug-in): imported and called so
that whatever goes wrong inside it is reported as theirs, in one line.

:func:`import_module_file` imports an effect module from its path (its top level runs) and
:func:`call_user` calls a method of it; an exception raised inside (or a ``sys.exit``) becomes a
:class:`~.exceptions.UserCodeError` naming the file, the line and the message (the exception its
``__cause__``). ``KeyboardInterrupt`` passes through. :data:`TRACEBACK_ENV` asks the command line
for the full traceback.
"""

from __future__ import annotations

import importlib.util
import inspect
import os
import sys
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

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
    """``function(*args)``, the user's code described by ``what`` (``effect 'x' (class X):
    chain_terms(variables)``) in the file ``path``; an exception or ``sys.exit`` inside it is a
    :class:`UserCodeError` (the file, the last line of it passed, ``what``, the message)."""
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
    """The module of the Python file ``path``, imported as ``module_name`` (no ``__pycache__``
    beside it). :class:`InputError`: not loadable; :class:`UserCodeError`: importing it raised
    (a syntax error, a missing import...) or called ``sys.exit``, naming the file and line."""
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

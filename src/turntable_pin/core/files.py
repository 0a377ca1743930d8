"""Small I/O helpers shared by every layer: atomic writes that never leave half a file behind,
and a YAML reader that refuses a key given twice."""

from __future__ import annotations

import functools
import os
import tempfile
from collections.abc import Callable
from pathlib import Path

__all__ = ["read_text_file", "read_yaml", "write_atomic", "write_bytes_atomic", "write_text_atomic"]


def write_atomic(path: str | Path, write: Callable[[Path], None]) -> Path:
    """Call ``write(tmp_path)`` on a temporary file beside ``path``, then rename it into place.

    If ``write`` raises, the temporary file is removed and any existing ``path`` is untouched.
    An operating-system error (a folder that is a file, no permission, a full disk) becomes an
    :class:`InputError` naming the output path.
    """
    from .exceptions import InputError

    path = Path(path)
    if path.is_dir():
        raise InputError("cannot write the file: it is a folder", path=path)
    blocking = next((p for p in path.parents if p.exists() and not p.is_dir()), None)
    if blocking is not None:
        raise InputError(f"cannot write the file: {blocking} is a file, not a folder", path=path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp_name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:
        raise InputError(f"cannot write the file: {exc.strerror or exc}", path=path) from None
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        write(tmp)
        # mkstemp makes the file private (0600); give it the mode a plain open() would.
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise InputError(f"cannot write the file: {exc.strerror or exc}", path=path) from None
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path


def write_text_atomic(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    return write_atomic(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


def write_bytes_atomic(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically."""
    return write_atomic(path, lambda tmp: tmp.write_bytes(data))


def read_text_file(path: str | Path, kind: str, encoding: str = "utf-8") -> str:
    """The text of the file ``path``; an unreadable or non-UTF-8 file is an ``InputError``
    naming it (``kind``: what the file should be, e.g. ``"YAML"``, for the message)."""
    from .exceptions import InputError

    path = Path(path)
    try:
        return path.read_text(encoding=encoding)
    except OSError as exc:
        raise InputError(f"cannot read the file: {exc.strerror or exc}", path=path) from None
    except UnicodeDecodeError:
        raise InputError(f"not a text (UTF-8) {kind} file", path=path) from None


def read_yaml(path: str | Path):
    """Parse a YAML file; an unreadable file or invalid YAML raises :class:`InputError`.

    A key given twice in one mapping is refused, naming the file and the line of the second one
    (plain YAML readers keep the last value and silently drop the first).
    """
    import yaml

    from .exceptions import InputError

    path = Path(path)
    text = read_text_file(path, "YAML")
    try:
        return yaml.load(text, Loader=_unique_key_loader())  # noqa: S506 (a SafeLoader)
    except _DuplicateKey as dup:
        raise InputError(
            f"key '{dup.key}' is given twice (first on line {dup.first_line}); give each key once",
            path=path,
            line=dup.line,
        ) from None
    except yaml.YAMLError as exc:
        raise InputError(f"not valid YAML: {str(exc).splitlines()[0]}", path=path) from None
    except (ValueError, OverflowError, RecursionError) as exc:  # e.g. a date 2020-13-45
        raise InputError(f"not valid YAML: {exc}", path=path) from None


class _DuplicateKey(Exception):
    """A mapping of a YAML document holds one key twice."""

    def __init__(self, key: object, line: int, first_line: int) -> None:
        super().__init__(key)
        self.key, self.line, self.first_line = key, line, first_line


@functools.lru_cache(maxsize=1)
def _unique_key_loader():
    """A ``yaml.SafeLoader`` subclass that raises :class:`_DuplicateKey` on a repeated key."""
    import yaml

    class UniqueKeyLoader(yaml.SafeLoader):
        def construct_mapping(self, node, deep=False):
            if isinstance(node, yaml.MappingNode):
                seen: dict[object, int] = {}
                for key_node, _ in node.value:
                    if key_node.tag == "tag:yaml.org,2002:merge":
                        continue
                    key = self.construct_object(key_node, deep=True)
                    try:
                        first = seen.get(key)
                    except TypeError:  # unhashable: the base class says so
                        continue
                    line = key_node.start_mark.line + 1
                    if first is not None:
                        raise _DuplicateKey(key, line, first)
                    seen[key] = line
            return super().construct_mapping(node, deep)

    return UniqueKeyLoader

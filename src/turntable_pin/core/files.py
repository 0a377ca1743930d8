"""Small I/O helpers shared by every layer: atomic writes that never leave half a file behind,
the one check of an input file before it is read (a regular file, within the size its kind may
have: :func:`check_input_file`), and a YAML reader that refuses a key given twice and a document
whose aliases expand beyond :data:`~turntable_pin.core.sizes.MAX_YAML_VALUES` values."""

# yaml is imported inside the functions that parse: a command that reads no YAML starts faster

from __future__ import annotations

import functools
import os
import stat
import tempfile
from collections.abc import Callable
from pathlib import Path

from .exceptions import InputError
from .sizes import MAX_YAML_FILE_BYTES, MAX_YAML_VALUES

__all__ = [
    "check_input_file",
    "output_target",
    "read_text_file",
    "read_yaml",
    "read_yaml_lines",
    "write_atomic",
    "write_bytes_atomic",
    "write_text_atomic",
]


def output_target(path: str | Path, *, folder: bool = False) -> Path:
    """Where an output ``path`` (a file, or a ``folder`` of files) goes, checked before anything
    is written: ``path``, or the target of a link there (the link is kept). :class:`InputError`
    (``cannot write the file: ...``) where a plain write would fail or undo what the user
    protected: a link to nothing or a loop; a folder for a file or the reverse, a parent that is
    a file; a write-protected file (for root: one without any write bit, the owner's say); a
    folder this user may not write in."""
    path = Path(path)
    target, why = _link_target(path)
    why = why or _why_not_writable(target, folder)
    if why:
        raise InputError(f"cannot write the {'folder' if folder else 'file'}: {why}", path=path)
    return target


def _link_target(path: Path) -> tuple[Path, str | None]:
    """The file a link at ``path`` points to (``path`` itself when no link), and why it cannot
    be written (a link to nothing, or a loop) or ``None``."""
    if not path.is_symlink():
        return path, None
    try:
        return path.resolve(strict=True), None
    except FileNotFoundError:
        return path, f"it is a link to {os.readlink(path)}, which does not exist"
    except (RuntimeError, OSError):  # RuntimeError: a loop, before Python 3.13
        return path, "it is a link that loops"


def _why_not_writable(target: Path, folder: bool) -> str | None:
    """Why an output at ``target`` cannot be written (see :func:`output_target`), or ``None``."""
    if folder and target.exists() and not target.is_dir():
        return "it is a file, not a folder"
    if not folder and target.is_dir():
        return "it is a folder"
    blocking = next((p for p in target.parents if p.exists() and not p.is_dir()), None)
    if blocking is not None:
        return f"{blocking} is a file, not a folder"
    if not folder and target.exists() and _write_protected(target):
        mode = stat.S_IMODE(target.stat().st_mode)
        return f"permission denied (the file is write-protected, mode {mode:04o})"
    where = target if folder and target.is_dir() else target.parent
    while not where.exists() and where != where.parent:
        where = where.parent
    if not _access(where, os.W_OK | os.X_OK):
        return f"permission denied (cannot write in the folder {where})"
    return None


def _access(path: Path, mode: int) -> bool:
    """``os.access`` for the effective user (who the process writes as)."""
    return os.access(path, mode, effective_ids=os.access in os.supports_effective_ids)


def _write_protected(path: Path) -> bool:
    """Whether a plain write to the existing file ``path`` would be refused (for root: whether
    the file has no write permission bit at all, since the system lets root write anyway)."""
    if getattr(os, "geteuid", lambda: -1)() == 0:
        return not path.stat().st_mode & 0o222
    return not _access(path, os.W_OK)


def write_atomic(path: str | Path, write: Callable[[Path], None]) -> Path:
    """Call ``write(tmp_path)`` on a temporary file beside ``path`` (checked first,
    :func:`output_target`), then rename it into place; if ``write`` raises, ``path`` is untouched.
    A replaced file keeps its mode (and owner, where allowed), a new one gets ``open()``'s; an
    OS error (a full disk) is an :class:`InputError` naming ``path``."""
    path = Path(path)
    target = output_target(path)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        previous = target.stat() if target.exists() else None
        fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    except OSError as exc:
        raise InputError(f"cannot write the file: {exc.strerror or exc}", path=path) from None
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        write(tmp)
        _give_mode(tmp, previous)
        os.replace(tmp, target)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise InputError(f"cannot write the file: {exc.strerror or exc}", path=path) from None
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path


def _give_mode(tmp: Path, previous: os.stat_result | None) -> None:
    """Give ``tmp`` (made private, 0600, by mkstemp) the mode and owner of the file it replaces
    (``previous``), or the mode a plain ``open()`` gives a new file."""
    if previous is None:
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        return
    if hasattr(os, "chown"):
        try:
            os.chown(tmp, previous.st_uid, previous.st_gid)
        except OSError:  # another user's file: a user cannot give it away; it becomes theirs
            pass
    os.chmod(tmp, stat.S_IMODE(previous.st_mode))


def write_text_atomic(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    return write_atomic(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


def write_bytes_atomic(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically."""
    return write_atomic(path, lambda tmp: tmp.write_bytes(data))


_NOT_REGULAR = (
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISFIFO, "a named pipe"),
    (stat.S_ISSOCK, "a socket"),
)


def _megabytes(size: int) -> str:
    return f"{size / 1e6:.4g} MB" if size < 1e9 else f"{size / 1e9:.4g} GB"


def check_input_file(path: str | Path, kind: str, max_bytes: int) -> Path:
    """``path`` when it is a regular file (links followed) of at most ``max_bytes`` bytes, else
    :class:`InputError` naming it (``kind``: ``"CSV"``, ...), before anything is read: where every
    reader starts. A device or pipe may never end; a huge file would fill the memory."""
    path = Path(path)
    try:
        info = path.stat()
    except OSError as exc:
        raise InputError(f"cannot read the file: {exc.strerror or exc}", path=path) from None
    if stat.S_ISDIR(info.st_mode):
        raise InputError(f"cannot read the file: it is a folder, not a {kind} file", path=path)
    if not stat.S_ISREG(info.st_mode):
        what = next((w for test, w in _NOT_REGULAR if test(info.st_mode)), "not a regular file")
        raise InputError(
            f"cannot read the file: it is {what}, not a {kind} file (give a regular file)",
            path=path,
        )
    if info.st_size > max_bytes:
        raise too_large(path, kind, max_bytes, info.st_size)
    return path


def too_large(path: str | Path, kind: str, max_bytes: int, size: int | None = None):
    """The :class:`InputError` of a ``kind`` file larger than ``max_bytes`` (``size``: its size
    in bytes, when known)."""
    has = f"{_megabytes(size)} ({size:,} bytes)" if size is not None else "larger"
    return InputError(
        f"the file is {has}; a {kind} file is read up to {_megabytes(max_bytes)}", path=path
    )


def read_text_file(
    path: str | Path, kind: str, encoding: str = "utf-8", *, max_bytes: int = MAX_YAML_FILE_BYTES
) -> str:
    """The text of ``path`` (:func:`check_input_file` first; never more than ``max_bytes`` read),
    universal newlines; an unreadable or non-UTF-8 file is an ``InputError`` naming it."""
    path = check_input_file(path, kind, max_bytes)
    try:
        with path.open(encoding=encoding) as handle:
            text = handle.read(max_bytes + 1)  # a file that grew since, or says it is empty
    except OSError as exc:
        raise InputError(f"cannot read the file: {exc.strerror or exc}", path=path) from None
    except UnicodeDecodeError:
        raise InputError(f"not a text (UTF-8) {kind} file", path=path) from None
    if len(text) > max_bytes:
        raise too_large(path, kind, max_bytes)
    return text


def read_yaml(path: str | Path):
    """Parse a YAML file; an unreadable file, invalid YAML, a key given twice in a mapping
    (named with its line: plain readers drop the first silently), more than ``MAX_YAML_FILE_BYTES``
    or ``MAX_YAML_VALUES`` values with aliases expanded raise :class:`InputError`."""
    return _load_yaml(path)[0]


def read_yaml_lines(path: str | Path) -> tuple[object, dict[tuple, int]]:
    """:func:`read_yaml`'s document and ``{key path: line}`` of its keys and list items (1-based;
    a key path is a tuple, ``("terms", 0, "site")``; an alias' keys listed once, at its anchor)."""
    data, node = _load_yaml(path)
    return data, _key_lines(node)


def _load_yaml(path: str | Path):
    """The document of the YAML file ``path`` and its composed node (``None`` when empty)."""
    import yaml

    path = Path(path)
    text = read_text_file(path, "YAML")
    loader = None
    try:
        loader = _unique_key_loader()(text)  # its reader refuses unprintable characters
        node = loader.get_single_node()
        if node is None:
            return None, None
        _check_values(node, path)
        return loader.construct_document(node), node
    except InputError:  # a ValueError, but said already
        raise
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
    finally:
        if loader is not None:
            loader.dispose()


def _check_values(root, path: Path) -> None:
    """Refuse a document of more than ``MAX_YAML_VALUES`` values with its aliases expanded, or
    one that holds itself (an alias inside its own anchor). Counted on the composed nodes, each
    once (an alias is the very node of its anchor): in time linear in the file."""
    import yaml

    sizes: dict[int, int] = {}
    inside: set[int] = set()

    def size(node) -> int:
        key = id(node)
        if key in sizes:
            return sizes[key]
        if key in inside:
            raise InputError(
                "an alias (*name) inside the value it names: the document would contain itself",
                path=path, line=node.start_mark.line + 1,
            )  # fmt: skip
        total = 1
        if isinstance(node, yaml.CollectionNode):
            inside.add(key)
            pairs = node.value if isinstance(node, yaml.MappingNode) else ((c,) for c in node.value)
            for pair in pairs:
                total += sum(size(child) for child in pair)
                if total > MAX_YAML_VALUES:
                    raise InputError(
                        f"more than {MAX_YAML_VALUES:,} values once its aliases (*name) are "
                        "expanded; the YAML inputs of this package hold hundreds at most (use "
                        "fewer aliases, or none)",
                        path=path, line=node.start_mark.line + 1,
                    )  # fmt: skip
            inside.discard(key)
        sizes[key] = total
        return total

    size(root)


def _key_lines(root) -> dict[tuple, int]:
    """``{key path: line}`` of the mapping keys and list items under ``root`` (1-based), each
    node entered once."""
    import yaml

    lines: dict[tuple, int] = {}
    entered: set[int] = set()

    def walk(node, where: tuple) -> None:
        if id(node) in entered:
            return
        entered.add(id(node))
        if isinstance(node, yaml.MappingNode):
            for key, value in node.value:
                if isinstance(key, yaml.ScalarNode):
                    here = (*where, key.value)
                    lines.setdefault(here, key.start_mark.line + 1)
                    walk(value, here)
        elif isinstance(node, yaml.SequenceNode):
            for i, item in enumerate(node.value):
                lines.setdefault((*where, i), item.start_mark.line + 1)
                walk(item, (*where, i))

    if root is not None:
        walk(root, ())
    return lines


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

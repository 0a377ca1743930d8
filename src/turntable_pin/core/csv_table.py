"""Reading numeric CSV tables with checks that name the file, row and column of every problem.

One row-numbering rule for every reader: a row is the file's line number, ``#`` comment lines
and blank lines counted (as an editor numbers lines; the header is row 1 unless comment lines
come first), and a problem of the header (its delimiter, a missing or repeated column) is
reported at the header's line. A file that fails a check raises :class:`InputError`. Only a
regular file within the sizes of :mod:`.sizes` is read (:func:`read_lines`).
"""

from __future__ import annotations

import csv
import difflib
import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .exceptions import InputError
from .files import check_input_file, write_text_atomic
from .sizes import MAX_TABLE_COLUMNS, MAX_TABLE_FILE_BYTES, MAX_TABLE_ROWS

__all__ = [
    "ROW_RULE",
    "CsvTable",
    "check_header",
    "closest_column_hint",
    "first_repeated_row",
    "ignored_columns_words",
    "missing_columns_words",
    "read_csv_table",
    "read_header",
    "read_lines",
    "refuse_repeated_rows",
    "write_csv_table",
]


ROW_RULE = "a row a message names is the file's line number, comment lines counted"
"""The row-numbering rule of the module docstring, in the words a command's help says it."""


@dataclass(frozen=True)
class CsvTable:
    """The numeric columns of a CSV file.

    Attributes:
        path: the file read; header: every column name, in file order.
        columns: ``{name: float array}`` of the required and the present optional columns.
        rows: the line number of each data row (module docstring); header_row: the header's
            (1 unless ``#`` lines come first).
        extra, skipped: with ``extra=True``, the other numeric columns and the names of the
            other, non-numeric ones (text or empty throughout), for the caller to say so.
    """

    path: Path
    columns: dict[str, np.ndarray]
    header: tuple[str, ...]
    rows: np.ndarray
    extra: dict[str, np.ndarray] = field(default_factory=dict)
    skipped: tuple[str, ...] = ()
    header_row: int = 1

    def __len__(self) -> int:
        return int(self.rows.size)

    def has(self, name: str) -> bool:
        """Whether the optional column ``name`` is present."""
        return name in self.columns

    def refuse(self, column: str, bad, rule: str) -> None:
        """Raise :class:`InputError` at the first row where ``bad`` (a mask over the rows) holds:
        ``"<rule>, found <value>"`` with file, row and column."""
        rows = np.flatnonzero(bad)
        if rows.size:
            raise InputError(
                f"{rule}, found {self[column][rows[0]]:g}",
                path=self.path, row=int(self.rows[rows[0]]), column=column,
            )  # fmt: skip

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]


def closest_column_hint(name: str, header, known=()) -> str:
    """`` (is 'X' a misspelling of it?)`` for the header column most like ``name``, or ``""``
    when none is close (difflib's ratio at least 0.6). A column in ``known`` (a name the reader
    knows, such as ``sigma_arcsec``) is no misspelling of another and is never proposed."""
    others = [h for h in header if h != name and h not in known]
    close = difflib.get_close_matches(name, others, n=1, cutoff=0.6)
    return f" (is '{close[0]}' a misspelling of it?)" if close else ""


DELIMITER = ","
"""The one column delimiter of every CSV file the commands read."""
_OTHER_DELIMITERS = {";": "';'", "\t": "a tab", "|": "'|'"}
"""Delimiters a spreadsheet may export instead, as the message names them."""


def check_header(path, header: Sequence[str], line: str, row: int) -> None:
    """Refuse a header line ``line`` (read as ``header``, at line ``row`` of ``path``) that is not
    comma-separated (one cell holding ``;`` or tabs: "the delimiter is ';' (expected ',')") or
    names a column twice: the header's problems every reader reports alike, at the header's
    line."""
    if len(header) == 1 and DELIMITER not in line:
        counts = {d: line.count(d) for d in _OTHER_DELIMITERS}
        found = max(counts, key=counts.get)
        if counts[found]:
            raise InputError(
                f"the delimiter is {_OTHER_DELIMITERS[found]} (expected '{DELIMITER}'): save "
                "the file as comma-separated CSV (decimal points, not commas, in the numbers)",
                path=path, row=row,
            )  # fmt: skip
    seen = set()
    for name in header:
        if name in seen:
            raise InputError(f"column '{name}' appears twice in the header", path=path, row=row)
        seen.add(name)


def read_header(path: str | Path) -> tuple[tuple[str, ...], int]:
    """The column names of a CSV file and the line number of its header line, read before the
    whole file (to choose which columns to ask for); ``((), 0)`` when the file is unreadable or
    empty, which :func:`read_csv_table` then reports. A header of another delimiter or with a
    repeated column is refused here (:func:`check_header`)."""
    found = None
    try:
        path = check_input_file(path, "CSV", MAX_TABLE_FILE_BYTES)
        with path.open(newline="", encoding="utf-8-sig") as handle:
            for row, line in enumerate(handle, start=1):
                if line.strip() and not line.lstrip().startswith("#"):
                    found = tuple(c.strip() for c in next(csv.reader([line]))), row, line
                    break
    except (InputError, OSError, UnicodeDecodeError, csv.Error):
        pass
    if found is None:
        return (), 0
    header, row, line = found
    check_header(path, header, line, row)
    return header, row


def read_lines(path: str | Path) -> list[tuple[int, str]]:
    """``(line number, line)`` of the lines of ``path`` that hold cells, header first (blank and
    ``#`` lines left out). Bounded before and while it reads (``MAX_TABLE_FILE_BYTES``,
    ``MAX_TABLE_ROWS``, ``MAX_TABLE_COLUMNS`` cells a row): no file holds more in memory than the
    largest table a command takes. :class:`InputError` names the file (and the row)."""
    path = check_input_file(path, "CSV", MAX_TABLE_FILE_BYTES)
    lines: list[tuple[int, str]] = []
    try:
        with path.open(newline="", encoding="utf-8-sig") as handle:
            for number, line in enumerate(handle, start=1):
                if not line.strip() or line.lstrip().startswith("#"):
                    continue
                if line.count(",") >= MAX_TABLE_COLUMNS:
                    raise InputError(
                        f"more than {MAX_TABLE_COLUMNS:,} cells; a CSV table is read up to "
                        f"{MAX_TABLE_COLUMNS:,} columns",
                        path=path, row=number,
                    )  # fmt: skip
                if len(lines) > MAX_TABLE_ROWS:  # the header and MAX_TABLE_ROWS rows are in
                    raise InputError(
                        f"more than {MAX_TABLE_ROWS:,} data rows; a CSV table is read up to "
                        f"{MAX_TABLE_ROWS:,}",
                        path=path, row=number,
                    )  # fmt: skip
                lines.append((number, line))
    except OSError as exc:
        raise InputError(f"cannot read the file: {exc.strerror or exc}", path=path) from None
    except UnicodeDecodeError:
        raise InputError("not a text (UTF-8) CSV file", path=path) from None
    return lines


def _csv_errors_named(read):
    """``read`` (a reader whose first argument is the path) with the csv module's own errors (a
    cell beyond its field size limit) said in one line naming the file."""

    @functools.wraps(read)
    def wrapper(path, *args, **kwargs):
        try:
            return read(path, *args, **kwargs)
        except csv.Error as exc:
            raise InputError(f"cannot read it as CSV: {exc}", path=path) from None

    return wrapper


@_csv_errors_named
def read_csv_table(
    path: str | Path,
    required: Sequence[str],
    optional: Sequence[str] = (),
    *,
    min_rows: int = 1,
    blank: Sequence[str] = (),
    extra: bool = False,
) -> CsvTable:
    """Read ``path`` (one header line; ``#`` lines before it skipped) and check that every
    ``required`` column exists and every value read is finite.

    Args:
        optional: columns read (and checked) when present; min_rows: fewest data rows.
        blank: columns whose empty cells are NaN ("not measured") instead of refused.
        extra: also read every other numeric column (:func:`_other_column`) into
            :attr:`CsvTable.extra`; the others are named in :attr:`CsvTable.skipped`.

    Raises:
        InputError: unreadable file, no header, a missing (close matches named) or repeated
            column, a cell read that is empty, not a number, NaN or infinite.
    """
    path = Path(path)
    lines = read_lines(path)
    if not lines:
        raise InputError("the file is empty (expected a header line)", path=path)
    # Without quotes a line's cells are its comma-separated fields: the header alone is parsed
    # here, and a clean body is read by numpy at once (:func:`_whole_table`).
    quoted = any('"' in line for _, line in lines)
    parsed = list(csv.reader([line for _, line in lines])) if quoted else None
    header = tuple(
        name.strip() for name in (parsed[0] if quoted else next(csv.reader([lines[0][1]])))
    )
    header_line = lines[0][0]
    check_header(path, header, lines[0][1], header_line)
    _check_required(path, header, required, (*required, *optional), set(blank), header_line)
    wanted = [name for name in (*required, *optional) if name in header]
    index = {name: header.index(name) for name in wanted}
    others = [n for n in header if n not in index and n] if extra else []
    values, other_cells, row_numbers = _read_cells(
        path, lines, parsed, header, index, others, set(blank)
    )
    if len(row_numbers) < min_rows:
        raise InputError(
            f"expected at least {min_rows} data row(s), found {len(row_numbers)}", path=path
        )
    extra_columns, skipped = _other_columns(path, lines, header, other_cells, row_numbers)
    return CsvTable(
        path=path,
        columns={name: np.asarray(v, dtype=float) for name, v in values.items()},
        header=header,
        rows=np.asarray(row_numbers, dtype=int),
        extra=extra_columns,
        skipped=tuple(skipped),
        header_row=header_line,
    )


def _check_required(
    path: Path, header: tuple[str, ...], required, known, blank: set[str], header_line: int
) -> None:
    """Refuse a required column missing: each named with the header column it may be (one the
    reader does not know, each proposed once), and for columns that may be empty (``blank``)
    that an empty column means "not measured"."""
    missing = [name for name in required if name not in header]
    if not missing:
        return
    proposed: set[str] = set()
    hints = [_missing_hint(name, header, known, proposed) for name in missing]
    empty = [name for name in missing if name in blank]
    advice = ""
    if empty:
        one = len(empty) == 1
        advice = (
            f"; if {_or(empty)} {'was' if one else 'were'} not measured, keep the "
            f"column{'' if one else 's'} with {'its' if one else 'their'} cells left empty (an "
            "empty cell means not measured)"
        )
    raise InputError(
        f"missing required column(s) {', '.join(hints)}; the header has {', '.join(header)}"
        + advice,
        path=path,
        row=header_line,
    )


def _missing_hint(name: str, header, known, proposed: set[str]) -> str:
    """A missing column ``name`` with the header column(s) it may be, none already ``proposed``
    for another (``proposed`` grows by what this one proposes)."""
    unknown = [h for h in header if h not in known and h not in proposed]
    close = [h for h in unknown if h.lower().replace(" ", "") == name.lower()]
    close += [h for h in unknown if h not in close and name.split("_")[0] == h.split("_")[0]]
    if close:
        proposed.update(close)
        return f"'{name}' (found {', '.join(repr(c) for c in close)})"
    hint = closest_column_hint(name, header, (*known, *proposed))
    if hint:
        proposed.add(hint.split("'")[1])
    return f"'{name}'{hint}"


def _or(names: Sequence[str]) -> str:
    return ", ".join(names[:-1]) + (" or " if len(names) > 1 else "") + names[-1]


def _read_cells(path, lines, parsed, header, index, others, blank_ok):
    """``(values, other cells, row numbers)``: numpy's parser on a clean unquoted body, else the
    wanted columns at once, else cell by cell (naming the problem)."""
    row_numbers = [line_no for line_no, _ in lines[1:]]
    whole = None if parsed else _whole_table([line for _, line in lines[1:]], len(header))
    if whole is not None and all(np.all(np.isfinite(whole[:, i])) for i in index.values()):
        values = {name: whole[:, i].copy() for name, i in index.items()}
        return values, {n: whole[:, header.index(n)].copy() for n in others}, row_numbers
    if parsed is None:
        parsed = list(csv.reader([line for _, line in lines]))
    data_rows = parsed[1:]
    fast = _whole_columns(data_rows, len(header), index)
    if fast is None:
        return _cell_by_cell(path, lines, data_rows, header, index, others, blank_ok)
    other_cells = {n: [cells[header.index(n)].strip() for cells in data_rows] for n in others}
    return fast, other_cells, row_numbers


def _other_columns(path, lines, header, other_cells, row_numbers) -> tuple[dict, list]:
    """The numeric other columns (``extra=True``) and the names of the text ones."""
    extra_columns, skipped = {}, []
    for name, cells in other_cells.items():
        if isinstance(cells, np.ndarray) and cells.size and np.all(np.isfinite(cells)):
            extra_columns[name] = cells  # read whole: finite numbers throughout
            continue
        if isinstance(cells, np.ndarray):  # a NaN or inf: the cells as written, to name it
            column = header.index(name)
            cells = [row[column].strip() for row in csv.reader([line for _, line in lines[1:]])]
        numbers = _other_column(path, name, cells, row_numbers)
        if numbers is None:
            skipped.append(name)
        else:
            extra_columns[name] = numbers
    return extra_columns, skipped


def _whole_table(data_lines: list[str], width: int) -> np.ndarray | None:
    """Every cell of unquoted data lines as floats (rows, ``width``) by numpy's parser, or
    ``None`` when a cell is not a number it reads or a row is not ``width`` wide (the cell-by-cell
    reading then decides). numpy accepts no cell ``float`` refuses and gives the same double (both
    round correctly); some ``float`` accepts (``1_000``) go the slow way."""
    if not data_lines:
        return None
    try:
        table = np.loadtxt(
            data_lines, delimiter=",", dtype=float, comments=None, ndmin=2, encoding=None
        )
    except ValueError:
        return None
    return table if table.shape == (len(data_lines), width) else None


def _whole_columns(data_rows, width: int, index: dict[str, int]) -> dict | None:
    """Every wanted column as floats at once, when the file is clean: each row as wide as the
    header and every wanted cell a finite number (``float`` of the cell, as cell by cell).
    ``None`` at the first doubt: :func:`_cell_by_cell` then finds and names the problem."""
    if any(len(cells) != width for cells in data_rows):
        return None
    columns = list(zip(*data_rows, strict=True)) if data_rows else [()] * width
    out = {}
    for name, i in index.items():
        try:
            column = np.fromiter(map(float, columns[i]), dtype=float, count=len(data_rows))
        except ValueError:
            return None
        if not np.all(np.isfinite(column)):
            return None
        out[name] = column
    return out


def _cell_by_cell(path, lines, data_rows, header, index, others, blank_ok):
    """Read the wanted columns row by row and cell by cell, raising at the first problem (its
    row and column named); ``(values, other cells, row numbers)``."""
    values = {name: [] for name in index}
    other_cells: dict[str, list[str]] = {n: [] for n in others}
    row_numbers = []
    for (line_no, _), cells in zip(lines[1:], data_rows, strict=True):
        if len(cells) != len(header):
            raise InputError(
                f"expected {len(header)} cells as in the header, found {len(cells)}",
                path=path,
                row=line_no,
            )
        for name in others:
            other_cells[name].append(cells[header.index(name)].strip())
        for name in index:
            text = cells[index[name]].strip()
            if not text and name in blank_ok:
                values[name].append(math.nan)
                continue
            try:
                number = float(text)
            except ValueError:
                what = "an empty cell" if not text else f"'{text}'"
                raise InputError(
                    f"expected a number, found {what}", path=path, row=line_no, column=name
                ) from None
            if not math.isfinite(number):
                raise InputError(
                    f"expected a finite number, found '{text}'", path=path, row=line_no, column=name
                )
            values[name].append(number)
        row_numbers.append(line_no)
    return values, other_cells, row_numbers


def _other_column(path, name: str, cells: Sequence[str], rows: Sequence[int]) -> np.ndarray | None:
    """A column other than the asked-for ones, as floats when it is numeric (at least half of
    its filled cells read as ``float``: ``temperature_c`` with a cell ``warm``), then checked as
    a required one (file, row and column of the first bad cell); ``None`` when it is text (a
    ``note`` column with a few numbers) or empty throughout."""
    numbers: list[float | None] = []
    for text in cells:
        try:
            numbers.append(float(text))
        except ValueError:
            numbers.append(None)
    filled = sum(1 for text in cells if text)
    counted = sum(1 for number in numbers if number is not None)
    if counted == 0 or 2 * counted < filled:
        return None
    for text, number, row in zip(cells, numbers, rows, strict=True):
        if number is not None and math.isfinite(number):
            continue
        why = f"{counted} of its {filled} filled cells are numbers, so it is a numeric column"
        if number is not None:
            found = f"expected a finite number, found '{text}'"
        else:
            found = (
                f"'{text}' is not a number" if text else "expected a number, found an empty cell"
            )
        raise InputError(f"{found} ({why})", path=path, row=int(row), column=name)
    return np.array(numbers, dtype=float)


def ignored_columns_words(names: Sequence[str]) -> str:
    """``"column(s) a, b ignored: not numbers (text or empty throughout)"``: what a reader
    tells of the columns :attr:`CsvTable.skipped` names."""
    return f"column(s) {', '.join(names)} ignored: not numbers (text or empty throughout)"


def missing_columns_words(missing: Sequence[str], ignored: Sequence[str], where: str) -> str:
    """Why the columns ``missing`` cannot be used: ``"a, absent from <where>"``, and ``"b,
    present in <where> but not numbers (...), so ignored"`` for those among ``ignored`` (the
    file's :attr:`CsvTable.skipped`): a column that is there is never called absent."""
    absent = [c for c in missing if c not in ignored]
    text = [c for c in missing if c in ignored]
    parts = [f"{', '.join(absent)}, absent from {where}"] if absent else []
    if text:
        parts.append(
            f"{', '.join(text)}, present in {where} but not numbers (text or empty "
            "throughout), so ignored"
        )
    return "; ".join(parts)


def refuse_repeated_rows(table: CsvTable, key_columns: Sequence[str], advice: str) -> None:
    """Refuse two rows equal in every present column of ``key_columns`` (to 1e-9), a measurement
    counted twice: both rows, the columns, then ``advice`` (what makes repeats legitimate)."""
    present = [c for c in key_columns if table.has(c)]
    found = first_repeated_row([table[c] for c in present], len(table))
    if found is not None:
        first, second = found
        raise InputError(
            f"the same position as row {int(table.rows[first])} ({', '.join(present)} all "
            f"equal); {advice}",
            path=table.path, row=int(table.rows[second]), column=present[0] if present else None,
        )  # fmt: skip


def first_repeated_row(columns: Sequence[np.ndarray], n_rows: int) -> tuple[int, int] | None:
    """``(earlier, row)``: the first row equal to an earlier one in every column, values rounded
    to 1e-9 as ``round`` does (``-0.0 == 0.0``); ``None`` when none repeats. The rule of
    :func:`refuse_repeated_rows`, for readers that name their own lines (a TPOINT file's)."""
    if columns and n_rows > 1:
        keys = np.stack([_rounded_9(np.asarray(c, dtype=float)) for c in columns], axis=1)
        ordered = keys[np.lexsort(keys.T)]
        if not np.any(np.all(ordered[1:] == ordered[:-1], axis=1)):
            return None
    rounded = [[round(v, 9) for v in np.asarray(c, dtype=float).tolist()] for c in columns]
    keys = list(zip(*rounded, strict=True)) if columns else [()] * n_rows
    seen: dict[tuple, int] = {}
    for i, key in enumerate(keys):
        if key in seen:
            return seen[key], i
        seen[key] = i
    return None


def _rounded_9(values: np.ndarray) -> np.ndarray:
    """``round(v, 9)`` of every value, as Python rounds: vectorised (``rint(v 1e9) / 1e9``) when
    that is the same (``v 1e9`` below 2**44 and nowhere within 0.01 of a half), else one by one."""
    scaled = values * 1e9
    fraction = np.abs(scaled - np.floor(scaled) - 0.5)
    if np.all(np.abs(scaled) < 2.0**44) and not np.any(fraction < 0.01):
        return np.rint(scaled) / 1e9
    return np.array([round(v, 9) for v in values.tolist()], dtype=float)


def write_csv_table(
    path: str | Path, columns: dict[str, Sequence[float]], *, comment: str = ""
) -> Path:
    """Write equal-length columns as a CSV file, atomically; ``comment`` lines get a ``#``."""
    names = list(columns)
    n = len(next(iter(columns.values()))) if columns else 0
    lines = [f"# {line}" for line in comment.splitlines()] if comment else []
    lines.append(",".join(names))
    for i in range(n):
        lines.append(",".join(_format_cell(columns[name][i]) for name in names))
    return write_text_atomic(path, "\n".join(lines) + "\n")


def _format_cell(value) -> str:
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if math.isnan(float(value)):
        return ""  # an empty cell: not measured
    return repr(float(value))

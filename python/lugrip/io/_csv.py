"""CSV sliding logs (one table per file; docs/sliding_log.md) and the header rules that
Parquet tables share."""

from __future__ import annotations

import codecs
import csv
import io
import math
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ._log import UNITS, LogError, SlidingLog, _Locator

#: Largest CSV file read [bytes]. Clean files are streamed (pyarrow's CSV reader, block by
#: block): the reader then holds only the columns of the format, 8 bytes per cell (a 1.1 GB file
#: of 10**7 rows and seven columns: 0.56 GB).
MAX_CSV_BYTES = 2 * 1024**3
#: Largest CSV file the line-by-line reader takes [bytes]: it finds and names any problem (the
#: row and the column of a text cell, a ragged row, a blank line) but holds the file's text and
#: its cells in memory, about 4 times the file's size at the peak (53 MB file: 208 MB). A larger
#: file that the streaming reader cannot parse is refused with the streaming reader's message.
MAX_LINE_READER_BYTES = 192 * 1024 * 1024
#: Bytes per block of the streaming reader.
STREAM_BLOCK_BYTES = 1024 * 1024

_HEADER_RE = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(?:[\[(]\s*([^\])]*?)\s*[\])])?\s*$")


#: Columns of one finger in a two-finger table (suffix _0 or _1); the others are shared.
FINGER_COLUMNS = ("f_n", "f_x", "f_y", "f_t", "tau", "omega")
#: Columns a two-finger table may add: the grasp-force command recorded with it [N].
GRASP_COLUMNS = ("command",)


def _column_name(raw: str, finger: int | None) -> str | None:
    """The format's name of a header cell (lower case, unit stripped), None for other cells;
    with ``finger`` k, ``f_n_k`` etc. name finger k's columns and other fingers' are None."""
    m = _HEADER_RE.match(str(raw))
    name = m.group(1).lower() if m else None
    if finger is None or name is None:
        return name
    if name in GRASP_COLUMNS:
        return name
    base, _, k = name.rpartition("_")
    if base in FINGER_COLUMNS:
        return base if k == str(finger) else None
    return None if name in FINGER_COLUMNS else name


def _source_names(raw: str) -> tuple[str, ...]:
    """The names a ``columns=`` mapping may give for a header cell: the whole cell and its name
    without a ``[unit]`` suffix, lower case."""
    cell = str(raw).strip().lower()
    m = _HEADER_RE.match(str(raw))
    return (cell, m.group(1).lower()) if m else (cell,)


def _renames(names: list[str], file: str, columns: Mapping[str, str] | None) -> dict[str, str]:
    """{source name (lower case): format name} of a ``columns=`` mapping {format name: source
    column}, checked against the format and the header."""
    if not columns:
        return {}
    rename: dict[str, str] = {}
    for target, source in columns.items():
        if target not in UNITS:
            raise LogError(file, f"[[opt:columns]]: {target!r} is not a column of the format "
                           f"(expected one of {', '.join(UNITS)})")
        key = str(source).strip().lower()
        if key in rename:
            raise LogError(file, f"[[opt:columns]]: column {source!r} is mapped twice "
                           f"({rename[key]!r} and {target!r})")
        rename[key] = target
    present = {n for raw in names for n in _source_names(raw)}
    for key, target in rename.items():
        if key not in present:
            have = ", ".join(str(n) for n in names) or "(none)"
            raise LogError(file, f"[[opt:columns]] maps {target!r} to {columns[target]!r}, which "
                           f"is not a column of the file; the file has: {have}",
                           where="row 1", row=1)
    return rename


def _parse_header(names: list[str], file: str, finger: int | None = None,
                  columns: Mapping[str, str] | None = None
                  ) -> tuple[dict[str, int], dict[str, str], list[str]]:
    """Map column name -> position, column -> unit from ``name [unit]``, ignored names
    (``finger``: see :func:`_column_name`; ``columns``: {format name: the file's column}, for
    files whose columns have other names; a file column named like a mapped format column is
    then ignored)."""
    index: dict[str, int] = {}
    units: dict[str, str] = {}
    ignored: list[str] = []
    known = set(UNITS) | (set(GRASP_COLUMNS) if finger is not None else set())
    rename = _renames(names, file, columns)
    for pos, raw in enumerate(names):
        m = _HEADER_RE.match(str(raw))
        mapped = [rename[n] for n in _source_names(raw) if n in rename]
        name = mapped[0] if mapped else _column_name(raw, finger)
        if name not in known or (not mapped and name in rename.values()):
            ignored.append(str(raw))
            continue
        if name in index:
            raise LogError(file, f"column '{name}' appears twice (columns {index[name] + 1} "
                           f"and {pos + 1})", where=f"row 1, column '{name}'", row=1,
                           column=name)
        index[name] = pos
        if m is not None and m.group(2) is not None:
            units[name] = m.group(2)
    return index, units, ignored


def _check_required(index: Mapping[str, Any], names: list[str], file: str,
                    finger: int | None = None) -> None:
    have = ", ".join(str(n) for n in names) or "(none)"
    expected = ("expected t [s], f_n [N], f_x and f_y [N] (or f_t [N]), tau [N m]; optional "
                "omega [rad/s], maneuver")
    missing = [c for c in ("t", "f_n", "tau") if c not in index]
    if "f_x" in index and "f_y" not in index:
        missing.append("f_y")
    elif "f_y" in index and "f_x" not in index:
        missing.append("f_x")
    elif not any(c in index for c in ("f_x", "f_y", "f_t")):
        missing.append("f_x/f_y or f_t")
    if missing and finger is not None:
        k = finger
        missing = [f"f_x_{k}/f_y_{k} or f_t_{k}" if m == "f_x/f_y or f_t"
                   else (f"{m}_{k}" if m in FINGER_COLUMNS else m) for m in missing]
        expected = ("a two-finger table has t and per finger k = 0, 1: f_n_k, f_x_k and f_y_k "
                    "(or f_t_k), tau_k; optional omega_k, command, maneuver")
    if missing:
        names_ = ", ".join(f"'{c}'" for c in missing)
        hint = ("" if finger is not None else "; map the file's own names with [[alt:columns="
                "{'t': 'time', 'f_n': 'Fz', 'tau': 'Mz', ...}|--columns t=time,f_n=Fz,tau=Mz,...]]")
        raise LogError(file, f"missing required column(s) {names_}; the file has: {have}; "
                       f"{expected}{hint}", where=f"row 1, column '{missing[0]}'", row=1,
                       column=missing[0])


def _cells_to_float(cells, column: str, loc: _Locator) -> np.ndarray:
    """Text cells -> float64; empty cells are NaN; LogError names the first bad cell."""
    cleaned = ["nan" if c is None or not str(c).strip() else c for c in cells]
    try:
        return np.array(cleaned, dtype=np.float64)
    except (ValueError, TypeError):
        pass
    for i, cell in enumerate(cleaned):
        try:
            float(cell)
        except (ValueError, TypeError):
            hint = ""
            if re.fullmatch(r"\s*[-+]?\d+,\d+\s*", str(cell)):
                hint = " (decimal comma? use '.' as decimal separator)"
            raise loc.error(f"{str(cell)!r} is not a number{hint}", i, column) from None
    raise loc.error("column is not numeric", None, column)  # pragma: no cover


def _read_csv(path: Path, file: str, finger: int | None = None,
              columns: Mapping[str, str] | None = None
              ) -> tuple[dict[str, np.ndarray], dict[str, str], _Locator, dict]:
    size = path.stat().st_size
    if size > MAX_CSV_BYTES:
        raise LogError(file, f"{size / 2**20:.0f} MiB is more than the {MAX_CSV_BYTES // 2**20} "
                       "MiB a CSV log may hold (the reader keeps its columns in memory); split "
                       "the recording or convert it to Parquet")
    with open(path, "rb") as fh:
        head = fh.read(4096)
    if head[:2] in (b"\xff\xfe", b"\xfe\xff") or b"\x00" in head:
        raise LogError(file, "not UTF-8 text (UTF-16 or a binary file?); save the table as "
                       "UTF-8 CSV")
    fast, why = _read_csv_stream(path, file, finger, columns)
    if fast is not None:
        return fast
    if size > MAX_LINE_READER_BYTES:
        reason = f" ({why})" if why else ""
        raise LogError(file, f"the streaming CSV reader cannot read this file{reason}; the "
                       "line-by-line reader that names the row takes files up to "
                       f"{MAX_LINE_READER_BYTES // 2**20} MiB: mend the file (one header row, "
                       "no blank lines, a number in every cell), split it or convert it to "
                       "Parquet")
    raw = path.read_bytes().removeprefix(codecs.BOM_UTF8)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise LogError(file, f"byte {exc.start} is not UTF-8 text; save the table as UTF-8 CSV",
                       where=f"row {line}", row=line) from None
    del raw
    if not text.strip():
        raise LogError(file, "empty file (expected a header row and data rows)")
    first = next(line for line in text.splitlines() if line.strip())
    delim = _delimiter(first)
    reader = csv.reader(io.StringIO(text, newline=""), delimiter=delim,
                        skipinitialspace=True)
    header: list[str] | None = None
    rows: list[list[str]] = []
    lines: list[int] = []
    records = iter(reader)
    while True:
        try:
            record = next(records)
        except StopIteration:
            break
        except csv.Error as exc:  # e.g. a cell longer than the csv module's field limit
            raise LogError(file, f"unreadable CSV ({exc})", where=f"row {reader.line_num}",
                           row=reader.line_num) from None
        if not record or all(not c.strip() for c in record) and len(record) <= 1:
            continue  # blank line
        if header is None:
            header = [c.strip() for c in record]
            header_line = reader.line_num
            continue
        rows.append(record)
        lines.append(reader.line_num)
    assert header is not None
    index, units, ignored = _parse_header(header, file, finger, columns)
    if not index and all(_is_number(c) for c in header if c):
        raise LogError(file, f"no header row: row {header_line} holds numbers; the first row "
                       "must name the columns (t, f_n, f_x, f_y or f_t, tau, omega, maneuver)",
                       where=f"row {header_line}", row=header_line)
    _check_required(index, header, file, finger)
    if not rows:
        raise LogError(file, "no data rows (only the header)")
    loc = _Locator(file, rows=np.asarray(lines))
    width = len(header)
    for k, record in enumerate(rows):
        if len(record) != width:
            raise loc.error(f"{len(record)} cells, but the header has {width} columns "
                            f"(delimiter {delim!r})", k, None)
    cols = {}
    for name, pos in index.items():
        cols[name] = _cells_to_float([r[pos] for r in rows], name, loc)
    meta = {"format": "csv", "columns": [str(h) for h in header], "ignored_columns": ignored}
    return cols, units, loc, meta


def _delimiter(first_line: str) -> str:
    return next((d for d in (",", ";", "\t") if d in first_line), ",")


def _header_line(path: Path) -> bytes | None:
    """The first line of the file (UTF-8 BOM removed, line end kept); None when the file has no
    line end within its first MiB."""
    with open(path, "rb") as fh:
        first = fh.readline(1 << 20)
    first = first.removeprefix(codecs.BOM_UTF8)
    return first if first.endswith(b"\n") else None


def _count_lines(path: Path) -> int:
    """Lines of the file (a last line without a line end counts), read block by block."""
    n, last = 0, b""
    with open(path, "rb") as fh:
        while block := fh.read(STREAM_BLOCK_BYTES):
            n += block.count(b"\n")
            last = block[-1:]
    return n if last == b"\n" else n + 1


def _read_csv_stream(path: Path, file: str, finger: int | None = None,
                     columns: Mapping[str, str] | None = None):
    """pyarrow's streaming CSV reader for clean files (one header row, no blank lines, every
    cell of the format's columns a number), block by block into the format's columns; only
    those columns are ever held. Returns (result, None), or (None, reason) to fall back to the
    line-by-line reader, which finds and names any problem (reason: the streaming reader's
    words, for files too large for that reader)."""
    try:
        import pyarrow as pa
        import pyarrow.csv as pacsv
    except ImportError:
        return None, "pyarrow is not installed"
    first = _header_line(path)
    if first is None:
        return None, "no line end in the first MiB"
    try:
        line = first.rstrip(b"\r\n").decode("utf-8")
    except UnicodeDecodeError:
        return None, "the header row is not UTF-8 text"
    if "\r" in line or not line.strip():
        return None, "a stray carriage return or a blank first line"
    delim = _delimiter(line)
    try:
        header = [c.strip() for c in next(csv.reader([line], delimiter=delim))]
    except (csv.Error, StopIteration):  # e.g. quotes the csv module refuses: it names them
        return None, "the header row is not one CSV record"
    index, units, ignored = _parse_header(header, file, finger, columns)
    if not index:
        return None, "the first row names none of the format's columns"
    _check_required(index, header, file, finger)
    names = [f"c{i}" for i in range(len(header))]
    rows = _count_lines(path) - 1
    if rows < 1:
        return None, "no data rows"
    # the columns are allocated once and filled block by block (no second copy of them)
    cols = {name: np.empty(rows) for name in index}
    done = 0
    try:
        reader = pacsv.open_csv(
            pa.OSFile(str(path)),  # read(2), not a memory map: the file's pages stay out of RSS
            read_options=pacsv.ReadOptions(skip_rows=1, column_names=names,
                                           block_size=STREAM_BLOCK_BYTES),
            parse_options=pacsv.ParseOptions(delimiter=delim),
            convert_options=pacsv.ConvertOptions(
                column_types={names[pos]: pa.float64() for pos in index.values()},
                include_columns=[names[pos] for pos in index.values()],
                null_values=[""], strings_can_be_null=False))
        for batch in reader:
            k = batch.num_rows
            if done + k > rows:
                return None, "more records than lines"
            for name, pos in index.items():  # an empty cell (null) becomes NaN
                cols[name][done:done + k] = batch.column(names[pos]).to_numpy(
                    zero_copy_only=False)
            done += k
    except (pa.ArrowException, ValueError, OSError) as exc:
        return None, " ".join(str(exc).split())[:300]
    finally:
        pa.default_memory_pool().release_unused()  # the blocks' buffers back to the system
    if done != rows:  # blank lines (skipped by pyarrow) or line ends inside quotes
        return None, "blank lines or line ends inside quotes"
    meta = {"format": "csv", "columns": header, "ignored_columns": ignored}
    return (cols, units, _Locator(file), meta), None


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True

def _write_csv(log: SlidingLog, fh) -> None:
    cols = log.columns()
    text = io.TextIOWrapper(fh, encoding="utf-8", newline="")
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow(list(cols))
    lists = [a.tolist() for a in cols.values()]  # Python floats: repr round-trips exactly
    writer.writerows(zip(*lists))
    text.flush()
    text.detach()


"""Parquet sliding logs: the CSV columns in a typed table, ``meta`` kept as JSON."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from ._csv import _cells_to_float, _check_required, _parse_header
from ._extras import exc_text, need
from ._log import UNITS, LogError, SlidingLog, _json_meta, _Locator

#: Most rows read from one Parquet log (checked from the file's metadata before reading; about
#: 200 bytes per row in memory with its columns, copies and checks).
MAX_PARQUET_ROWS = 3_000_000


def _read_parquet(path: Path, file: str, finger: int | None = None,
                  columns=None):
    pa = need("pyarrow", "reading Parquet")
    pq = need("pyarrow.parquet", "reading Parquet")
    if path.stat().st_size == 0:
        raise LogError(file, "empty file (expected a Parquet table)")
    try:
        rows = pq.ParquetFile(path).metadata.num_rows
    except Exception as exc:  # noqa: BLE001 (pyarrow raises several types for bad files)
        raise LogError(file, f"not a readable Parquet file ({exc_text(exc)})") from None
    if rows > MAX_PARQUET_ROWS:
        raise LogError(file, f"{rows} rows, more than the {MAX_PARQUET_ROWS} a Parquet log may "
                       "hold (the reader keeps it in memory); split the recording")
    try:
        table = pq.read_table(path)
    except Exception as exc:  # noqa: BLE001 (pyarrow raises several types for bad files)
        raise LogError(file, f"not a readable Parquet file ({exc_text(exc)})") from None
    names = list(table.column_names)
    index, units, ignored = _parse_header(names, file, finger, columns)
    _check_required(index, names, file, finger)
    if table.num_rows == 0:
        raise LogError(file, "no data rows (the table is empty)")
    loc = _Locator(file)
    cols = {}
    for name, pos in index.items():
        col = table.column(pos)
        typ = col.type
        if pa.types.is_integer(typ) or pa.types.is_floating(typ) or pa.types.is_boolean(typ) \
                or pa.types.is_decimal(typ):
            arr = col.cast(pa.float64()).fill_null(math.nan).to_numpy()
            cols[name] = np.asarray(arr, dtype=np.float64)
        elif pa.types.is_string(typ) or pa.types.is_large_string(typ):
            cols[name] = _cells_to_float(col.to_pylist(), name, loc)
        else:
            raise loc.error(f"column type {typ} is not numeric (expected numbers in "
                            f"{UNITS.get(name, 'N')})", None, name)
    meta: dict[str, Any] = {"format": "parquet", "columns": names, "ignored_columns": ignored}
    stored = (table.schema.metadata or {}).get(b"lugrip")
    if stored:
        try:
            extra = json.loads(stored)
            meta.update({k: v for k, v in extra.items() if k not in meta})
        except ValueError:
            pass
    return cols, units, loc, meta

def _write_parquet(log: SlidingLog, fh) -> None:
    pa = need("pyarrow", "writing Parquet")
    pq = need("pyarrow.parquet", "writing Parquet")
    cols = log.columns()
    arrays = [pa.array(a, type=pa.int64() if name == "maneuver" else pa.float64())
              for name, a in cols.items()]
    # keep provenance (topics, t0_ns, ...), drop what describes one particular read
    skip = ("format", "columns", "ignored_columns", "converted_from", "flip_normal", "units")
    meta = _json_meta({k: v for k, v in log.meta.items() if k not in skip})
    meta["format_version"] = 1
    schema = pa.schema([pa.field(name, arr.type) for name, arr in zip(cols, arrays)],
                       metadata={b"lugrip": json.dumps(meta).encode()})
    pq.write_table(pa.Table.from_arrays(arrays, schema=schema), fh)


"""Generated hostile files against the CSV and MCAP readers (hypothesis).

Every example writes a file and reads it with :func:`lugrip.read_log`. The oracle:

* no exception but :class:`lugrip.LogError` (no traceback through the command line);
* CSV, random byte edits: a log that is read satisfies the SlidingLog invariants (finite,
  strictly increasing t; f_t >= 0; equal lengths);
* CSV, corruptions the format lets a reader see (a text cell, a row with a missing or extra
  cell, a duplicated or backward time, a block of >= 400 rows whose tau, f_n or f_x/f_y are
  scaled by 1000 where a full 200-row window of the block carries torque or force): a
  LogError naming the corrupted column, never a log;
* MCAP (zstd and uncompressed chunks, CRCs as mcap writes them), bytes flipped or the file
  cut: a LogError, or the original samples bit for bit, or (with a LogWarning that the file
  is truncated or damaged) a prefix of them. A log with other values is a silently accepted
  corruption and fails the test.

Examples per test: 200 (CI); ``LUGRIP_FUZZ_EXAMPLES=10000`` runs 10^4 locally.
"""

from __future__ import annotations

import os
import sys
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lugrip import ContactParams, LogError, LogWarning, read_log, write_log
from lugrip.sliding import simulate_maneuvers

EXAMPLES = int(os.environ.get("LUGRIP_FUZZ_EXAMPLES", "200"))
FUZZ = settings(max_examples=EXAMPLES, deadline=None, derandomize=False,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    d = tmp_path_factory.mktemp("fuzz")
    log = simulate_maneuvers(ContactParams.table1(), 3, seed=4).log
    csv = write_log(log, d / "base.csv")
    files = {"csv": csv.read_bytes()}
    pytest.importorskip("mcap")
    pytest.importorskip("rosbags")
    import mcap.writer  # noqa: F401  (imported before zstandard is hidden below)

    files["mcap_zstd"] = write_log(log, d / "z.mcap").read_bytes()
    saved = sys.modules.get("zstandard")
    sys.modules["zstandard"] = None  # write_log falls back to uncompressed chunks
    try:
        files["mcap_plain"] = write_log(log, d / "p.mcap", overwrite=True).read_bytes()
    finally:
        if saved is None:
            del sys.modules["zstandard"]
        else:
            sys.modules["zstandard"] = saved
    ref = read_log(csv)
    return _Base(dir=d, log=ref, files=files, lines=files["csv"].decode().splitlines())


class _Base(dict):
    """The fixture's files (a short repr: hypothesis prints it with a failing example)."""

    def __init__(self, **kw):
        super().__init__(**kw)

    def __repr__(self) -> str:
        return f"<fuzz base files in {self['dir']}>"


def _read(path):
    """(log or None, LogError or None, warnings); any other exception propagates."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            return read_log(path), None, caught
        except LogError as err:
            return None, err, caught


def _invariants(log) -> None:
    t = np.asarray(log.t)
    assert t.size and np.all(np.isfinite(t)) and np.all(np.diff(t) > 0)
    assert np.all(np.asarray(log.f_t)[np.isfinite(log.f_t)] >= 0)
    assert len(log.f_n) == len(log.tau) == len(t) == len(log.f_t)


# --- CSV -------------------------------------------------------------------------------------

@FUZZ
@given(data=st.data())
def test_csv_random_byte_edits(base, data):
    raw = bytearray(base["files"]["csv"])
    for _ in range(data.draw(st.integers(1, 4), label="edits")):
        kind = data.draw(st.sampled_from(["flip", "insert", "delete", "truncate"]))
        i = data.draw(st.integers(0, len(raw) - 1), label="at")
        if kind == "flip":
            raw[i] = data.draw(st.integers(0, 255))
        elif kind == "insert":
            raw[i:i] = data.draw(st.binary(min_size=1, max_size=8))
        elif kind == "delete":
            del raw[i:i + data.draw(st.integers(1, 16))]
        else:
            del raw[i:]
        if not raw:
            raw = bytearray(b"\n")
    path = base["dir"] / "edit.csv"
    path.write_bytes(bytes(raw))
    log, err, _ = _read(path)
    if err is None:
        _invariants(log)


_COLS = ["t", "f_n", "f_x", "f_y", "tau", "omega", "maneuver"]


def _cells(line: str) -> list[str]:
    return line.split(",")


@FUZZ
@given(data=st.data())
def test_csv_visible_corruptions_are_refused(base, data):
    lines = list(base["lines"])
    header = _cells(lines[0])
    n = len(lines) - 1
    kind = data.draw(st.sampled_from(["text", "missing", "extra", "dup_t", "back_t"]))
    r = data.draw(st.integers(2, n), label="row")  # a data row (1-based in lines)
    column = None
    if kind == "text":
        column = data.draw(st.sampled_from(header))
        token = data.draw(st.sampled_from(["abc", "1,5", "0x1p3", "--", "N", "1 2", "e5"]))
        f = _cells(lines[r])
        f[header.index(column)] = token
        lines[r] = ",".join(f)
    elif kind == "missing":
        lines[r] = ",".join(_cells(lines[r])[:-1])
    elif kind == "extra":
        lines[r] = lines[r] + ",0"
    elif kind == "dup_t":
        f = _cells(lines[r])
        f[0] = _cells(lines[r - 1])[0]
        lines[r] = ",".join(f)
        column = "t"
    else:
        k = data.draw(st.integers(1, r - 1), label="older row")
        f = _cells(lines[r])
        f[0] = _cells(lines[k])[0]
        lines[r] = ",".join(f)
        column = "t"
    path = base["dir"] / "vis.csv"
    path.write_text("\n".join(lines) + "\n")
    _log, err, _ = _read(path)
    assert err is not None, f"{kind} at row {r} ({column}) accepted"
    if column is not None:  # the error points at the corrupted cell (row as a sheet counts)
        assert err.column == column or err.row == r + 1, str(err)


@FUZZ
@given(data=st.data())
def test_csv_unit_blocks_are_refused(base, data):
    ref = base["log"]
    lines = list(base["lines"])
    header = _cells(lines[0])
    n = len(lines) - 1
    what = data.draw(st.sampled_from(["tau", "f_n", "f_xy"]))
    length = data.draw(st.integers(400, min(1200, n - 1)), label="rows")
    a = data.draw(st.integers(0, n - length), label="first")  # 0-based sample index
    cols = ["f_x", "f_y"] if what == "f_xy" else [what]
    for i in range(a, a + length):
        f = _cells(lines[i + 1])
        for c in cols:
            j = header.index(c)
            f[j] = repr(float(f[j]) * 1000.0)
        lines[i + 1] = ",".join(f)
    # does a full 200-row window of the block carry a load the check can see?
    f_n = np.asarray(ref.f_n)
    if what == "tau":
        x, bound, q = 1000.0 * np.abs(ref.tau) / f_n, 0.1, 90
    elif what == "f_n":
        x, bound, q = 1000.0 * f_n, 200.0, 50
    else:
        x, bound, q = 1000.0 * np.hypot(ref.f_x, ref.f_y) / f_n, 100.0, 90
    contact = f_n > max(0.1 * float(np.median(f_n)), 1e-3)
    if what == "f_n":
        contact = np.ones_like(contact)
    starts = [s for s in range(0, n, 200) if s >= a and s + 200 <= a + length]
    if n % 200:
        starts += [n - 200] if (n - 200 >= a and n <= a + length) else []
    visible = any(np.percentile(x[s:s + 200][contact[s:s + 200]], q) > bound
                  for s in starts if contact[s:s + 200].sum() >= 50)
    path = base["dir"] / "units.csv"
    path.write_text("\n".join(lines) + "\n")
    log, err, _ = _read(path)
    if visible:
        assert err is not None, f"{what} x1000 on rows {a + 2}-{a + length + 1} accepted"
        assert "units" in str(err)
    elif err is None:
        _invariants(log)


# --- MCAP ------------------------------------------------------------------------------------

def _same_prefix(log, ref) -> bool:
    k = len(log)
    if k == 0 or k > len(ref):
        return False
    return all(np.array_equal(np.asarray(getattr(log, c)), np.asarray(getattr(ref, c))[:k],
                              equal_nan=True) for c in ("f_n", "tau", "f_t"))


@FUZZ
@given(data=st.data(), variant=st.sampled_from(["mcap_zstd", "mcap_plain"]))
def test_mcap_damage_is_refused_or_harmless(base, data, variant):
    raw = bytearray(base["files"][variant])
    ref = base["log"]
    kind = data.draw(st.sampled_from(["flip", "flip", "flip", "truncate"]))
    if kind == "flip":
        for _ in range(data.draw(st.integers(1, 3), label="flips")):
            i = data.draw(st.integers(0, len(raw) - 1), label="byte")
            raw[i] ^= data.draw(st.integers(1, 255), label="xor")
    else:
        del raw[data.draw(st.integers(0, len(raw) - 1), label="cut"):]
    path = base["dir"] / "damaged.mcap"
    path.write_bytes(bytes(raw))
    log, err, caught = _read(path)
    if err is not None:
        assert str(path) in str(err)
        return
    if len(log) == len(ref) and _same_prefix(log, ref):
        return  # the damage did not reach the samples (an index, the summary)
    damaged = [w for w in caught if issubclass(w.category, LogWarning)
               and ("truncated" in str(w.message) or "damaged" in str(w.message))]
    assert damaged and _same_prefix(log, ref), (
        f"{kind}: {len(log)} samples read, other values than the original")

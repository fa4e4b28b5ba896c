"""Sliding-log I/O (lugrip.io): round trips, validation messages, units, segments, ROS sources."""

from __future__ import annotations

import math
import os
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lugrip.io import LogError, LogWarning, SlidingLog, read_log, write_log

HEADER = "t,f_n,f_x,f_y,tau,omega,maneuver\n"


def make_log(n=300, *, seed=0, vector=True, omega=True, maneuvers=3, dt=0.002) -> SlidingLog:
    """A plausible fingertip log: f_n 1-10 N, |f_t| < 2 N, |tau| < 10 N mm."""
    rng = np.random.default_rng(seed)
    t = 0.25 + dt * np.arange(n) + rng.uniform(0, 0.2 * dt, n)
    f_n = rng.uniform(1.0, 10.0, n)
    f_x, f_y = rng.uniform(-1.0, 1.0, (2, n))
    tau = rng.uniform(-0.01, 0.01, n)
    kw = {"f_x": f_x, "f_y": f_y} if vector else {"f_t": np.hypot(f_x, f_y)}
    if omega:
        kw["omega"] = rng.normal(0.0, 0.5, n)
    if maneuvers:
        kw["maneuver"] = np.sort(rng.integers(0, maneuvers, n))
    return SlidingLog.from_arrays(t, f_n, tau, **kw)


def assert_same(a: SlidingLog, b: SlidingLog, *, t_atol=0.0):
    assert len(a) == len(b)
    assert a.has_force_vector == b.has_force_vector
    np.testing.assert_allclose(b.t, a.t, rtol=0, atol=t_atol)
    for name in ("f_n", "f_t", "tau", "f_x", "f_y", "omega"):
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None) == (y is None), name
        if x is not None:
            np.testing.assert_array_equal(y, x, err_msg=name)
    np.testing.assert_array_equal(b.maneuver, a.maneuver)
    assert b.maneuver.dtype == np.int64


def csv_error(tmp_path, text, name="bad.csv", **kw) -> LogError:
    path = tmp_path / name
    path.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LogWarning)
        with pytest.raises(LogError) as info:
            read_log(path, **kw)
    err = info.value
    assert str(path) in str(err), "the message names the file"
    return err


def rows(*lines: str) -> str:
    return HEADER + "".join(line + "\n" for line in lines)


GOOD = ["0.000,2.0,0.1,0.2,0.001,0.0,0", "0.002,2.1,0.1,0.2,0.001,0.1,0",
        "0.004,2.2,0.1,0.2,0.001,0.2,0", "0.006,2.3,0.1,0.2,0.001,0.3,0"]


# ---------------------------------------------------------------------------------------------
# Round trips
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".pq", ".mcap"])
@pytest.mark.parametrize("vector", [True, False])
def test_round_trip(tmp_path, suffix, vector):
    """Every written format reads back to the same arrays (MCAP times to the nanosecond)."""
    log = make_log(vector=vector, seed=1)
    path = write_log(log, tmp_path / f"log{suffix}")
    back = read_log(path)
    assert_same(log, back, t_atol=1e-9 if suffix == ".mcap" else 0.0)
    assert back.source == str(path)
    assert back.meta["units"]["tau"] == "N m"


def test_round_trip_without_optional_columns(tmp_path):
    """Logs without omega and maneuver come back without omega and with maneuver 0."""
    log = make_log(omega=False, maneuvers=0)
    for suffix in (".csv", ".parquet", ".mcap"):
        back = read_log(write_log(log, tmp_path / f"plain{suffix}"))
        assert back.omega is None
        assert not back.maneuver.any()
        assert_same(log, back, t_atol=1e-9)


def test_mcap_keeps_negative_and_epoch_times(tmp_path):
    """MCAP stores unsigned ns: negative times and epoch offsets (meta t0_ns) survive."""
    log = make_log(n=50)
    shifted = SlidingLog.from_arrays(log.t - 1.0, log.f_n, log.tau, f_x=log.f_x, f_y=log.f_y)
    assert_same(shifted, read_log(write_log(shifted, tmp_path / "neg.mcap")), t_atol=1e-9)
    epoch = SlidingLog.from_arrays(log.t, log.f_n, log.tau, f_t=log.f_t,
                                   meta={"t0_ns": 1_700_000_000_123_456_789})
    back = read_log(write_log(epoch, tmp_path / "epoch.mcap"))
    assert back.meta["t0_ns"] == 1_700_000_000_123_456_789
    np.testing.assert_allclose(back.t, epoch.t, rtol=0, atol=1e-9)


def test_mcap_decodes_with_independent_ros2_decoder(tmp_path):
    """The MCAP messages are standard ROS 2 CDR: mcap-ros2-support decodes the same numbers."""
    pytest.importorskip("mcap_ros2.reader", reason="mcap-ros2-support not installed")
    from mcap_ros2.reader import read_ros2_messages

    log = make_log(n=40, seed=3)
    path = write_log(log, tmp_path / "x.mcap")
    wrenches = [m.ros_msg for m in read_ros2_messages(str(path), topics=["/lugrip/wrench"])]
    twists = [m.ros_msg for m in read_ros2_messages(str(path), topics=["/lugrip/omega"])]
    assert [w.wrench.force.z for w in wrenches] == log.f_n.tolist()
    assert [w.wrench.force.x for w in wrenches] == log.f_x.tolist()
    assert [w.wrench.force.y for w in wrenches] == log.f_y.tolist()
    assert [w.wrench.torque.z for w in wrenches] == log.tau.tolist()
    assert [tw.twist.angular.z for tw in twists] == log.omega.tolist()
    stamps = [w.header.stamp.sec + 1e-9 * w.header.stamp.nanosec for w in wrenches]
    np.testing.assert_allclose(stamps, log.t, rtol=0, atol=1e-9)


def test_f_t_is_the_in_plane_magnitude():
    """f_t = hypot(f_x, f_y) when the vector is given; a consistent f_t is accepted."""
    f_x, f_y = np.array([3.0, -0.6, 0.0]), np.array([4.0, 0.8, -2.0])
    log = SlidingLog.from_arrays([0.0, 0.1, 0.2], [1.0, 1.0, 1.0], [0.0, 0.0, 0.0],
                                 f_x=f_x, f_y=f_y)
    np.testing.assert_array_equal(log.f_t, [5.0, 1.0, 2.0])
    both = SlidingLog.from_arrays([0.0, 0.1, 0.2], [1.0] * 3, [0.0] * 3, f_x=f_x, f_y=f_y,
                                  f_t=[5.0, 1.0, 2.0])
    np.testing.assert_array_equal(both.f_t, [5.0, 1.0, 2.0])


def test_csv_head_and_header_units(tmp_path):
    """The CSV is plain: one header of column names, then numbers; headers may carry units."""
    path = write_log(make_log(n=3, maneuvers=0), tmp_path / "h.csv")
    assert path.read_text().splitlines()[0] == "t,f_n,f_x,f_y,tau,omega,maneuver"
    p = tmp_path / "units.csv"
    p.write_text("t [ms],f_n (N),f_t [mN],tau [N mm],comment\n0,2,100,1.5,a\n2,2,200,-1.5,b\n")
    log = read_log(p)
    np.testing.assert_allclose(log.t, [0.0, 0.002])
    np.testing.assert_allclose(log.f_t, [0.1, 0.2])
    np.testing.assert_allclose(log.tau, [0.0015, -0.0015])
    assert log.meta["ignored_columns"] == ["comment"]
    assert log.meta["converted_from"] == {"t": "ms", "f_t": "mN", "tau": "N mm"}


def test_csv_fast_and_line_by_line_readers_agree(tmp_path, monkeypatch):
    """The streaming pyarrow CSV path (in blocks of 16 MiB, and of 512 bytes: many blocks of
    a few rows each) and the line-by-line path read identical arrays."""
    import lugrip.io._csv as lio

    log = make_log(n=200, seed=9)
    path = write_log(log, tmp_path / "both.csv")
    fast = read_log(path)
    monkeypatch.setattr(lio, "STREAM_BLOCK_BYTES", 512)
    blocks = read_log(path)
    assert path.stat().st_size > 20 * 512
    monkeypatch.setattr(lio, "_read_csv_stream", lambda *a: (None, "test"))
    slow = read_log(path)
    assert_same(fast, slow)
    assert_same(blocks, slow)
    assert_same(log, slow)


def test_truncated_mcap_reads_what_is_complete(tmp_path, monkeypatch):
    """An MCAP cut short (crash while recording) reads its complete chunks, with a warning."""
    import mcap.writer

    class SmallChunks(mcap.writer.Writer):
        def __init__(self, output, **kw):
            super().__init__(output, **{**kw, "chunk_size": 4096})

    monkeypatch.setattr(mcap.writer, "Writer", SmallChunks)
    log = make_log(n=3000, seed=4, omega=False, maneuvers=0)
    whole = write_log(log, tmp_path / "whole.mcap").read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(whole[: len(whole) // 2])
    with pytest.warns(LogWarning, match="truncated or damaged MCAP"):
        part = read_log(cut)
    assert 0.3 * len(log) < len(part) < 0.7 * len(log)
    np.testing.assert_array_equal(part.f_n, log.f_n[: len(part)])
    np.testing.assert_allclose(part.t, log.t[: len(part)], rtol=0, atol=1e-9)


def test_semicolon_csv_and_blank_lines(tmp_path):
    """';'-separated files and blank lines are read; rows keep their line numbers."""
    p = tmp_path / "semi.csv"
    p.write_text("t;f_n;f_t;tau\n0;1;0.5;0\n\n0.1;1;0.5;0\n")
    assert len(read_log(p)) == 2
    err = csv_error(tmp_path, "t,f_n,f_t,tau\n0,1,0.5,0\n\n0.1,1,x,0\n")
    assert err.row == 4 and "row 4" in str(err) and "'f_t'" in str(err)


# ---------------------------------------------------------------------------------------------
# Malformed input: each message names file, row and column
# ---------------------------------------------------------------------------------------------

MALFORMED = [
    # (id, file text, row, column, words in the message)
    ("missing-tau", "t,f_n,f_x,f_y\n0,1,0,0\n", 1, "tau", ["missing", "t, f_n, f_x, f_y"]),
    ("missing-f_y", "t,f_n,f_x,tau\n0,1,0,0\n", 1, "f_y", ["missing"]),
    ("missing-force", "t,f_n,tau\n0,1,0\n", 1, "f_x/f_y or f_t", ["missing"]),
    ("non-numeric", rows(GOOD[0], GOOD[1], "0.004,abc,0.1,0.2,0.001,0,0"), 4, "f_n",
     ["'abc' is not a number"]),
    ("duplicated-time", rows(GOOD[0], GOOD[1], GOOD[1], GOOD[3]), 4, "t",
     ["duplicated time", "row 3"]),
    ("backwards-time", rows(GOOD[0], GOOD[2], GOOD[1], GOOD[3]), 4, "t",
     ["backwards", "row 3"]),
    ("nan-time", rows(GOOD[0], "nan,2,0.1,0.2,0.001,0,0"), 3, "t", ["finite time"]),
    ("nan-run", rows(GOOD[0], *[f"0.00{k},2,0.1,0.2,,0,0" for k in range(1, 6)],
                     "0.006,2,0,0,0,0,0"), 3, "tau", ["5 consecutive", "rows 3-7", "allow_gaps"]),
    ("negative-f_t", "t,f_n,f_t,tau\n0,1,0.5,0\n0.1,1,-0.5,0\n", 3, "f_t", ["magnitude"]),
    ("inconsistent-f_t", "t,f_n,f_x,f_y,f_t,tau\n0,1,3,4,5,0\n0.1,1,3,4,6,0\n", 3, "f_t",
     ["hypot"]),
    ("fractional-maneuver", rows(GOOD[0], "0.002,2,0.1,0.2,0.001,0,1.5"), 3, "maneuver",
     ["not an integer"]),
    ("inf-omega", rows(GOOD[0], "0.002,2,0.1,0.2,0.001,inf,0"), 3, "omega", ["NaN"]),
    ("negative-f_n", rows(*[g.replace(",2.", ",-2.") for g in GOOD]), None, "f_n",
     ["flip_normal=True"]),
    ("unknown-unit", "t,f_n,f_t,tau [furlong]\n0,1,0,0\n", 1, "tau", ["furlong", "N mm"]),
    ("duplicate-column", "t,f_n,f_t,tau,f_n\n0,1,0,0,1\n", 1, "f_n", ["twice"]),
    ("decimal-comma", "t;f_n;f_t;tau\n0;1,5;0;0\n", 2, "f_n", ["decimal comma"]),
]


@pytest.mark.parametrize("case", MALFORMED, ids=[c[0] for c in MALFORMED])
def test_malformed_csv_names_file_row_and_column(tmp_path, case):
    """Each malformed table gives a LogError naming the file, the row and the column."""
    _, text, row, column, words = case
    err = csv_error(tmp_path, text)
    msg = str(err)
    assert err.column == column and f"'{column}'" in msg
    if row is not None:
        assert err.row == row
        assert f"row {row}" in msg or f"rows {row}-" in msg
    else:
        assert err.row is not None and f"row {err.row}" in msg
    for word in words:
        assert word in msg, (word, msg)


def test_flip_normal_on_a_table(tmp_path):
    """flip_normal on a table rotates by pi about x: f_n, f_y, tau, omega change sign."""
    p = tmp_path / "raw.csv"
    p.write_text(rows(*[g.replace(",2.", ",-2.") for g in GOOD]))
    log = read_log(p, flip_normal=True)
    np.testing.assert_array_equal(log.f_n, [2.0, 2.1, 2.2, 2.3])
    np.testing.assert_array_equal(log.f_x, [0.1] * 4)
    np.testing.assert_array_equal(log.f_y, [-0.2] * 4)
    np.testing.assert_array_equal(log.tau, [-0.001] * 4)
    np.testing.assert_array_equal(log.omega, [-0.0, -0.1, -0.2, -0.3])


def test_ragged_row_and_missing_header(tmp_path):
    """A row with the wrong cell count, and a file without header, are named by row."""
    err = csv_error(tmp_path, rows(GOOD[0], "0.002,2,0.1"))
    assert err.row == 3 and "3 cells" in str(err) and "7 columns" in str(err)
    err = csv_error(tmp_path, "0,1,0.5,0\n0.1,1,0.5,0\n", name="nohead.csv")
    assert err.row == 1 and "no header" in str(err)


def test_empty_and_header_only_files(tmp_path):
    """Empty files and files without data rows are rejected, in every table format."""
    assert "empty file" in str(csv_error(tmp_path, "", name="empty.csv"))
    assert "empty file" in str(csv_error(tmp_path, "\n  \n", name="blank.csv"))
    assert "no data rows" in str(csv_error(tmp_path, HEADER, name="head.csv"))
    for suffix in (".parquet", ".mcap", ".bag"):
        p = tmp_path / f"empty{suffix}"
        p.write_bytes(b"")
        with pytest.raises(LogError, match="empty file") as info:
            read_log(p)
        assert str(p) in str(info.value)
    pa = pytest.importorskip("pyarrow")
    import pyarrow.parquet as pq

    p = tmp_path / "norows.parquet"
    pq.write_table(pa.table({c: pa.array([], pa.float64()) for c in ("t", "f_n", "f_t", "tau")}), p)
    with pytest.raises(LogError, match="no data rows"):
        read_log(p)


def test_unknown_suffix_missing_file_and_garbage(tmp_path):
    """Unknown suffixes list the known ones; a missing file is FileNotFoundError."""
    p = tmp_path / "log.xlsx"
    p.write_text("x")
    with pytest.raises(LogError, match=r"unknown file type '\.xlsx'.*\.csv.*\.mcap") as info:
        read_log(p)
    assert str(p) in str(info.value)
    with pytest.raises(FileNotFoundError):
        read_log(tmp_path / "nope.csv")
    for suffix in (".parquet", ".mcap"):
        bad = tmp_path / f"garbage{suffix}"
        bad.write_bytes(b"this is not a binary log at all" * 10)
        with pytest.raises(LogError, match="not a readable") as info:
            read_log(bad)
        assert str(bad) in str(info.value)
    # format= overrides the suffix
    txt = tmp_path / "log.txt"
    txt.write_text(rows(*GOOD))
    assert len(read_log(txt, format="csv")) == 4


def test_malformed_parquet_names_row_and_column(tmp_path):
    """Parquet rows are numbered as a spreadsheet shows them (header = row 1)."""
    pa = pytest.importorskip("pyarrow")
    import pyarrow.parquet as pq

    p = tmp_path / "bad.parquet"
    pq.write_table(pa.table({"t": [0.0, 0.1, 0.2], "f_n": ["1", "2", "x"], "f_t": [0.1] * 3,
                             "tau": [0.0] * 3}), p)
    with pytest.raises(LogError) as info:
        read_log(p)
    assert info.value.row == 4 and "row 4" in str(info.value) and "'f_n'" in str(info.value)
    p2 = tmp_path / "back.parquet"
    pq.write_table(pa.table({"t": [0.0, 0.2, 0.1], "f_n": [1.0] * 3, "f_t": [0.1] * 3,
                             "tau": [0.0] * 3}), p2)
    with pytest.raises(LogError, match=r"row 4, column 't'.*backwards"):
        read_log(p2)
    p3 = tmp_path / "cols.parquet"
    pq.write_table(pa.table({"time": [0.0], "f_n": [1.0], "f_t": [0.1], "tau": [0.0]}), p3)
    with pytest.raises(LogError, match=r"missing required column\(s\) 't'.*time, f_n"):
        read_log(p3)


def test_from_arrays_validation_names_sample_index():
    """In-memory logs are validated the same way; errors give the 0-based index."""
    with pytest.raises(LogError, match=r"<arrays>: sample 2 \(0-based index\), column 't'"):
        SlidingLog.from_arrays([0.0, 0.1, 0.1], [1.0] * 3, [0.0] * 3, f_t=[0.1] * 3)
    with pytest.raises(ValueError, match="differ in length"):
        SlidingLog.from_arrays([0.0, 0.1], [1.0] * 3, [0.0] * 3, f_t=[0.1] * 3)
    with pytest.raises(ValueError, match="f_x and f_y"):
        SlidingLog.from_arrays([0.0], [1.0], [0.0], f_x=[0.1])
    with pytest.raises(ValueError, match="1-D"):
        SlidingLog.from_arrays([[0.0]], [[1.0]], [[0.0]], f_t=[[0.1]])
    log = SlidingLog.from_arrays([0.0, 0.1], [1.0, 1.0], [0.0, 0.0], f_t=[0.1, 0.1])
    with pytest.raises(ValueError):
        log.t[0] = 5.0  # read-only arrays: the log is immutable


# ---------------------------------------------------------------------------------------------
# NaNs, gaps, no contact, segments
# ---------------------------------------------------------------------------------------------

def test_isolated_nan_warns_and_splits_segments(tmp_path):
    """An isolated NaN is kept with a warning naming its row, and segments() skip it."""
    p = tmp_path / "nan.csv"
    p.write_text(rows(GOOD[0], GOOD[1], "0.004,nan,0.1,0.2,0.001,0.2,0", GOOD[3]))
    with pytest.warns(LogWarning, match=r"nan\.csv: 1 non-finite sample.*row 4 \(f_n\)"):
        log = read_log(p)
    assert log.valid.tolist() == [True, True, False, True]
    assert log.segments() == [(0, 2), (3, 4)]


def test_long_nan_run_allowed_as_gap(tmp_path):
    """allow_gaps=True keeps a long dropout; segments() do not cross it."""
    t = np.arange(20) * 0.01
    tau = np.zeros(20)
    tau[5:12] = np.nan
    with pytest.raises(LogError, match="7 consecutive"):
        SlidingLog.from_arrays(t, np.ones(20), tau, f_t=np.ones(20) * 0.1)
    with pytest.warns(LogWarning):
        log = SlidingLog.from_arrays(t, np.ones(20), tau, f_t=np.ones(20) * 0.1,
                                     allow_gaps=True)
    assert log.segments() == [(0, 5), (12, 20)]
    with pytest.warns(LogWarning):
        relaxed = SlidingLog.from_arrays(t, np.ones(20), tau, f_t=np.ones(20) * 0.1,
                                         max_nan_run=7)
    assert len(relaxed) == 20


def test_no_contact_samples_warn_and_are_kept(tmp_path):
    """f_n <= 0 samples (no contact) are kept with a warning; they do not split segments."""
    p = tmp_path / "lift.csv"
    p.write_text(rows(GOOD[0], "0.002,0.0,0,0,0,0,0", "0.004,-0.01,0,0,0,0,0", GOOD[3]))
    with pytest.warns(LogWarning, match=r"2 sample\(s\) with f_n <= 0, first at row 3"):
        log = read_log(p)
    assert len(log) == 4 and log.segments() == [(0, 4)]


def test_segments_at_time_gaps_and_maneuvers():
    """segments() splits where dt exceeds max_gap and where the maneuver changes."""
    t = np.concatenate([np.arange(10) * 0.001, 1.0 + np.arange(10) * 0.001])
    man = np.r_[np.zeros(15, int), np.ones(5, int)]
    log = SlidingLog.from_arrays(t, np.ones(20), np.zeros(20), f_t=np.zeros(20), maneuver=man)
    assert log.segments() == [(0, 10), (10, 15), (15, 20)]
    assert log.segments(by_maneuver=False) == [(0, 10), (10, 20)]
    assert log.segments(max_gap=2.0, by_maneuver=False) == [(0, 20)]
    assert log.segments(min_length=6) == [(0, 10)]
    parts = log.split()
    assert [len(p) for p in parts] == [10, 5, 5]
    assert [(k, len(sub)) for k, sub in log.maneuvers()] == [(0, 15), (1, 5)]


def reference_segments(t, valid, man, max_gap):
    """Plain loop: the maximal runs of valid samples without a gap or maneuver change."""
    out, start = [], None
    for i in range(len(t)):
        joins = (start is not None and valid[i] and t[i] - t[i - 1] <= max_gap
                 and man[i] == man[i - 1])
        if start is not None and not joins:
            out.append((start, i))
            start = None
        if valid[i] and start is None:
            start = i
    if start is not None:
        out.append((start, len(t)))
    return out


@settings(max_examples=60, deadline=None)
@given(st.data())
def test_segments_match_a_plain_loop(data):
    """segments() equals a plain loop on random logs with NaNs, gaps and maneuvers."""
    n = data.draw(st.integers(1, 60))
    steps = data.draw(st.lists(st.sampled_from([0.001, 0.001, 0.001, 0.02]), min_size=n,
                               max_size=n))
    t = np.cumsum(steps)
    bad = np.array(data.draw(st.lists(st.booleans(), min_size=n, max_size=n)))
    man = np.array(data.draw(st.lists(st.integers(0, 2), min_size=n, max_size=n)))
    f_n = np.where(bad, np.nan, 1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LogWarning)
        log = SlidingLog.from_arrays(t, f_n, np.zeros(n), f_t=np.zeros(n), maneuver=man,
                                     allow_gaps=True)
    assert log.segments(0.005) == reference_segments(t, ~bad, man, 0.005)
    assert log.segments(0.005, by_maneuver=False) == reference_segments(t, ~bad, np.zeros(n),
                                                                        0.005)


def test_select_and_views():
    """select() takes masks, indices and slices; dt and len are per sample."""
    log = make_log(n=10, maneuvers=0)
    assert len(log) == 10 and log.dt.shape == (9,)
    np.testing.assert_array_equal(log.dt, np.diff(log.t))
    assert log.sample_period == pytest.approx(np.median(np.diff(log.t)))
    mask = log.f_n > 5
    sub = log.select(mask)
    np.testing.assert_array_equal(sub.f_x, log.f_x[mask])
    np.testing.assert_array_equal(log.select([0, 2]).tau, log.tau[[0, 2]])
    assert len(log.select(slice(2, 5))) == 3
    with pytest.raises(ValueError, match="mask"):
        log.select(np.ones(3, bool))


# ---------------------------------------------------------------------------------------------
# Units
# ---------------------------------------------------------------------------------------------

def si_log(n=1500, seed=5):
    return make_log(n=n, seed=seed, maneuvers=0, omega=False)


def scaled_csv(tmp_path, log, **factors):
    cols = {k: np.asarray(v, float) * factors.get(k, 1.0) for k, v in log.columns().items()}
    p = tmp_path / "scaled.csv"
    lines = [",".join(cols)]
    lines += [",".join(repr(float(x)) for x in row) for row in zip(*cols.values())]
    p.write_text("\n".join(lines) + "\n")
    return p


@pytest.mark.parametrize(("column", "factor", "unit", "hint"), [
    ("t", 1e3, "ms", "'t': 'ms'"),
    ("t", 1e9, "ns", "'t': 'ns'"),
    ("tau", 1e3, "N mm", "'tau': 'N mm'"),
    ("f_n", 1e3, "mN", "'f_n': 'mN'"),
    ("f_x", 1e3 / 9.80665 * 5, None, "'f_x': 'mN'"),
])
def test_wrong_units_are_caught_and_override_converts(tmp_path, column, factor, unit, hint):
    """Magnitudes in ms/ns, N mm or mN give an error suggesting the conversion; units= fixes."""
    log = si_log()
    if column == "f_x":  # lateral force in gram-force-like magnitudes: flagged as not newtons
        log = SlidingLog.from_arrays(log.t, log.f_n, log.tau, f_x=log.f_x + 100.0, f_y=log.f_y)
    p = scaled_csv(tmp_path, log, **{column: factor})
    with pytest.raises(LogError) as info:
        read_log(p)
    msg = str(info.value)
    assert str(p) in msg and f"column '{column}'" in msg and "row " in msg
    assert hint in msg
    if unit is not None:
        back = read_log(p, units={column: unit})
        np.testing.assert_allclose(getattr(back, column), getattr(log, column), rtol=1e-12,
                                   atol=1e-12 * factor)
        assert back.meta["converted_from"] == {column: unit}


def test_unit_override_declares_si_and_force_shorthand(tmp_path):
    """units={'col': SI} silences the guess; 'force' converts all forces; gf is g0/1000 N."""
    log = si_log()
    big = SlidingLog.from_arrays(log.t, log.f_n + 300.0, log.tau, f_x=log.f_x, f_y=log.f_y,
                                 check_units=False)
    p = write_log(big, tmp_path / "big.csv")
    with pytest.raises(LogError, match="newtons"):
        read_log(p)
    np.testing.assert_array_equal(read_log(p, units={"f_n": "N"}).f_n, big.f_n)
    assert len(read_log(p, check_units=False)) == len(big)
    p2 = scaled_csv(tmp_path, log, f_n=1 / 9.80665e-3, f_x=1 / 9.80665e-3, f_y=1 / 9.80665e-3)
    back = read_log(p2, units={"force": "gf"})
    np.testing.assert_allclose(back.f_n, log.f_n, rtol=1e-12)
    np.testing.assert_allclose(back.f_t, log.f_t, rtol=1e-12)
    with pytest.raises(LogError, match="unknown column 'torque'"):
        read_log(p2, units={"torque": "N mm"})


def test_plausible_si_logs_pass_the_unit_checks():
    """Real magnitudes (1 kHz, 0.2-16 N, tau up to mu*xi*rho*f_n ~ 1 cm * f_n) are accepted."""
    rng = np.random.default_rng(7)
    n = 5000
    f_n = rng.uniform(0.2, 16.0, n)
    tau = rng.uniform(-1, 1, n) * 0.01 * f_n
    log = SlidingLog.from_arrays(1e-3 * np.arange(n), f_n, tau, f_t=0.9 * f_n)
    assert len(log) == n


# ---------------------------------------------------------------------------------------------
# Writing: overwrite protection and atomicity
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".mcap"])
def test_never_overwrites_without_permission(tmp_path, suffix):
    """An existing file is left byte-for-byte untouched unless overwrite=True."""
    path = tmp_path / f"keep{suffix}"
    path.write_bytes(b"precious")
    with pytest.raises(FileExistsError) as info:
        write_log(make_log(n=5), path)
    assert str(path) in str(info.value)
    assert path.read_bytes() == b"precious"
    write_log(make_log(n=5), path, overwrite=True)
    assert len(read_log(path)) == 5
    assert sorted(os.listdir(tmp_path)) == [path.name]


def test_write_is_atomic(tmp_path, monkeypatch):
    """A failure while writing leaves neither a partial file nor a temporary file."""
    import lugrip.io._files as lio  # write_log's module

    def half_then_fail(log, fh):
        fh.write(b"t,f_n,f_t,tau\n0,1,")
        raise RuntimeError("disk full")

    monkeypatch.setattr(lio, "_write_csv", half_then_fail)
    with pytest.raises(RuntimeError, match="disk full"):
        write_log(make_log(n=5), tmp_path / "new.csv")
    assert os.listdir(tmp_path) == []
    old = tmp_path / "old.csv"
    old.write_text("original")
    with pytest.raises(RuntimeError):
        write_log(make_log(n=5), old, overwrite=True)
    assert old.read_text() == "original" and os.listdir(tmp_path) == ["old.csv"]


def test_write_rejects_unknown_format(tmp_path):
    """write_log writes CSV, Parquet and MCAP only and says so."""
    with pytest.raises(LogError, match="csv, parquet, mcap") as info:
        write_log(make_log(n=3), tmp_path / "x.bag")
    assert str(tmp_path / "x.bag") in str(info.value)
    assert os.listdir(tmp_path) == []


# ---------------------------------------------------------------------------------------------
# Property test: random valid logs round-trip
# ---------------------------------------------------------------------------------------------

finite = st.floats(allow_nan=False, allow_infinity=False, width=64)


@st.composite
def valid_logs(draw):
    n = draw(st.integers(1, 40))
    steps = draw(st.lists(st.floats(1e-5, 0.05), min_size=n, max_size=n))
    t = draw(st.floats(-10.0, 1e4)) + np.cumsum(steps)
    if len(np.unique(t)) < n or np.any(np.diff(t) <= 0):
        t = np.arange(n) * 1e-3
    f_n = np.array(draw(st.lists(st.floats(0.01, 100.0), min_size=n, max_size=n)))
    # |tau| / f_n <= 5 mm and f_n <= 100 N: |tau| <= 0.5 N m, never flagged by the unit check
    frac = np.array(draw(st.lists(st.floats(-0.005, 0.005), min_size=n, max_size=n)))
    kw = {}
    if draw(st.booleans()):
        kw["f_x"] = np.array(draw(st.lists(st.floats(-50, 50), min_size=n, max_size=n)))
        kw["f_y"] = np.array(draw(st.lists(st.floats(-50, 50), min_size=n, max_size=n)))
    else:
        kw["f_t"] = np.array(draw(st.lists(st.floats(0, 50), min_size=n, max_size=n)))
    if draw(st.booleans()):
        kw["omega"] = np.array(draw(st.lists(st.one_of(finite, st.just(math.nan)),
                                             min_size=n, max_size=n)))
    if draw(st.booleans()):
        kw["maneuver"] = np.array(draw(st.lists(st.integers(-2**40, 2**40), min_size=n,
                                                max_size=n)))
    return SlidingLog.from_arrays(t, f_n, frac * f_n, **kw)


@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(log=valid_logs())
def test_random_valid_logs_round_trip(tmp_path, log):
    """Random valid logs come back bit-identical from CSV and Parquet."""
    suffixes = [".csv"]
    try:
        import pyarrow  # noqa: F401

        suffixes.append(".parquet")
    except ImportError:
        pass
    for suffix in suffixes:
        path = write_log(log, tmp_path / f"prop{suffix}", overwrite=True)
        back = read_log(path)
        assert_same(log, back)
        if log.omega is not None:
            np.testing.assert_array_equal(np.isnan(back.omega), np.isnan(log.omega))


# ---------------------------------------------------------------------------------------------
# MCAP topics and ROS bags (written with rosbags' own serializer: an independent encoder)
# ---------------------------------------------------------------------------------------------

def test_mcap_topic_errors_list_the_topics(tmp_path):
    """A missing or wrongly typed topic names the file and lists the topics present."""
    path = write_log(make_log(n=20), tmp_path / "t.mcap")
    with pytest.raises(LogError, match=r"no topic '/ft'.*/lugrip/wrench \(geometry_msgs/"
                                       r"WrenchStamped, 20 messages\)") as info:
        read_log(path, wrench_topic="/ft")
    assert str(path) in str(info.value)
    with pytest.raises(LogError, match=r"no topic '/odom' \(omega_topic=\)"):
        read_log(path, omega_topic="/odom")
    with pytest.raises(LogError, match=r"'/lugrip/maneuver' has type std_msgs/Int32"):
        read_log(path, wrench_topic="/lugrip/maneuver")


def _typestore(ros1: bool):
    typesys = pytest.importorskip("rosbags.typesys", reason="rosbags not installed")
    return typesys.get_typestore(typesys.Stores.ROS1_NOETIC if ros1
                                 else typesys.Stores.ROS2_HUMBLE)


def _wrench(ts, ros1, stamp_ns, force, torque):
    T = ts.types
    sec, nsec = divmod(int(stamp_ns), 1_000_000_000)
    stamp = T["builtin_interfaces/msg/Time"](sec=sec, nanosec=nsec)
    header = (T["std_msgs/msg/Header"](seq=0, stamp=stamp, frame_id="ft") if ros1
              else T["std_msgs/msg/Header"](stamp=stamp, frame_id="ft"))
    V = T["geometry_msgs/msg/Vector3"]
    return T["geometry_msgs/msg/WrenchStamped"](
        header=header, wrench=T["geometry_msgs/msg/Wrench"](force=V(*force), torque=V(*torque)))


def _ros_samples(n=400, rate=500.0, t0_ns=1_700_000_000_000_000_000):
    rng = np.random.default_rng(11)
    stamps = t0_ns + np.round(np.arange(n) / rate * 1e9).astype(np.int64)
    force = np.c_[rng.uniform(-1, 1, (n, 2)), rng.uniform(1, 8, n)]
    torque = np.c_[rng.uniform(-0.1, 0.1, (n, 2)), rng.uniform(-0.005, 0.005, n)]
    return stamps, force, torque


def _write_bag(path, *, ros1, stamps, force, torque, omega=None, storage="sqlite3",
               extra_wrench_topic=False):
    ts = _typestore(ros1)
    if ros1:
        from rosbags.rosbag1 import Writer

        writer = Writer(path)
        ser = ts.serialize_ros1
    else:
        from rosbags.rosbag2 import StoragePlugin, Writer

        writer = Writer(path, version=9, storage_plugin=StoragePlugin[storage.upper()])
        ser = ts.serialize_cdr
    wtype = "geometry_msgs/msg/WrenchStamped"
    with writer:
        wc = writer.add_connection("/ft/wrench", wtype, typestore=ts)
        for s, f, tq in zip(stamps, force, torque):
            writer.write(wc, int(s) + 1000, ser(_wrench(ts, ros1, s, f, tq), wtype))
        if extra_wrench_topic:
            ec = writer.add_connection("/other/wrench", wtype, typestore=ts)
            writer.write(ec, int(stamps[0]), ser(_wrench(ts, ros1, stamps[0], force[0], torque[0]),
                                                 wtype))
        if omega is not None:
            o_ns, o_val = omega
            oc = writer.add_connection("/truth/omega", "std_msgs/msg/Float64", typestore=ts)
            F = ts.types["std_msgs/msg/Float64"]
            for s, v in zip(o_ns, o_val):
                writer.write(oc, int(s), ser(F(data=float(v)), "std_msgs/msg/Float64"))


@pytest.mark.parametrize("kind", ["ros1", "ros2-sqlite3", "ros2-mcap"])
def test_ros_bags_read_without_ros(tmp_path, kind):
    """ROS 1 and ROS 2 bags: f_n = force.z, tau = torque.z, header stamps, omega resampled."""
    ros1 = kind == "ros1"
    _typestore(ros1)
    stamps, force, torque = _ros_samples()
    o_ns = stamps[0] - 10_000_000 + np.arange(0, 700_000_000, 5_000_000)  # 200 Hz, shorter
    o_val = np.sin(7.0 * (o_ns - stamps[0]) / 1e9)
    path = tmp_path / ("rec.bag" if ros1 else "rec")
    _write_bag(path, ros1=ros1, stamps=stamps, force=force, torque=torque,
               omega=(o_ns, o_val), storage=kind.split("-")[-1])
    log = read_log(path, omega_topic="/truth/omega")
    assert log.meta["format"] == ("ros1" if ros1 else "ros2")
    assert log.meta["wrench_topic"] == "/ft/wrench" and log.meta["time_source"] == "header"
    assert log.meta["t0_ns"] == int(stamps[0])
    np.testing.assert_allclose(log.t, (stamps - stamps[0]) / 1e9, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(log.f_n, force[:, 2])
    np.testing.assert_array_equal(log.f_x, force[:, 0])
    np.testing.assert_array_equal(log.f_y, force[:, 1])
    np.testing.assert_array_equal(log.tau, torque[:, 2])
    np.testing.assert_allclose(log.f_t, np.hypot(force[:, 0], force[:, 1]))
    # omega: linear interpolation of sin(7 t) sampled at 200 Hz: error <= h^2/8 * 49
    inside = log.t <= (o_ns[-1] - stamps[0]) / 1e9
    assert inside.sum() < len(log)  # the omega topic ends early: NaN after it
    assert np.all(np.isnan(log.omega[~inside]))
    err = np.abs(log.omega[inside] - np.sin(7.0 * log.t[inside]))
    assert err.max() <= 0.005**2 / 8 * 49 + 1e-12
    if not ros1:  # the storage file alone is read through its bag
        storage = next(p for p in path.iterdir() if p.suffix in (".db3", ".mcap"))
        assert len(read_log(storage)) == len(stamps)


def test_ros_flip_normal_and_topic_choice(tmp_path):
    """flip_normal turns a sensor whose z points out of the contact into f_n > 0 (rotation by
    pi about x: f_y, f_n, tau flip, f_x stays); several wrench topics need wrench_topic=."""
    _typestore(False)
    stamps, force, torque = _ros_samples(n=50)
    force[:, 2] *= -1.0
    path = tmp_path / "flip"
    _write_bag(path, ros1=False, stamps=stamps, force=force, torque=torque,
               extra_wrench_topic=True)
    with pytest.raises(LogError, match=r"2 wrench topics \(/ft/wrench, /other/wrench\)"):
        read_log(path)
    with pytest.raises(LogError, match=r"message \d+ on topic '/ft/wrench', field "
                                       r"wrench\.force\.z \(column 'f_n'\).*flip_normal=True"):
        read_log(path, wrench_topic="/ft/wrench")
    log = read_log(path, wrench_topic="/ft/wrench", flip_normal=True)
    np.testing.assert_array_equal(log.f_n, -force[:, 2])
    np.testing.assert_array_equal(log.f_x, force[:, 0])
    np.testing.assert_array_equal(log.f_y, -force[:, 1])
    np.testing.assert_array_equal(log.tau, -torque[:, 2])
    assert np.all(log.f_n > 0) and log.meta["flip_normal"] is True


def test_ros_duplicated_stamp_is_dropped_with_a_warning(tmp_path):
    """A duplicated header stamp drops that message (first of the time kept) with a warning
    naming the message and topic; the rest of the bag is read, not rejected."""
    _typestore(True)
    stamps, force, torque = _ros_samples(n=10)
    stamps[6] = stamps[5]
    path = tmp_path / "dup.bag"
    _write_bag(path, ros1=True, stamps=stamps, force=force, torque=torque)
    with pytest.warns(LogWarning, match=r"topic '/ft/wrench': 1 message\(s\) with a "
                                        r"duplicated time, first message 7") as rec:
        log = read_log(path)
    assert str(path) in str(rec[0].message)
    keep = np.r_[0:6, 7:10]
    assert len(log) == 9
    np.testing.assert_array_equal(log.f_n, force[keep, 2])
    np.testing.assert_array_equal(log.tau, torque[keep, 2])

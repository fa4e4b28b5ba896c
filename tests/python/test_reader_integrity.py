"""The log readers verify what the format offers and refuse corrupted data per file, naming the
file and the field (docs/reliability.md, "Readers"): MCAP chunk and data-section CRCs, the
channel's schema name, encoding and definition against the standard message type. Files are
generated in the tests; the user's files are checked byte for byte after each refusal."""

from __future__ import annotations

import hashlib
import struct
import sys
import zlib

import numpy as np
import pytest

pytest.importorskip("mcap")
pytest.importorskip("rosbags")
from lugrip import ContactParams, LogError, read_log, write_log
from lugrip.cli import main
from lugrip.sliding import simulate_maneuvers
from mcap.writer import CompressionType, Writer

WRENCH = "geometry_msgs/msg/WrenchStamped"


def _sha(path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture(scope="module")
def log():
    return simulate_maneuvers(ContactParams.table1(), 2, seed=1).log


def _uncompressed(path, log, monkeypatch):
    """write_log without zstandard: an uncompressed chunk (the issue's case)."""
    with monkeypatch.context() as m:
        m.setitem(sys.modules, "zstandard", None)
        write_log(log, path, overwrite=True)
    return path


def _flip_value(raw: bytearray, value: float, factor: float = 1000.0) -> int:
    """Replace the first little-endian copy of ``value`` in ``raw`` by value * factor."""
    i = raw.find(struct.pack("<d", value))
    assert i > 0
    raw[i:i + 8] = struct.pack("<d", value * factor)
    return i



def test_chunk_crc_mismatch_is_refused(exit_2, tmp_path, monkeypatch, log):
    """Two values changed in an uncompressed chunk (f_n 1970 N for 1.97 N was read as valid):
    exit 2 naming the file and Chunk.uncompressed_crc; the intact file still reads."""
    good = _uncompressed(tmp_path / "good.mcap", log, monkeypatch)
    assert len(read_log(good)) == len(log)
    raw = bytearray(good.read_bytes())
    _flip_value(raw, float(log.f_n[10]))
    _flip_value(raw, float(log.f_n[11]))
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(bytes(raw))
    before = _sha(bad)
    with pytest.raises(LogError, match="Chunk.uncompressed_crc"):
        read_log(bad)
    err = exit_2(["observe", bad, "--preset", "table1", "--out", tmp_path / "e.csv"])
    assert "bad.mcap" in err and "uncompressed_crc" in err and "corrupted" in err
    assert _sha(bad) == before and not (tmp_path / "e.csv").exists()


def _unchunked(path, log):
    """The wrench messages written outside chunks (only the data-section CRC covers them)."""
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    T = ts.types
    V = T["geometry_msgs/msg/Vector3"]
    with open(path, "wb") as fh:
        w = Writer(fh, use_chunking=False, compression=CompressionType.NONE,
                   enable_data_crcs=True)
        w.start(profile="ros2", library="test")
        sid = w.register_schema(name=WRENCH, encoding="ros2msg",
                                data=ts.generate_msgdef(WRENCH, ros_version=2)[0].encode())
        cid = w.register_channel(topic="/wrench", message_encoding="cdr", schema_id=sid)
        for i in range(len(log)):
            ns = 1_000_000_000 + int(np.rint(log.t[i] * 1e9))
            hdr = T["std_msgs/msg/Header"](
                stamp=T["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9),
                frame_id="pad")
            msg = T[WRENCH](header=hdr, wrench=T["geometry_msgs/msg/Wrench"](
                force=V(0.0, float(log.f_t[i]), float(log.f_n[i])),
                torque=V(0.0, 0.0, float(log.tau[i]))))
            w.add_message(channel_id=cid, log_time=ns, publish_time=ns,
                          data=bytes(ts.serialize_cdr(msg, WRENCH)), sequence=i)
        w.finish()
    return path


def test_data_section_crc_mismatch_is_refused(tmp_path, log):
    ok = _unchunked(tmp_path / "ok.mcap", log)
    raw = ok.read_bytes()
    marker = b"\x0f" + struct.pack("<Q", 4)  # the DataEnd record: opcode 0x0F, length 4
    i = raw.rfind(marker)
    stored = struct.unpack("<I", raw[i + 9:i + 13])[0]
    assert stored == zlib.crc32(raw[:i]) != 0  # the file has a data-section CRC
    assert len(read_log(ok)) == len(log)  # and it is accepted
    bad_raw = bytearray(raw)
    _flip_value(bad_raw, float(log.f_n[100]))
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(bytes(bad_raw))
    with pytest.raises(LogError, match="DataEnd.data_section_crc") as info:
        read_log(bad)
    assert info.value.file == str(bad)


def _one_channel(path, *, schema_name=WRENCH, schema_encoding="ros2msg", schema_text="",
                 message_encoding="cdr", payload=None, n=20):
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    F = ts.types["std_msgs/msg/Float64"]
    payload = payload or (lambda i: bytes(ts.serialize_cdr(F(data=float(i)),
                                                            "std_msgs/msg/Float64")))
    with open(path, "wb") as fh:
        w = Writer(fh, compression=CompressionType.NONE)
        w.start(profile="ros2", library="test")
        sid = w.register_schema(name=schema_name, encoding=schema_encoding,
                                data=schema_text.encode())
        cid = w.register_channel(topic="/wrench", message_encoding=message_encoding,
                                 schema_id=sid)
        for i in range(n):
            w.add_message(channel_id=cid, log_time=2_000_000 * i, publish_time=2_000_000 * i,
                          data=payload(i), sequence=i)
        w.finish()
    return path


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({}, "message 1 on topic '/wrench'"),  # Float64 bytes under a WrenchStamped channel
        ({"schema_text": "float64 data\n"}, "schema.data"),
        ({"schema_text": "std_msgs/Header header\ngeometry_msgs/Vector3 wrench\n"},
         "schema.data"),
        ({"schema_encoding": "ros1msg"}, "schema.encoding"),
        ({"schema_text": "this is not a message definition %%%\n"}, "schema.data"),
    ],
    ids=["float-bytes", "schema-float64", "schema-wrong-nested", "schema-ros1", "schema-junk"],
)
def test_channel_that_is_not_the_declared_type_is_refused(exit_2, tmp_path, kwargs, field):
    path = _one_channel(tmp_path / "w.mcap", **kwargs)
    with pytest.raises(LogError) as info:
        read_log(path)
    assert field in str(info.value) and str(path) in str(info.value)
    err = exit_2(["observe", path, "--preset", "table1", "--out", tmp_path / "e.csv"])
    assert field in err


def test_trailing_bytes_after_a_wrench_are_refused(tmp_path, log):
    """A WrenchStamped payload with 8 extra bytes: the message size does not match the type."""
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    T = ts.types
    V = T["geometry_msgs/msg/Vector3"]

    def payload(i):
        hdr = T["std_msgs/msg/Header"](stamp=T["builtin_interfaces/msg/Time"](
            sec=1, nanosec=2_000_000 * i), frame_id="pad")
        msg = T[WRENCH](header=hdr, wrench=T["geometry_msgs/msg/Wrench"](
            force=V(0.0, 0.1, 2.0), torque=V(0.0, 0.0, 0.0)))
        return bytes(ts.serialize_cdr(msg, WRENCH)) + b"\x00" * 8

    path = _one_channel(tmp_path / "t.mcap",
                        schema_text=ts.generate_msgdef(WRENCH, ros_version=2)[0],
                        payload=payload)
    with pytest.raises(LogError, match="size mismatch"):
        read_log(path)


def test_standard_schema_text_is_accepted(tmp_path, log):
    """The standard definition (as recorders store it) passes the schema check."""
    path = write_log(log, tmp_path / "ok.mcap")
    out = read_log(path)
    assert np.allclose(out.f_n, log.f_n)


def test_a_recording_cut_short_still_reads_with_a_warning(tmp_path, log):
    """Truncation (a crash) is not corruption: the complete chunks read, with a warning."""
    from lugrip import LogWarning

    path = tmp_path / "cut.mcap"
    data = simulate_maneuvers(ContactParams.table1(), 6, seed=2).log
    write_log(data, path)
    raw = path.read_bytes()
    # cut inside the summary section (after DataEnd): every message was read and checked
    marker = b"\x0f" + struct.pack("<Q", 4)
    end = raw.rfind(marker) + 13
    cut = tmp_path / "cut2.mcap"
    cut.write_bytes(raw[: end + 20])
    with pytest.warns(LogWarning, match="truncated"):
        out = read_log(cut)
    assert len(out) == len(data)


# --- ROS time stamps ----------------------------------------------------------------------------

def _stamped(path, log, stamps_ns, log_ns=None, metadata=None):
    """The log as WrenchStamped messages with the given header stamps; log times increasing
    at the log's rate (what a recorder sees when the sensor's clock misbehaves); `metadata`:
    lugrip's ``lugrip.sliding_log`` record, written before the messages."""
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    T = ts.types
    V = T["geometry_msgs/msg/Vector3"]
    if log_ns is None:
        log_ns = 1_000_000_000 + np.round(log.t * 1e9).astype(np.int64)
    with open(path, "wb") as fh:
        w = Writer(fh, compression=CompressionType.NONE)
        w.start(profile="ros2", library="test")
        sid = w.register_schema(name=WRENCH, encoding="ros2msg",
                                data=ts.generate_msgdef(WRENCH, ros_version=2)[0].encode())
        cid = w.register_channel(topic="/ft", message_encoding="cdr", schema_id=sid)
        if metadata is not None:
            w.add_metadata("lugrip.sliding_log", metadata)
        for i in range(len(log)):
            s = int(stamps_ns[i])
            hdr = T["std_msgs/msg/Header"](stamp=T["builtin_interfaces/msg/Time"](
                sec=s // 10**9, nanosec=s % 10**9), frame_id="pad")
            msg = T[WRENCH](header=hdr, wrench=T["geometry_msgs/msg/Wrench"](
                force=V(0.0, float(log.f_t[i]), float(log.f_n[i])),
                torque=V(0.0, 0.0, float(log.tau[i]))))
            w.add_message(channel_id=cid, log_time=int(log_ns[i]), publish_time=int(log_ns[i]),
                          data=bytes(ts.serialize_cdr(msg, WRENCH)), sequence=i)
        w.finish()
    return path


def test_header_clock_jumping_back_is_an_error_with_a_log_time_option(exit_2, tmp_path, log):
    """The sensor clock jumps back 10 s at sample 500 (it interleaved samples 10 s apart with
    a warning): exit 2 naming the topic and the count; --time-source log reads it in order."""
    stamps = 5_000_000_000 + np.round(log.t * 1e9).astype(np.int64)
    stamps[500:] -= 10_000_000_000
    path = _stamped(tmp_path / "jump.mcap", log, stamps)
    with pytest.raises(LogError, match=r"topic '/ft'.*go backwards at 1 of \d+ messages, "
                                       r"first at message 501 \(by 9.998 s") as info:
        read_log(path)
    assert "time_source='log'" in str(info.value)
    err = exit_2(["observe", path, "--preset", "table1", "--out", tmp_path / "e.csv"])
    assert "'/ft'" in err and "--time-source log" in err
    got = read_log(path, time_source="log")
    assert len(got) == len(log) and np.all(np.diff(got.t) > 0)
    np.testing.assert_allclose(got.t - got.t[0], log.t - log.t[0], atol=1e-9)
    assert got.meta["time_source"] == "log"
    assert main(["observe", str(path), "--preset", "table1", "--out", str(tmp_path / "e.csv"),
                 "--time-source", "log"]) == 0


def test_identical_stamps_are_an_error_not_one_sample(exit_2, tmp_path, log):
    """Every header stamp identical (the recording became one sample, exit 0): exit 2 naming
    the topic and the count; by log time the recording reads whole."""
    stamps = np.full(len(log), 7_000_000_000, dtype=np.int64)
    path = _stamped(tmp_path / "same.mcap", log, stamps)
    n = len(log)
    with pytest.raises(LogError, match=rf"topic '/ft'.*{n - 1} of {n} messages"):
        read_log(path)
    exit_2(["observe", path, "--preset", "table1", "--out", tmp_path / "e.csv"])
    assert len(read_log(path, time_source="log")) == n


def test_duplicated_stamps_up_to_the_stated_fraction_are_dropped(tmp_path, log):
    """1 % of the messages duplicated: dropped with a warning; one more: an error."""
    from lugrip import LogWarning
    from lugrip.io._ros import MAX_DUPLICATE_FRACTION

    n = len(log)
    allowed = int(MAX_DUPLICATE_FRACTION * n)
    base = 5_000_000_000 + np.round(log.t * 1e9).astype(np.int64)
    stamps = base.copy()
    idx = np.arange(1, n, n // (allowed + 2))[: allowed + 1]
    stamps[idx[:allowed]] = stamps[idx[:allowed] - 1]
    with pytest.warns(LogWarning, match=rf"{allowed} message\(s\) with a duplicated time"):
        got = read_log(_stamped(tmp_path / "few.mcap", log, stamps))
    assert len(got) == n - allowed
    stamps[idx] = base[idx - 1]
    with pytest.raises(LogError, match=rf"{allowed + 1} of {n} messages"):
        read_log(_stamped(tmp_path / "many.mcap", log, stamps))


def test_time_source_applies_to_ros_sources_only(tmp_path, log):
    path = write_log(log, tmp_path / "x.csv")
    with pytest.raises(LogError, match="time_source"):
        read_log(path, time_source="log")
    with pytest.raises(LogError, match="time_source 'clock'"):
        read_log(write_log(log, tmp_path / "x.mcap"), time_source="clock")


# --- per-block unit plausibility -----------------------------------------------------------

@pytest.fixture(scope="module")
def long_log():
    return simulate_maneuvers(ContactParams.table1(), 40, seed=3).log


def _mixed_csv(path, log, column: str, factor: float, start: float, frac: float):
    """The log as CSV with ``column`` multiplied by ``factor`` in a block of rows."""
    write_log(log, path, overwrite=True)
    lines = path.read_text().splitlines()
    ci = lines[0].split(",").index(column)
    n = len(lines) - 1
    a, b = int(start * n), int(start * n) + int(frac * n)
    for i in range(1 + a, 1 + b):
        f = lines[i].split(",")
        f[ci] = repr(float(f[ci]) * factor)
        lines[i] = ",".join(f)
    path.write_text("\n".join(lines) + "\n")
    return path, a + 2, b + 1  # the block's first and last row as a spreadsheet counts them


@pytest.mark.parametrize(
    ("column", "factor", "frac", "what"),
    [("tau", 1000.0, 0.05, "N mm"), ("tau", 1000.0, 0.01, "N mm"),
     ("f_n", 1000.0, 0.05, "mN"), ("f_y", 1000.0, 0.05, "mN")],
    ids=["tau-Nmm-5pct", "tau-Nmm-1pct", "f_n-mN-5pct", "f_y-mN-5pct"],
)
def test_a_block_in_other_units_is_refused(exit_2, tmp_path, long_log, column, factor, frac,
                                           what):
    """τ in N mm in a 5 % block of rows passed observe (ω̂ RMSE 37.9 rad/s): exit 2, one line
    naming the field and rows that overlap the block; the clean file still reads."""
    clean = write_log(long_log, tmp_path / "clean.csv")
    assert len(read_log(clean)) == len(long_log)
    path, first, last = _mixed_csv(tmp_path / "mixed.csv", long_log, column, factor, 0.5, frac)
    before = _sha(path)
    with pytest.raises(LogError, match=rf"mixed units: {column} in rows") as info:
        read_log(path)
    e = info.value
    assert e.column == column and what in str(e)
    lo, hi = (int(x) for x in str(e).split(" in rows ")[1].split(" ")[0].split("-"))
    assert lo <= last and hi >= first  # the rows named overlap the block
    assert hi - lo < 3 * (last - first + 1) + 400  # and are the block, not the whole file
    err = exit_2(["observe", path, "--preset", "table1", "--out", tmp_path / "e.csv"])
    assert "mixed units" in err and column in err
    assert _sha(path) == before
    # the user declares the column's unit: the check is theirs to skip
    read_log(path, check_units=False)


def test_clean_files_of_other_rigs_pass_the_block_checks(tmp_path):
    """No false alarm on synthetic logs of several parameter sets and noise levels."""
    from lugrip import PRESETS

    for k, name in enumerate(PRESETS):
        log = simulate_maneuvers(ContactParams.preset(name), 12, seed=10 + k,
                                 noise=(0.05, 1e-4)).log
        assert len(read_log(write_log(log, tmp_path / f"{name}.csv"))) == len(log)


@pytest.mark.parametrize("t0", ["abc", "1e9", "99999999999999999999999999999"])
def test_bad_metadata_t0_names_the_file_and_field(exit_2, tmp_path, log, t0):
    """lugrip's MCAP metadata record with a t0_ns that is not an integer (a ValueError that
    named no file): exit 2 naming the file and the field."""
    stamps = 10**9 + np.round(log.t * 1e9).astype(np.int64)
    path = _stamped(tmp_path / "meta.mcap", log, stamps,
                    metadata={"wrench_topic": "/ft", "t0_ns": t0})
    with pytest.raises(LogError, match="t0_ns"):
        read_log(path)
    err = exit_2(["observe", path, "--preset", "table1", "--out", tmp_path / "e.csv"])
    assert "meta.mcap" in err and "t0_ns" in err


def _bag_with_definition(path, msgdef: str, payload):
    from rosbags.rosbag1 import Writer as BagWriter
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    own = get_typestore(Stores.EMPTY)
    own.register(get_types_from_msg(msgdef, WRENCH))
    with BagWriter(path) as w:
        c = w.add_connection("/ft", WRENCH, msgdef=msgdef,
                             md5sum=own.generate_msgdef(WRENCH)[1])
        for i in range(30):
            w.write(c, 10**9 + 2_000_000 * i, payload(i))
    return path


# WrenchStamped with float32 vectors: the field names of the standard message, other numbers
_F32 = ("std_msgs/Header header\ngeometry_msgs/Wrench wrench\n" + "=" * 80 +
        "\nMSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id\n" + "=" * 80 +
        "\nMSG: geometry_msgs/Wrench\ngeometry_msgs/Vector3 force\ngeometry_msgs/Vector3 torque\n"
        + "=" * 80 + "\nMSG: geometry_msgs/Vector3\nfloat32 x\nfloat32 y\nfloat32 z\n")


def test_bag_with_a_non_standard_definition_is_refused(exit_2, tmp_path):
    """A ROS 1 bag whose WrenchStamped definition has float32 vectors (the standard field
    names, another layout): not the standard message, refused as in MCAP files, naming the
    topic and the msgdef (it was read by its own definition)."""
    pytest.importorskip("rosbags.rosbag1")

    def payload(i):
        head = struct.pack("<III", i, 1, 2_000_000 * i) + struct.pack("<I", 1) + b"p"
        return head + struct.pack("<6f", 0.0, 0.1, 2.0, 0.0, 0.0, 1e-4)

    path = _bag_with_definition(tmp_path / "f32.bag", _F32, payload)
    with pytest.raises(LogError, match=r"topic '/ft'.*geometry_msgs/Vector3.*field msgdef"):
        read_log(path)
    err = exit_2(["observe", path, "--preset", "table1", "--out", tmp_path / "e.csv"])
    assert "f32.bag" in err and "msgdef" in err


@pytest.mark.parametrize("q", [50.0, 90.0])
def test_window_percentiles_match_numpy(q):
    """The per-block statistic (one sort per window) equals np.percentile of each window's
    used samples; windows with fewer than a quarter used are NaN."""
    from lugrip.io._log import _window_stat

    rng = np.random.default_rng(1)
    x = rng.lognormal(size=10_037)
    use = rng.random(x.size) > 0.3
    use[400:600] = False  # a window without enough samples
    starts, stat = _window_stat(x, use, 200, q)
    for s, v in zip(starts, stat):
        sel = x[s:s + 200][use[s:s + 200]]
        if sel.size >= 50:
            assert v == pytest.approx(np.percentile(sel, q), rel=1e-12)
        else:
            assert np.isnan(v)
    assert starts[-1] == x.size - 200

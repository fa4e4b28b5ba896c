"""MCAP recordings: read with mcap's stream reader, messages decoded by mcap-ros2-support when
it is installed, else by rosbags' typestore (ROS 2 CDR or ROS 1); written as ROS 2 CDR through
the typestore."""

from __future__ import annotations

import json
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from ._extras import decode_error_text, exc_text, need
from ._log import UNITS, LogError, LogWarning, SlidingLog
from ._ros import (
    _DEFAULT_MANEUVER_TOPIC,
    _DEFAULT_OMEGA_TOPIC,
    _DEFAULT_WRENCH_TOPIC,
    _MCAP_META,
    _TYPES,
    MAX_MESSAGES,
    RosSource,
    full_type,
    short_type,
)


def typestore(ros1: bool = False):
    """rosbags' typestore with the standard message types (ROS 1 Noetic or ROS 2 Humble)."""
    typesys = need("rosbags.typesys", "decoding ROS messages")
    return typesys.get_typestore(typesys.Stores.ROS1_NOETIC if ros1
                                 else typesys.Stores.ROS2_HUMBLE)


class _Decoders:
    """One decoding function per channel: mcap-ros2-support's when importable (ros2msg schemas,
    CDR), else rosbags' typestore, registering types the schema defines that it lacks."""

    def __init__(self, file: str):
        self.file = file
        try:
            from mcap_ros2.decoder import DecoderFactory
            self._ros2 = DecoderFactory()
        except ImportError:
            self._ros2 = None
        self._stores: dict[bool, Any] = {}

    def _store(self, ros1: bool, typename: str, schema_text: str):
        if ros1 not in self._stores:
            self._stores[ros1] = typestore(ros1)
        ts = self._stores[ros1]
        if typename not in ts.types and schema_text:
            typesys = need("rosbags.typesys", "decoding ROS messages")
            ts.register(typesys.get_types_from_msg(schema_text, typename))
        return ts

    def for_channel(self, encoding: str, schema) -> Any:
        typename = full_type(schema.name)
        text = schema.data.decode("utf-8", "replace")
        if encoding == "cdr":
            if short_type(schema.name) in _TYPES:
                # the types a sliding log reads: their schema was checked against the standard
                # definition (_check_schema), and rosbags' decoder refuses a message whose
                # size does not match the type (mcap-ros2's ignores trailing bytes)
                ts = self._store(False, typename, "")
                return lambda data: ts.deserialize_cdr(data, typename)
            if self._ros2 is not None and schema.encoding == "ros2msg":
                decoder = self._ros2.decoder_for(encoding, schema)
                if decoder is not None:
                    return decoder
            ts = self._store(False, typename, text)
            return lambda data: ts.deserialize_cdr(data, typename)
        if encoding == "ros1":
            ts = self._store(True, typename, text)
            return lambda data: ts.deserialize_ros1(data, typename)
        raise LogError(self.file, f"channel of type {short_type(schema.name)} is encoded as "
                       f"{encoding!r}; only ROS 1 and ROS 2 (CDR) messages can be read")


_SCHEMA_ENCODING = {"cdr": "ros2msg", "ros1": "ros1msg"}  # message encoding -> schema encoding


def _check_schema(file: str, topic: str, encoding: str, schema) -> None:
    """A channel of a type a sliding log reads must declare it as the standard message: the
    schema encoding must go with the message encoding, and a schema text (when the file has
    one) must define the same fields as the standard type (ROS 2 Humble or ROS 1 Noetic).
    Raises LogError naming the topic and the field."""
    name = short_type(schema.name)
    where = f"topic '{topic}'"
    want = _SCHEMA_ENCODING.get(encoding)
    if want is None:
        return  # refused when read (for_channel): only ROS 1 and ROS 2 messages are decoded
    if schema.encoding != want:
        raise LogError(file, f"schema encoding {schema.encoding!r} of {name} does not go with "
                       f"message encoding {encoding!r} (expected {want!r}): field "
                       "schema.encoding", where=where)
    text = schema.data.decode("utf-8", "replace").strip()
    if not text:
        return  # no definition stored: the standard one is used
    typesys = need("rosbags.typesys", "decoding ROS messages")
    typename = full_type(schema.name)
    try:
        defined = typesys.get_types_from_msg(text, typename)
    except Exception as exc:  # noqa: BLE001 (the parser raises several types)
        raise LogError(file, f"the schema of {name} cannot be parsed ({exc_text(exc)}): field "
                       "schema.data", where=where) from None
    standard = typestore(encoding == "ros1").fielddefs
    for tname, fields in defined.items():
        ref = standard.get(tname)
        if ref is not None and [f[0] for f in ref[1]] != [f[0] for f in fields[1]]:
            raise LogError(file, f"the schema declares {name} but defines {short_type(tname)} "
                           f"with fields {', '.join(f[0] for f in fields[1])[:120]} instead of "
                           f"{', '.join(f[0] for f in ref[1])}: field schema.data", where=where)
        if ref is not None and ref != fields:
            raise LogError(file, f"the schema declares {name} but its {short_type(tname)} "
                           "fields have other types than the standard message: field "
                           "schema.data", where=where)


def _at_end(fh, exc: BaseException) -> bool:
    """Whether a reader failure is the end of a recording cut short (the file ends inside a
    record: mcap raises EndOfFile) rather than damage inside the file."""
    import struct

    from mcap.exceptions import EndOfFile

    return isinstance(exc, (EndOfFile, struct.error))


def _crc_error(file: str, exc) -> LogError:
    """LogError for mcap's CRCValidationError: the record and its CRC field named."""
    rec = getattr(exc, "record", None)
    kind = type(rec).__name__ if rec is not None else "record"
    field = {"Chunk": "uncompressed_crc", "DataEnd": "data_section_crc"}.get(kind, "crc")
    where = "chunk" if kind == "Chunk" else "data section" if kind == "DataEnd" else kind
    extra = ""
    if kind == "Chunk":
        extra = (f" (messages {rec.message_start_time}..{rec.message_end_time} ns)")
    return LogError(file, f"checksum mismatch in the {where}{extra}: field {kind}.{field} "
                    f"stores {getattr(exc, 'expected', 0):#010x}, the data give "
                    f"{getattr(exc, 'actual', 0):#010x}; the file is corrupted")


class McapSource(RosSource):
    """One sequential pass over the file (no summary needed, so a recording cut short by a
    crash is read up to its last complete chunk, with a warning). Message bytes are kept only
    for the types a sliding log reads."""

    def __init__(self, path: Path, file: str):
        super().__init__(file)
        stream_reader = need("mcap.stream_reader", "reading MCAP")
        records = need("mcap.records", "reading MCAP")
        if path.stat().st_size == 0:
            raise LogError(file, "empty file (expected an MCAP recording)")
        schemas: dict[int, Any] = {}
        channels: dict[int, tuple[str, str, str, Any]] = {}  # id -> topic, type, enc, schema
        counts: dict[str, int] = {}
        self._raw: dict[str, list[tuple[int, bytes]]] = {}
        self._channel: dict[str, tuple[str, Any]] = {}
        with open(path, "rb") as fh:
            try:
                # chunk CRCs (uncompressed_crc) and the data section CRC (DataEnd) are checked
                # where the file stores them (a CRC of 0 means none was written)
                for rec in stream_reader.StreamReader(fh, validate_crcs=True).records:
                    if isinstance(rec, records.Message):
                        topic, typ, _enc, _schema = channels[rec.channel_id]
                        counts[topic] += 1
                        # past MAX_MESSAGES only count: read() refuses the topic then
                        if typ in _TYPES and counts[topic] <= MAX_MESSAGES:
                            self._raw[topic].append((rec.log_time, rec.data))
                    elif isinstance(rec, records.Schema):
                        schemas[rec.id] = rec
                    elif isinstance(rec, records.Channel):
                        schema = schemas.get(rec.schema_id)
                        typ = short_type(schema.name) if schema is not None else "(no schema)"
                        if typ in _TYPES:
                            _check_schema(file, rec.topic, rec.message_encoding, schema)
                        channels[rec.id] = (rec.topic, typ, rec.message_encoding, schema)
                        counts.setdefault(rec.topic, 0)
                        self._raw.setdefault(rec.topic, [])
                        self._channel[rec.topic] = (rec.message_encoding, schema)
                    elif isinstance(rec, records.Metadata) and rec.name == _MCAP_META:
                        self.metadata = dict(rec.metadata)
            except LogError:
                raise
            except stream_reader.CRCValidationError as exc:
                raise _crc_error(file, exc) from None
            except Exception as exc:  # noqa: BLE001 (any reader failure: a bad file)
                if not channels or not _at_end(fh, exc):
                    if channels:  # damage inside the file, not a recording cut short
                        raise LogError(file, f"damaged MCAP at byte {fh.tell()} of "
                                       f"{path.stat().st_size} ({exc_text(exc)})") from None
                    raise LogError(file, f"not a readable MCAP file ({exc_text(exc)})") from None
                warnings.warn(f"{file}: truncated or damaged MCAP ({exc_text(exc)}); read the "
                              f"{sum(counts.values())} messages before the damage",
                              LogWarning, stacklevel=5)
        for topic, typ, enc, _schema in channels.values():
            self.topics[topic] = (typ, enc, counts[topic])

    def _messages(self, names) -> Iterator[tuple[str, int, Any]]:
        decoders = _Decoders(self.file)
        for name in names:
            encoding, schema = self._channel[name]
            decode = decoders.for_channel(encoding, schema)
            # file order is chunk order; sort by log time (stable) as a recorder plays it
            for k, (log_ns, data) in enumerate(sorted(self._raw[name], key=lambda m: m[0])):
                try:
                    msg = decode(data)
                except Exception as exc:  # noqa: BLE001 (decoders raise several types)
                    raise LogError(self.file, f"cannot decode {self.topics[name][0]} "
                                   f"({decode_error_text(exc)})", where=f"message {k + 1} on topic "
                                   f"'{name}'", row=k + 1) from None
                yield name, log_ns, msg


def write_mcap(log: SlidingLog, fh, wrench_topic: str | None, omega_topic: str | None,
               frame_id: str) -> None:
    """The log as ROS 2 messages (see :func:`lugrip.io.write_log`)."""
    writer_mod = need("mcap.writer", "writing MCAP")
    ts = typestore(False)
    wrench_topic = wrench_topic or log.meta.get("wrench_topic") or _DEFAULT_WRENCH_TOPIC
    omega_topic = omega_topic or log.meta.get("omega_topic") or _DEFAULT_OMEGA_TOPIC
    if log.omega is not None and omega_topic == wrench_topic:
        raise ValueError("write_log: omega_topic and wrench_topic must differ")
    n = len(log)
    t0 = int(log.meta.get("t0_ns", 0) or 0)
    if n and not np.all(np.isfinite(log.t)):
        raise ValueError("write_log: MCAP needs finite times")
    offs = np.rint(log.t * 1e9).astype(np.int64) if n else np.zeros(0, np.int64)
    if n and t0 + int(offs.min()) < 0:
        t0 = -int(offs.min())  # MCAP times are unsigned: shift, the metadata keeps t0
    stamps = (t0 + offs).tolist()
    try:
        import zstandard  # noqa: F401

        compression = writer_mod.CompressionType.ZSTD
    except ImportError:
        compression = writer_mod.CompressionType.NONE
    w = writer_mod.Writer(fh, compression=compression)
    w.start(profile="ros2", library="lugrip")
    T = ts.types

    def channel(topic: str, typ: str) -> int:
        sid = w.register_schema(name=typ, encoding="ros2msg",
                                data=ts.generate_msgdef(typ, ros_version=2)[0].encode())
        return w.register_channel(topic=topic, message_encoding="cdr", schema_id=sid)

    wtype, otype, mtype = ("geometry_msgs/msg/WrenchStamped", "geometry_msgs/msg/TwistStamped",
                           "std_msgs/msg/Int32")
    wid = channel(wrench_topic, wtype)
    oid = channel(omega_topic, otype) if log.omega is not None else None
    mid = channel(_DEFAULT_MANEUVER_TOPIC, mtype)
    # metadata first: a file cut short by a crash still says how to read it
    w.add_metadata(_MCAP_META, {
        "format_version": "1", "wrench_topic": wrench_topic,
        "omega_topic": omega_topic if log.omega is not None else "",
        "maneuver_topic": _DEFAULT_MANEUVER_TOPIC,
        "force_vector": "true" if log.has_force_vector else "false", "t0_ns": str(t0),
        "frame_id": frame_id, "units": json.dumps(UNITS)})
    if log.has_force_vector:
        fx, fy = log.f_x.tolist(), log.f_y.tolist()
    else:
        fx, fy = [0.0] * n, log.f_t.tolist()
    fz, tz = log.f_n.tolist(), log.tau.tolist()
    om = log.omega.tolist() if log.omega is not None else None
    man = log.maneuver.tolist()
    V, Time = T["geometry_msgs/msg/Vector3"], T["builtin_interfaces/msg/Time"]
    Header = T["std_msgs/msg/Header"]
    Wrench, WrenchStamped = T["geometry_msgs/msg/Wrench"], T[wtype]
    Twist, TwistStamped = T["geometry_msgs/msg/Twist"], T[otype]
    Int32 = T[mtype]
    zero = V(0.0, 0.0, 0.0)
    for i in range(n):
        s = stamps[i]
        sec, nsec = divmod(s, 1_000_000_000)
        header = Header(stamp=Time(sec=sec, nanosec=nsec), frame_id=frame_id)
        msg = WrenchStamped(header=header, wrench=Wrench(force=V(fx[i], fy[i], fz[i]),
                                                         torque=V(0.0, 0.0, tz[i])))
        w.add_message(channel_id=wid, log_time=s, publish_time=s,
                      data=bytes(ts.serialize_cdr(msg, wtype)), sequence=i)
        if om is not None:
            msg = TwistStamped(header=header, twist=Twist(linear=zero,
                                                          angular=V(0.0, 0.0, om[i])))
            w.add_message(channel_id=oid, log_time=s, publish_time=s,
                          data=bytes(ts.serialize_cdr(msg, otype)), sequence=i)
        if i == 0 or man[i] != man[i - 1]:
            w.add_message(channel_id=mid, log_time=s, publish_time=s,
                          data=bytes(ts.serialize_cdr(Int32(data=int(man[i])), mtype)),
                          sequence=i)
    w.finish()

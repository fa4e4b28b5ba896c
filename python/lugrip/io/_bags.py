"""ROS 1 bags and ROS 2 bags (sqlite3 or MCAP storage), read and decoded by rosbags'
AnyReader with the message definitions the bag carries (standard types from its typestore
when a ROS 2 bag carries none). No ROS installation is needed."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

from ._extras import decode_error_text, exc_text, need
from ._log import LogError
from ._ros import _TYPES, RosSource, short_type


def _reachable(defs: dict, name: str) -> list[str]:
    """``name`` and every message type its fields use, through ``defs`` (a typestore's
    fielddefs: name -> (constants, [(field, (node type, spec))]))."""
    seen: list[str] = []
    todo = [name]
    while todo:
        t = todo.pop()
        if t in seen or t not in defs:
            continue
        seen.append(t)

        def walk(spec):
            if isinstance(spec, str):
                todo.append(spec)
            elif isinstance(spec, tuple):
                for part in spec:
                    walk(part)

        for _field, desc in defs[t][1]:
            walk(desc)
    return seen


def _check_definitions(file: str, connections, defined: dict, standard: dict) -> None:
    """A topic of a type the log reads must carry the standard definition of it, as in MCAP
    files (the bag is decoded with its own definitions, so a bag that declares the standard
    name for another layout is not a recording of that message; lugrip picks its fields by the
    standard layout). LogError naming the topic and the type."""
    for conn in connections:
        if short_type(conn.msgtype) not in _TYPES:
            continue
        for t in _reachable(defined, conn.msgtype):
            ref = standard.get(t)
            if ref is not None and ref[1] != defined[t][1]:
                names = ", ".join(f[0] for f in defined[t][1])[:120]
                raise LogError(file, f"the bag declares {short_type(conn.msgtype)} but defines "
                               f"{short_type(t)} with fields ({names}) that are not the "
                               f"standard message's ({', '.join(f[0] for f in ref[1])}): "
                               "field msgdef", where=f"topic '{conn.topic}'")


class BagSource(RosSource):
    def __init__(self, path: Path, file: str, ros1: bool):
        super().__init__(file)
        highlevel = need("rosbags.highlevel", "reading ROS 1 bags" if ros1
                         else "reading ROS 2 bags")
        typesys = need("rosbags.typesys", "reading ROS bags")
        if path.is_file() and path.stat().st_size == 0:
            raise LogError(file, "empty file (expected a ROS bag)")
        if not ros1 and path.is_file():
            path = path.parent  # a storage file of a ROS 2 bag: read the bag
        store = typesys.get_typestore(typesys.Stores.ROS1_NOETIC if ros1
                                      else typesys.Stores.ROS2_HUMBLE)
        self._ros = 1 if ros1 else 2
        try:
            self._reader = highlevel.AnyReader([path], default_typestore=store)
            self._reader.open()
        except Exception as exc:  # noqa: BLE001 (any reader failure: a bad file)
            raise LogError(file, f"not a readable ROS {self._ros} bag "
                           f"({exc_text(exc)})") from None
        try:
            _check_definitions(file, self._reader.connections, self._reader.typestore.fielddefs,
                               store.fielddefs)
        except LogError:
            self._reader.close()
            raise
        for conn in self._reader.connections:
            typ = short_type(conn.msgtype)
            count = getattr(conn, "msgcount", None)
            old = self.topics.get(conn.topic)
            if old is not None and old[2] is not None and count is not None:
                count += old[2]
            self.topics[conn.topic] = (typ, "ros1" if ros1 else "cdr", count)

    def _messages(self, names) -> Iterator[tuple[str, int, Any]]:
        counts = dict.fromkeys(names, 0)
        try:
            conns = [c for c in self._reader.connections if c.topic in counts]
            for conn, log_ns, data in self._reader.messages(connections=conns):
                counts[conn.topic] += 1
                try:
                    msg = self._reader.deserialize(data, conn.msgtype)
                except Exception as exc:  # noqa: BLE001 (decoders raise several types)
                    raise LogError(self.file, f"cannot decode {short_type(conn.msgtype)} "
                                   f"({decode_error_text(exc)})",
                                   where=f"message {counts[conn.topic]} "
                                   f"on topic '{conn.topic}'", row=counts[conn.topic]) from None
                yield conn.topic, log_ns, msg
        except LogError:
            raise
        except Exception as exc:  # noqa: BLE001 (any reader failure: a bad file)
            raise LogError(self.file, f"cannot read the bag ({exc_text(exc)})") from None
        finally:
            self._reader.close()

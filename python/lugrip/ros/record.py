"""``lugrip ros record``: topics to an MCAP file that ``lugrip identify`` / ``replay`` /
``observe`` read unchanged (:func:`lugrip.io.read_log`).

The messages are taken as the middleware delivers them (serialized CDR, no decoding) and
written by rosbags' rosbag2 writer with its MCAP storage: OUT is a rosbag2 directory whose
``OUT/OUT.mcap`` is the file to read (its schemas come from rosbags' Kilted typestore). Log times
are the arrival times on the ROS clock; the readers order the samples by the header stamps.
"""

from __future__ import annotations

import time
from pathlib import Path

import rclpy
from rclpy.node import Node
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy

__all__ = ["Recorder", "mcap_file"]


def mcap_file(out: str | Path) -> Path:
    """The MCAP file inside the rosbag2 directory ``out``."""
    out = Path(out)
    return out / f"{out.name}.mcap"


def _message_class(type_name: str):
    import importlib

    pkg, _, name = type_name.partition("/msg/")
    return getattr(importlib.import_module(f"{pkg}.msg"), name)


class Recorder(Node):
    """Subscribes to ``topics`` as their publishers appear (reliable when every publisher
    offers it, else best effort, as ``ros2 bag record`` does) and writes each message as
    received."""

    def __init__(self, out: str | Path, topics: list[str], name: str = "lugrip_recorder"):
        super().__init__(name)
        from rosbags.rosbag2 import StoragePlugin, Writer
        from rosbags.typesys import Stores, get_typestore

        self.out = Path(out)
        if self.out.exists():
            raise FileExistsError(f"{self.out}: exists (rosbag2 writes a new directory)")
        self.typestore = get_typestore(Stores.ROS2_KILTED)
        self.writer = Writer(self.out, version=9, storage_plugin=StoragePlugin.MCAP)
        self.writer.open()
        self.wanted = [t if t.startswith("/") else "/" + t for t in topics]
        self.connections: dict[str, object] = {}
        self.counts: dict[str, int] = {}
        self.create_timer(0.2, self._discover)
        self._discover()

    def _discover(self) -> None:
        types = dict(self.get_topic_names_and_types())
        for topic in self.wanted:
            if topic in self.connections or topic not in types:
                continue
            type_name = types[topic][0]
            if type_name not in self.typestore.types:
                self.get_logger().warn(f"{topic}: type {type_name} unknown to rosbags; skipped")
                self.connections[topic] = None
                continue
            infos = self.get_publishers_info_by_topic(topic)
            if not infos:
                continue  # the topic is known but its publisher not yet: next round
            conn = self.writer.add_connection(topic, type_name, typestore=self.typestore)
            self.connections[topic] = conn
            self.counts[topic] = 0
            # as ros2 bag does: reliable when every publisher offers it, else best effort
            reliable = all(i.qos_profile.reliability == ReliabilityPolicy.RELIABLE
                           for i in infos)
            qos = QoSProfile(reliability=ReliabilityPolicy.RELIABLE if reliable
                             else ReliabilityPolicy.BEST_EFFORT,
                             history=HistoryPolicy.KEEP_LAST, depth=1000)
            self.create_subscription(_message_class(type_name), topic,
                                     lambda raw, c=conn, t=topic: self._write(c, t, raw),
                                     qos, raw=True)

    def _write(self, conn, topic: str, raw: bytes) -> None:
        self.writer.write(conn, self.get_clock().now().nanoseconds, raw)
        self.counts[topic] += 1

    def close(self) -> Path:
        self.writer.close()
        return mcap_file(self.out)


def record(out: str | Path, topics: list[str], duration: float | None = None) -> dict[str, int]:
    """Record until ``duration`` [s] (None: until Ctrl-C / SIGTERM); rclpy initialised by the
    caller. Returns the message count per topic."""
    node = Recorder(out, topics)
    end = None if duration is None else time.monotonic() + duration
    try:
        while rclpy.ok() and (end is None or time.monotonic() < end):
            rclpy.spin_once(node, timeout_sec=0.1)
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    finally:
        node.close()
        node.destroy_node()
    return dict(node.counts)

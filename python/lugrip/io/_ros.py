"""ROS recordings as sliding logs: the topics a log is read from, how their messages become
columns, and what is done to the wrench on the way (frame flip, move to the contact point).

Messages are decoded by the recording libraries themselves (rosbags' typestore, mcap and,
when installed, mcap-ros2-support); this module only picks fields out of the decoded objects.
The sources live in :mod:`._mcap` and :mod:`._bags`.
"""

from __future__ import annotations

import operator
import warnings
from collections.abc import Iterator
from typing import Any

import numpy as np

from .. import _core
from ._log import LogError, LogWarning, _Locator

_DEFAULT_WRENCH_TOPIC = "/lugrip/wrench"
_DEFAULT_OMEGA_TOPIC = "/lugrip/omega"
_DEFAULT_MANEUVER_TOPIC = "/lugrip/maneuver"
_MCAP_META = "lugrip.sliding_log"

_WRENCH_FIELDS = tuple(f"{a}.{b}" for a in ("force", "torque") for b in "xyz")
_INT_TYPES = tuple(f"std_msgs/{k}Int{n}" for k in ("", "U") for n in (8, 16, 32, 64))
_FLOAT_TYPES = ("std_msgs/Float64", "std_msgs/Float32")
# short type name -> (has a std_msgs/Header, fields read in this order)
_TYPES: dict[str, tuple[bool, tuple[str, ...]]] = {
    "geometry_msgs/WrenchStamped": (True, tuple("wrench." + f for f in _WRENCH_FIELDS)),
    "geometry_msgs/Wrench": (False, _WRENCH_FIELDS),
    "geometry_msgs/TwistStamped": (True, ("twist.angular.z",)),
    "geometry_msgs/Twist": (False, ("angular.z",)),
    "geometry_msgs/Vector3Stamped": (True, ("vector.z",)),
    "geometry_msgs/Vector3": (False, ("z",)),
    "geometry_msgs/PoseStamped": (True, tuple(f"pose.orientation.{a}" for a in "xyzw")),
    **{t: (False, ("data",)) for t in _FLOAT_TYPES + _INT_TYPES},
}
WRENCH_TYPES = ("geometry_msgs/WrenchStamped", "geometry_msgs/Wrench")
OMEGA_TYPES = ("geometry_msgs/TwistStamped", "geometry_msgs/Twist",
               "geometry_msgs/Vector3Stamped", "geometry_msgs/Vector3",
               "geometry_msgs/PoseStamped") + _FLOAT_TYPES
#: Ground truth given as a pose (motion capture): differentiated by :func:`pose_rate`.
POSE_TYPES = ("geometry_msgs/PoseStamped",)
POSE_METHOD = ("d/dt of the twist angle about z, 2 atan2(q_z, q_w) (swing-twist "
               "decomposition) unwrapped, by second-order central differences on the stamps")
ID_TYPES = _INT_TYPES + _FLOAT_TYPES  # maneuver ids (floats must hold integers)
SCALAR_TYPES = _FLOAT_TYPES + _INT_TYPES  # recorded commands and similar scalars
#: Most messages read from one topic (about 330 bytes each in memory: 2e6 = 66 min at 500 Hz).
MAX_MESSAGES = 2_000_000


def short_type(name: str) -> str:
    """'geometry_msgs/msg/WrenchStamped' and 'geometry_msgs/WrenchStamped' -> the latter."""
    return name.replace("/msg/", "/")


def full_type(name: str) -> str:
    """'geometry_msgs/WrenchStamped' -> 'geometry_msgs/msg/WrenchStamped' (typestore name)."""
    pkg, _, rest = short_type(name).partition("/")
    return f"{pkg}/msg/{rest}"


_GETTERS = {typ: operator.attrgetter(*fields) for typ, (_s, fields) in _TYPES.items()}


def _values(typ: str, msg: Any) -> tuple:
    got = _GETTERS[typ](msg)
    return got if isinstance(got, tuple) else (got,)


def _stamp_ns(msg: Any) -> int:
    stamp = msg.header.stamp
    return int(stamp.sec) * 1_000_000_000 + int(getattr(stamp, "nanosec", 0))


class Topic:
    """All messages of one topic in recording order: log times [ns], header stamps [ns] (0
    for unstamped types) and the fields of :data:`_TYPES` per message."""

    def __init__(self, name: str, typ: str):
        self.name = name
        self.type = typ
        self.log_ns: list[int] = []
        self.stamp_ns: list[int] = []
        self.values: list[tuple] = []

    def add(self, log_ns: int, msg: Any) -> None:
        stamped = _TYPES[self.type][0]
        self.log_ns.append(int(log_ns))
        self.stamp_ns.append(_stamp_ns(msg) if stamped else 0)
        self.values.append(_values(self.type, msg))

    def times(self, source: str = "header") -> tuple[np.ndarray, str]:
        """Header stamps when the type has them, they are set and ``source`` is "header";
        else the log times."""
        stamps = np.asarray(self.stamp_ns, dtype=np.int64)
        if (source == "header" and _TYPES[self.type][0] and stamps.size
                and np.any(stamps != 0)):
            return stamps, "header"
        return np.asarray(self.log_ns, dtype=np.int64), "log"


class RosSource:
    """Topics of an MCAP file or a ROS bag; :meth:`read` decodes the messages of some topics.

    Subclasses fill ``topics`` (name -> (short type, encoding, message count or None)) and
    ``metadata`` (lugrip's MCAP metadata record, else empty) and implement
    :meth:`_messages`, yielding ``(topic, log time [ns], decoded message)``.
    """

    def __init__(self, file: str):
        self.file = file
        self.topics: dict[str, tuple[str, str, int | None]] = {}
        self.metadata: dict[str, str] = {}

    def describe(self) -> str:
        if not self.topics:
            return "(no topics)"
        out = []
        for name, (typ, _enc, count) in sorted(self.topics.items()):
            n = "" if count is None else f", {count} messages"
            out.append(f"{name} ({typ}{n})")
        return ", ".join(out)

    def _messages(self, names: list[str]) -> Iterator[tuple[str, int, Any]]:
        raise NotImplementedError

    def _too_many(self, name: str, count: int) -> LogError:
        return LogError(self.file, f"topic '{name}' has {count} messages or more, over the "
                        f"{MAX_MESSAGES} one log may hold in memory; cut the recording into "
                        "pieces (e.g. rosbags-convert or mcap filter with a time range)")

    def read(self, names: list[str]) -> dict[str, Topic]:
        for name in names:
            count = self.topics[name][2]
            if count is not None and count > MAX_MESSAGES:
                raise self._too_many(name, count)
        out = {name: Topic(name, self.topics[name][0]) for name in names}
        for name, log_ns, msg in self._messages(names):
            topic = out[name]
            if len(topic.values) >= MAX_MESSAGES:
                raise self._too_many(name, MAX_MESSAGES + 1)
            try:
                topic.add(log_ns, msg)
            except (AttributeError, TypeError, ValueError) as exc:
                raise LogError(self.file, f"message has no usable {topic.type} fields ({exc})",
                               where=f"message {len(topic.values) + 1} on topic '{name}'",
                               row=len(topic.values) + 1) from None
        return out

    def check_topic(self, topic: str, types, what: str) -> None:
        """``what``: the option naming the topic (``omega_topic``: shown as ``--omega-topic``
        on the command line) or words for other topics."""
        option = f"[[opt:{what}]]" if what.endswith("_topic") else what
        if topic not in self.topics:
            fitting = sorted(n for n, (typ, _, _) in self.topics.items() if typ in types)
            choose = (f"; of a fitting type: {', '.join(fitting)}" if fitting
                      else f"; none has a fitting type ({', '.join(types)})")
            raise LogError(self.file, f"no topic '{topic}' ({option}); topics present: "
                           f"{self.describe()}{choose}")
        typ = self.topics[topic][0]
        if typ not in types:
            raise LogError(self.file, f"topic '{topic}' has type {typ}; {option} must be one of "
                           f"{', '.join(types)}")

    def pick_wrench_topic(self, wrench_topic: str | None) -> str:
        if wrench_topic is None:
            wrench_topic = self.metadata.get("wrench_topic")
        if wrench_topic is None:
            found = [n for n, (typ, _, _) in self.topics.items() if typ in WRENCH_TYPES]
            if len(found) == 1:
                return found[0]
            if not found:
                raise LogError(self.file, "no geometry_msgs/WrenchStamped topic; topics "
                               f"present: {self.describe()}")
            raise LogError(self.file, f"{len(found)} wrench topics "
                           f"({', '.join(sorted(found))}); choose one with [[opt:wrench_topic]]")
        self.check_topic(wrench_topic, WRENCH_TYPES, "wrench_topic")
        return wrench_topic


#: Largest fraction of a topic's messages that may repeat the time of the message before them
#: (dropped with a warning, the first of each time kept); more is an error. At least one
#: duplicate is always tolerated.
MAX_DUPLICATE_FRACTION = 0.01

TIME_SOURCES = ("header", "log")
"""How a ROS source orders its messages: by the header stamps (the sensor's clock, default)
or by the recorder's log times."""

_BY_LOG = "read by log time instead with [[alt:time_source='log'|--time-source log]]"


def ordered(file: str, topic: Topic, ns: np.ndarray, column: str,
            stacklevel: int, source: str = "header") -> np.ndarray:
    """Indices that put the messages of ``topic`` in increasing time ``ns`` with exact
    duplicates dropped (first kept).

    Header stamps (``source`` "header") that go backwards in recording order are an error (a
    sensor clock that jumps back would interleave samples seconds apart), and so are
    duplicated times on more than :data:`MAX_DUPLICATE_FRACTION` of the messages (identical
    stamps would collapse the recording); both messages name the topic and the count. Fewer
    duplicates are dropped with a warning; log times out of order are sorted with a warning."""
    n = len(ns)
    order = np.argsort(ns, kind="stable")
    back = np.flatnonzero(np.diff(ns) < 0) if n > 1 else np.zeros(0, dtype=np.int64)
    if back.size:
        k = int(back[0]) + 1
        if source == "header":
            jump = (int(ns[k]) - int(ns[k - 1])) / 1e9
            raise LogError(file, f"the header stamps go backwards at {back.size} of {n} "
                           f"messages, first at message {k + 1} (by {-jump:.6g} s; column "
                           f"'{column}'): the sensor clock jumped or the messages are out of "
                           f"order; {_BY_LOG}", where=f"topic '{topic.name}'", row=k + 1,
                           column=column)
        warnings.warn(f"{file}: topic '{topic.name}': times go backwards from message {k + 1} "
                      f"on (column '{column}'); messages sorted by time", LogWarning,
                      stacklevel=stacklevel)
    s = ns[order]
    dup = np.zeros(n, dtype=bool)
    dup[1:] = s[1:] == s[:-1]
    if dup.any():
        first = int(order[np.flatnonzero(dup)[0]])
        count = int(dup.sum())
        if count > max(1, int(MAX_DUPLICATE_FRACTION * n)):
            alt = f"; {_BY_LOG}" if source == "header" else ""
            raise LogError(file, f"{count} of {n} messages ({100.0 * count / n:.3g} %) repeat "
                           f"the time of the message before them, more than "
                           f"{100 * MAX_DUPLICATE_FRACTION:g} %; first message {first + 1} "
                           f"(column '{column}', t = {int(ns[first])} ns){alt}",
                           where=f"topic '{topic.name}'", row=first + 1, column=column)
        warnings.warn(f"{file}: topic '{topic.name}': {count} message(s) with a "
                      f"duplicated time, first message {first + 1} (column '{column}', "
                      f"t = {int(ns[first])} ns); dropped, the first of each time kept",
                      LogWarning, stacklevel=stacklevel)
    return order[~dup]


def resample(t_src: np.ndarray, y_src: np.ndarray, t_dst: np.ndarray,
             max_gap: float) -> np.ndarray:
    """Linear interpolation of (t_src, y_src) at t_dst; NaN outside the source's time span
    and between source samples further apart than max_gap."""
    m = len(t_src)
    out = np.full(len(t_dst), np.nan)
    if m == 0:
        return out
    idx = np.searchsorted(t_src, t_dst, side="left")
    inside = idx < m
    exact = np.zeros(len(t_dst), dtype=bool)
    exact[inside] = t_src[idx[inside]] == t_dst[inside]
    out[exact] = y_src[idx[exact]]
    mid = (idx > 0) & inside & ~exact
    lo, hi = idx[mid] - 1, idx[mid]
    span = t_src[hi] - t_src[lo]
    w = (t_dst[mid] - t_src[lo]) / span
    val = y_src[lo] + w * (y_src[hi] - y_src[lo])
    val[span > max_gap] = np.nan
    out[mid] = val
    return out


def hold_last(ns_src: np.ndarray, y_src: np.ndarray, ns_dst: np.ndarray,
              before: float) -> np.ndarray:
    """Zero-order hold: at each ns_dst the value of the latest source message at or before
    it; ``before`` ahead of the first message."""
    k = np.searchsorted(ns_src, ns_dst, side="right") - 1
    return np.where(k >= 0, y_src[np.maximum(k, 0)], before)


def pose_rate(t: np.ndarray, quaternions: np.ndarray) -> np.ndarray:
    """Angular velocity [rad/s] about z of a pose (object relative to the fingertip, z along
    the contact normal; e.g. motion capture of both expressed in the fingertip's frame) from its
    orientation quaternions (n, 4) as (x, y, z, w) at times t [s]: :data:`POSE_METHOD`. The
    twist about z is the part of the rotation that slides the contact; the swing (tilt of the
    normal) is left out."""
    q = np.asarray(quaternions, dtype=np.float64)
    angle = np.unwrap(2.0 * np.arctan2(q[:, 2], q[:, 3]))
    if len(t) < 2:
        return np.full(len(t), np.nan)
    return np.gradient(angle, t)


def contact_floor(f_n: np.ndarray) -> float:
    """The normal force [N] below which a batch's centre of pressure is not located: 5 % of
    the median pressing force, at least 1 mN (inf without a pressing sample)."""
    fz = np.asarray(f_n, dtype=np.float64)
    pressed = fz[np.isfinite(fz) & (fz > 0)]
    return max(1e-3, 0.05 * float(np.median(pressed))) if pressed.size else np.inf


def contact_wrench(force, moment, *, flip_normal: bool = False,
                   contact_offset: float | None = None,
                   floor: float | None = None) -> np.ndarray:
    """A fingertip sensor's wrench in lugrip's contact frame: rows (f_n, f_x, f_y, tau), the
    layout :meth:`lugrip.SlipControl.step` takes, from force and moment [N], [N m] of shape
    (3,) or (n, 3) in the sensor's frame (a ``geometry_msgs/Wrench``). The C++ core's
    ``lugrip::contact_wrench`` (include/lugrip/sensor_frame.hpp), shared by the log readers
    (:func:`lugrip.io.read_log`), the ROS node (:mod:`lugrip.ros`) and C++ robot loops:

    * ``flip_normal``: the sensor's z axis points toward the object, so its force z is
      negative while pressed: the frame is rotated by pi about x (y and z of force and
      moment change sign) so that f_n > 0 in contact;
    * ``contact_offset`` [m] (None: the wrench is already at the contact): the sensor origin
      lies this far behind the pad surface along the normal; the torsional moment is moved
      to the centre of pressure, x = -(m_y + d f_x) / f_z, y = (m_x - d f_y) / f_z,
      tau = m_z - x f_y + y f_x (docs/sliding_log.md, "Wrench at the sensor origin"), where
      f_z > ``floor`` [N]; below it tau = m_z. ``floor`` None: :func:`contact_floor` of the
      batch (one wrench: 1 mN).

    Returns shape (4,) for one wrench, (n, 4) for n."""
    offset = -1.0 if contact_offset is None else float(contact_offset)
    f = np.asarray(force, dtype=np.float64)
    m = np.asarray(moment, dtype=np.float64)
    if f.shape == (3,) and m.shape == (3,):
        return np.array(_core.contact_wrench(f.tolist(), m.tolist(), bool(flip_normal), offset,
                                             1e-3 if floor is None else float(floor)))
    if f.ndim != 2 or f.shape != m.shape or f.shape[1] != 3:
        raise ValueError(f"force and moment: expected shape (3,) or (n, 3) each, got "
                         f"{np.shape(force)} and {np.shape(moment)}")
    if floor is None:
        floor = contact_floor(f[:, 2] * (-1.0 if flip_normal else 1.0))
    return _core.contact_wrenches(np.ascontiguousarray(f), np.ascontiguousarray(m),
                                  bool(flip_normal), offset, float(floor))


def _metadata_t0(src: RosSource) -> int:
    """The ``t0_ns`` field of lugrip's MCAP metadata record (an integer of nanoseconds)."""
    text = str(src.metadata["t0_ns"]).strip()
    if len(text) > 24 or not text.lstrip("-").isdigit() or abs(int(text)) >= 2**63:
        raise LogError(src.file, f"metadata record {_MCAP_META!r}: field t0_ns is not an "
                       "integer of nanoseconds")
    return int(text)


def read_ros(src: RosSource, *, wrench_topic: str | None, omega_topic: str | None,
             maneuver_topic: str | None, flip_normal: bool, contact_offset: float | None,
             stacklevel: int, scalar_topics=None, time_source: str = "header"):
    """Columns of a sliding log from a ROS source (see :func:`lugrip.io.read_log`)."""
    file = src.file
    if time_source not in TIME_SOURCES:
        raise LogError(file, f"time_source {time_source!r}: expected one of "
                       f"{', '.join(TIME_SOURCES)}")
    wrench_topic = src.pick_wrench_topic(wrench_topic)
    if omega_topic is None:
        omega_topic = src.metadata.get("omega_topic") or None
    if omega_topic is not None:
        src.check_topic(omega_topic, OMEGA_TYPES, "omega_topic")
    if maneuver_topic is None:
        maneuver_topic = src.metadata.get("maneuver_topic") or None
    if maneuver_topic is not None:
        src.check_topic(maneuver_topic, ID_TYPES, "maneuver_topic")
    scalar_topics = dict(scalar_topics or {})
    for column, topic in scalar_topics.items():
        src.check_topic(topic, SCALAR_TYPES, f"{column} topic")
    names = [n for n in dict.fromkeys((wrench_topic, omega_topic, maneuver_topic,
                                       *scalar_topics.values())) if n]
    topics = src.read(names)

    wrench = topics[wrench_topic]
    if not wrench.values:
        raise LogError(file, f"topic '{wrench_topic}' has no messages")
    stamps, used = wrench.times(time_source)
    keep = ordered(file, wrench, stamps, "t", stacklevel + 1, used)
    stamps = stamps[keep]
    log_ns = np.asarray(wrench.log_ns, dtype=np.int64)[keep]
    t0 = _metadata_t0(src) if "t0_ns" in src.metadata else int(stamps[0])
    t = (stamps - t0) / 1e9
    v = np.asarray(wrench.values, dtype=np.float64)[keep]
    sign = -1.0 if flip_normal else 1.0  # omega below: the same rotation by pi about x
    w = contact_wrench(v[:, 0:3], v[:, 3:6], flip_normal=flip_normal,
                       contact_offset=contact_offset)
    cols = {"t": t, "f_x": w[:, 1], "f_y": w[:, 2], "f_n": w[:, 0], "tau": w[:, 3]}
    if src.metadata.get("force_vector") == "false":
        cols["f_t"] = np.hypot(cols.pop("f_x"), cols.pop("f_y"))
    prefix = "wrench." if _TYPES[wrench.type][0] else ""
    fields = {"t": "header.stamp" if used == "header" else "log time",
              "f_x": prefix + "force.x", "f_y": prefix + "force.y",
              "f_t": f"|{prefix}force.xy|", "f_n": prefix + "force.z",
              "tau": prefix + ("torque.z" if contact_offset is None
                               else "torque moved to the contact point")}
    meta: dict[str, Any] = {"format": None, "wrench_topic": wrench_topic,
                            "wrench_type": wrench.type, "time_source": used,
                            "t0_ns": t0, "flip_normal": bool(flip_normal)}
    if contact_offset is not None:
        meta["contact_offset"] = float(contact_offset)

    if omega_topic is not None:
        om = topics[omega_topic]
        if not om.values:
            raise LogError(file, f"topic '{omega_topic}' has no messages")
        o_ns, o_source = om.times(time_source)
        pick = ordered(file, om, o_ns, "omega", stacklevel + 1, o_source)
        o_t = (o_ns[pick] - t0) / 1e9
        values = np.asarray(om.values, dtype=np.float64)[pick]
        if om.type in POSE_TYPES:
            y = sign * pose_rate(o_t, values)
            fields["omega"] = f"pose of '{omega_topic}' differentiated: {POSE_METHOD}; resampled"
            meta["omega_method"] = POSE_METHOD
        else:
            y = sign * values[:, 0]
            fields["omega"] = f"{_TYPES[om.type][1][0]} of '{omega_topic}' resampled"
        step = np.diff(o_t)
        max_gap = 10.0 * float(np.median(step)) if step.size else 0.0
        cols["omega"] = resample(o_t, y, t, max_gap)
        meta.update(omega_topic=omega_topic, omega_type=om.type, omega_time_source=o_source)
    else:  # what a --omega-topic could name, for the messages of commands that need omega
        meta["omega_candidates"] = sorted(n for n, (typ, _, _) in src.topics.items()
                                          if typ in OMEGA_TYPES)

    if maneuver_topic is not None:
        mt = topics[maneuver_topic]
        m_ns, m_source = mt.times(time_source)
        pick = ordered(file, mt, m_ns, "maneuver", stacklevel + 1, m_source)
        m_val = np.asarray([val[0] for val in mt.values], dtype=np.float64)[pick]
        # compare like with like: a stamped id topic against the wrench stamps, else log times
        at = stamps if (m_source == "header" and used == "header") else log_ns
        cols["maneuver"] = hold_last(m_ns[pick], m_val, at,
                                     m_val[0] if m_val.size else 0.0)
        meta["maneuver_topic"] = maneuver_topic

    for column, topic in scalar_topics.items():  # e.g. a recorded command: the latest value
        st = topics[topic]
        s_ns, s_source = st.times(time_source)
        pick = ordered(file, st, s_ns, column, stacklevel + 1, s_source)
        s_val = np.asarray([val[0] for val in st.values], dtype=np.float64)[pick]
        at = stamps if (s_source == "header" and used == "header") else log_ns
        cols[column] = hold_last(s_ns[pick], s_val, at, np.nan)
        meta[f"{column}_topic"] = topic

    loc = _Locator(file, rows=keep + 1, topic=wrench_topic, fields=fields, kind="ros")
    return cols, {}, loc, meta

"""``lugrip`` as a managed (lifecycle) ROS 2 node: fingertip wrenches in, grip command out.

The node wraps one :class:`lugrip.SlipControl` (the C++ core, through the bindings):

* subscribes to each fingertip's ``geometry_msgs/WrenchStamped`` (``wrench_topics``), moves
  each wrench into lugrip's contact frame with :func:`lugrip.io.contact_wrench` (the log
  readers' transform: ``flip_normal``, ``contact_offset`` per finger), pairs the fingers'
  samples by header stamp (|difference| <= ``max_skew``) and steps SlipControl once per pair,
  with dt from the stamps (never from arrival times);
* publishes the grip-force command when the controller issues one (every ``command_ratio``
  samples): ``~/command`` (``std_msgs/Float64`` [N]) and ``~/joint_command``
  (``sensor_msgs/JointState``, effort [N], stamped with the sample's stamp); every sample a
  status (``~/status``, ``diagnostic_msgs/DiagnosticArray``: per finger S, omega_hat, c~,
  status; the controller's command, mode, mu belief, held); and ``/diagnostics``;
* services ``~/pivot``, ``~/slipping_avoidance``, ``~/reset`` (``std_srvs/Trigger``),
  ``~/dynamic`` (``std_srvs/SetBool``: the paper's dynamic or static slipping avoidance); mu and
  every run-time setting through their parameters (:mod:`lugrip.ros._parameters`).

Faults (docs/ros.md, "Time and faults"): a sample that is non-finite, from the wrong
``frame_id``, stamped at or before the finger's previous stamp (backwards), older than the last
stepped sample (stale) or left without its partner (missing) reaches the controller as a NaN row
for that finger, so the core holds the command (never lowers it) and reports InvalidSample;
backwards and stale samples are dropped. A finger that sends nothing for
``silence_timeout`` (arrival time: the only clock that can see silence) is reported within that
time plus ``watchdog_period``; a gap in the stamps longer than ``max_gap`` is reported when the
samples resume. Each cause is named in ``/diagnostics``; the node never raises on traffic.
"""

from __future__ import annotations

import collections
import math
import time
from typing import Any

import numpy as np
import rclpy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import WrenchStamped
from rcl_interfaces.msg import ParameterDescriptor, ParameterType, SetParametersResult
from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64
from std_srvs.srv import SetBool, Trigger

from .._contact import Status
from .._controller import ControllerMode
from ..io import contact_wrench
from ._parameters import ParameterSpec, build_slip_control, settings_parameters

__all__ = ["CAUSES", "SlipControlNode", "main"]

#: Fault causes named in /diagnostics (key: the count's key; value: what it means).
CAUSES = {
    "nan_wrench": "a wrench with a NaN or infinite component",
    "wrong_frame": "a wrench whose header.frame_id is not the finger's frame_ids entry",
    "stamps_backwards": "a stamp at or before the finger's previous one (dropped)",
    "stale": "a sample older than the last one stepped (dropped)",
    "missing": "a finger's sample without its partner within max_skew (stepped as invalid)",
    "gap": "consecutive samples further apart in stamp time than max_gap",
    "silent": "a finger sent nothing for silence_timeout",
}

_MODES = {int(m): m.name for m in ControllerMode}
_STATUS_NAMES = {int(st): st.name for st in Status}

_TYPES = {"float": ParameterType.PARAMETER_DOUBLE, "int": ParameterType.PARAMETER_INTEGER,
          "bool": ParameterType.PARAMETER_BOOL, "string": ParameterType.PARAMETER_STRING}

#: The node's own parameters (topics, frames, timing): name -> (type, default, description,
#: may change while active).
_IO_PARAMETERS: dict[str, tuple[int, Any, str, bool]] = {
    "wrench_topics": (ParameterType.PARAMETER_STRING_ARRAY,
                      ["fingertip_0/wrench", "fingertip_1/wrench"],
                      "geometry_msgs/WrenchStamped topic of each finger (one per finger)", False),
    "frame_ids": (ParameterType.PARAMETER_STRING_ARRAY, [""],
                  "header.frame_id each finger's wrench must carry; '' or an empty list: any",
                  False),
    "flip_normal": (ParameterType.PARAMETER_BOOL_ARRAY, [False],
                    "per finger (one value: all): the sensor's z points toward the object, "
                    "rotate by pi about x so that f_n > 0 in contact", False),
    "contact_offset": (ParameterType.PARAMETER_DOUBLE_ARRAY, [-1.0],
                       "per finger (one value: all) [m]: sensor origin this far behind the pad "
                       "surface, torque moved to the centre of pressure; < 0: the wrench is "
                       "already at the contact", False),
    "max_skew": (ParameterType.PARAMETER_DOUBLE, 0.001,
                 "[s] largest stamp difference of two fingers' samples paired into one step",
                 True),
    "max_gap": (ParameterType.PARAMETER_DOUBLE, 0.02,
                "[s] a longer step between consecutive stamps is reported as a gap", True),
    "silence_timeout": (ParameterType.PARAMETER_DOUBLE, 0.05,
                        "[s] a finger silent this long (arrival time) is reported", True),
    "watchdog_period": (ParameterType.PARAMETER_DOUBLE, 0.01,
                        "[s] period of the silence check and the /diagnostics throttle", False),
    "pair_timeout": (ParameterType.PARAMETER_DOUBLE, 0.01,
                     "[s] stamp span one finger's samples may wait for the other's before they "
                     "are stepped alone (the other finger invalid)", True),
    "initial_force": (ParameterType.PARAMETER_DOUBLE, 0.0,
                      "[N] command held after activation and ~/reset until the first step "
                      "computes one (0: controller.f_min)", True),
    "joint_names": (ParameterType.PARAMETER_STRING_ARRAY, ["gripper"],
                    "names of ~/joint_command (one effort per name, all the command)", False),
    "qos_depth": (ParameterType.PARAMETER_INTEGER, 10,
                  "history depth of the wrench subscriptions (best effort)", False),
}


def _key_values(values: dict[str, Any]) -> list[KeyValue]:
    return [KeyValue(key=k, value=repr(v) if isinstance(v, float) else str(v))
            for k, v in values.items()]


class SlipControlNode(LifecycleNode):
    """The managed lugrip node (see the module docstring). ``params_file``: a ``lugrip
    identify`` YAML (contact model and observer) giving the settings parameters' defaults; the
    node's own ``params_file`` parameter (from ``--ros-args -p`` or a ROS parameter file) does
    the same. Every other parameter overrides it as usual."""

    def __init__(self, node_name: str = "lugrip", *, params_file: str | None = None, **kwargs):
        super().__init__(node_name, **kwargs)
        given = self.declare_parameter(
            "params_file", params_file or "",
            ParameterDescriptor(description="lugrip identify YAML: defaults of contact.* and "
                                "observer.* (read once at start-up)", read_only=True,
                                type=ParameterType.PARAMETER_STRING)).value
        self._specs: dict[str, ParameterSpec] = {}
        for spec in settings_parameters(given or None):
            self._specs[spec.name] = spec
            self.declare_parameter(spec.name, spec.default, ParameterDescriptor(
                description=spec.description, additional_constraints=spec.constraint_text(),
                type=_TYPES[spec.kind]))
        for name, (typ, default, doc, live) in _IO_PARAMETERS.items():
            self.declare_parameter(name, default, ParameterDescriptor(
                description=doc, type=typ, additional_constraints=(
                    "may change while active" if live else "fixed while active")))
        self._sc = None
        self._active = False
        self._subs: list = []
        self._pubs: dict[str, Any] = {}
        self._triggers: list = []
        self._timer = None
        self.add_on_set_parameters_callback(self._on_set_parameters)
        self._reset_state()

    # --- parameters ------------------------------------------------------------------------
    def _values(self) -> dict[str, Any]:
        return {name: self.get_parameter(name).value for name in self._specs}

    def _io(self, name: str):
        return self.get_parameter(name).value

    def _on_set_parameters(self, params) -> SetParametersResult:
        changes = {p.name: p.value for p in params}
        settings = {k: v for k, v in changes.items() if k in self._specs}
        try:
            if self._active:
                fixed = [k for k in changes if (k in self._specs and not self._specs[k].while_active)
                         or (k in _IO_PARAMETERS and not _IO_PARAMETERS[k][3])]
                if fixed:
                    raise ValueError(f"{', '.join(fixed)}: fixed while the node is active; "
                                     "deactivate it to change")
                self._apply_live(settings)
            elif settings:
                trial = build_slip_control({**self._values(), **settings})
                if self._sc is not None:
                    self._sc = trial
            for k in ("max_skew", "max_gap", "silence_timeout", "pair_timeout", "watchdog_period"):
                if k in changes and not (isinstance(changes[k], float) and changes[k] > 0.0
                                         and math.isfinite(changes[k])):
                    raise ValueError(f"{k} = {changes[k]!r} s: must be finite and > 0")
        except ValueError as err:
            reason = " ".join(str(err).split())
            self.get_logger().warn(f"parameter change refused: {reason}")
            return SetParametersResult(successful=False, reason=reason)
        if self._active:
            self._load_timing(changes)
        return SetParametersResult(successful=True)

    def _load_timing(self, changes: dict[str, Any] | None = None) -> None:
        """The timing parameters the sample path reads, cached (nanoseconds where compared
        with stamps)."""
        value = {**{k: self._io(k) for k in ("max_skew", "max_gap", "pair_timeout",
                                             "silence_timeout", "joint_names")},
                 **(changes or {})}
        self._skew_ns = int(float(value["max_skew"]) * 1e9)
        self._gap_s = float(value["max_gap"])
        self._wait_ns = int(float(value["pair_timeout"]) * 1e9)
        self._silence_s = float(value["silence_timeout"])
        self._joint_names = list(value["joint_names"])

    def _apply_live(self, settings: dict[str, Any]) -> None:
        """Run-time changes on the running SlipControl (validated by the core)."""
        ctrl = {k.partition(".")[2]: v for k, v in settings.items() if k.startswith("controller.")}
        if ctrl:
            self._sc.update_settings(**ctrl)
        if "contact.mu" in settings:
            self._sc.set_mu(settings["contact.mu"])

    # --- lifecycle -------------------------------------------------------------------------
    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        try:
            self._sc = build_slip_control(self._values())
            self._check_io()
        except ValueError as err:
            self._sc = None
            self.get_logger().error(f"configure failed: {' '.join(str(err).split())}")
            return TransitionCallbackReturn.FAILURE
        self._pubs = {
            "command": self.create_publisher(Float64, "~/command", 10),
            "joint": self.create_publisher(JointState, "~/joint_command", 10),
            "status": self.create_publisher(DiagnosticArray, "~/status", 10),
            "diagnostics": self.create_publisher(DiagnosticArray, "/diagnostics", 10),
        }
        self._triggers = [
            self.create_service(Trigger, "~/pivot", self._srv_pivot),
            self.create_service(Trigger, "~/slipping_avoidance", self._srv_avoid),
            self.create_service(Trigger, "~/reset", self._srv_reset),
            self.create_service(SetBool, "~/dynamic", self._srv_dynamic),
        ]
        return TransitionCallbackReturn.SUCCESS

    def _check_io(self) -> None:
        n = self._sc.fingers
        topics = list(self._io("wrench_topics"))
        if len(topics) != n:
            raise ValueError(f"wrench_topics has {len(topics)} topics for {n} finger(s)")
        for name in ("frame_ids", "flip_normal", "contact_offset"):
            if len(self._io(name)) not in (0, 1, n):
                raise ValueError(f"{name}: one value, or one per finger ({n})")
        offsets = list(self._io("contact_offset"))
        if any(not math.isfinite(x) for x in offsets):
            raise ValueError("contact_offset: must be finite (< 0: none)")
        if int(self._io("qos_depth")) < 1:
            raise ValueError("qos_depth must be >= 1")

    def _per_finger(self, name: str, default):
        values = list(self._io(name))
        n = self._sc.fingers
        if not values:
            return [default] * n
        return values * n if len(values) == 1 else values

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        try:
            self._check_io()  # inputs may have changed while inactive
        except ValueError as err:
            self.get_logger().error(f"activate failed: {' '.join(str(err).split())}")
            return TransitionCallbackReturn.FAILURE
        n = self._sc.fingers
        self._frames = [f or None for f in self._per_finger("frame_ids", "")]
        self._flip = [bool(x) for x in self._per_finger("flip_normal", False)]
        self._offset = [None if x < 0 else float(x) for x in self._per_finger("contact_offset", -1.0)]
        self._f_n_floor = float(self._sc.settings.observer.cor.f_n_min)
        qos = QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT,
                         history=HistoryPolicy.KEEP_LAST, depth=int(self._io("qos_depth")))
        self._subs = [self.create_subscription(WrenchStamped, topic,
                                               lambda msg, k=k: self._on_wrench(k, msg), qos)
                      for k, topic in enumerate(list(self._io("wrench_topics"))[:n])]
        self._load_timing()
        self._status = self._status_message()
        self._reset_controller()
        self._timer = self.create_timer(float(self._io("watchdog_period")), self._watchdog)
        self._active = True
        return super().on_activate(state)

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self._active = False
        for sub in self._subs:
            self.destroy_subscription(sub)
        self._subs = []
        if self._timer is not None:
            self.destroy_timer(self._timer)
            self._timer = None
        return super().on_deactivate(state)

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        for pub in self._pubs.values():
            self.destroy_publisher(pub)
        for srv in self._triggers:
            self.destroy_service(srv)
        self._pubs, self._triggers, self._sc = {}, [], None
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        if self._active:
            self.on_deactivate(state)
        if self._sc is not None:
            self.on_cleanup(state)
        return TransitionCallbackReturn.SUCCESS

    # --- state -----------------------------------------------------------------------------
    def _reset_state(self) -> None:
        n = self._sc.fingers if self._sc is not None else 2
        self._queues = [collections.deque() for _ in range(n)]
        self._last_stamp = [None] * n       # newest stamp received per finger [ns]
        self._last_arrival = [None] * n     # monotonic arrival time per finger [s]
        self._stepped = None                # stamp of the last step [ns]
        self._counts = dict.fromkeys(CAUSES, 0)
        self._recent: dict[str, str] = {}   # cause -> detail, since the last /diagnostics
        self._silent = [False] * n
        self._diag_due = 0.0
        self._last_output = None
        self.samples = 0

    def _reset_controller(self) -> None:
        force = float(self._io("initial_force"))
        self._reset_state()
        self._sc.reset(force if force > 0.0 else None)

    # --- services --------------------------------------------------------------------------
    def _trigger(self, response, action, what: str):
        if not self._active:
            response.success, response.message = False, "the node is not active"
            return response
        action()
        response.success, response.message = True, what
        return response

    def _srv_pivot(self, request, response):
        return self._trigger(response, self._sc.request_pivoting,
                             "pivoting requested (starts at the next sample)")

    def _srv_avoid(self, request, response):
        return self._trigger(response, self._sc.request_slipping_avoidance,
                             "slipping avoidance requested (pivoting ends at the next sample)")

    def _srv_dynamic(self, request, response):
        on = bool(request.data)
        return self._trigger(response, lambda: self._sc.set_dynamic_enabled(on),
                             "dynamic part " + ("on (C_d restarts from rest)" if on else "off"))

    def _srv_reset(self, request, response):
        return self._trigger(response, self._reset_controller,
                             "observers and controller reset; initial_force held")

    # --- samples ---------------------------------------------------------------------------
    def _fault(self, cause: str, detail: str) -> None:
        self._counts[cause] += 1
        if cause not in self._recent:
            self._recent[cause] = detail
            self._diag_due = 0.0  # publish the new cause at the next check

    def _on_wrench(self, k: int, msg: WrenchStamped) -> None:
        if not self._active:
            return
        arrival = time.monotonic()
        if self._silent[k]:
            self._silent[k] = False
        self._last_arrival[k] = arrival
        stamp = int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)
        last = self._last_stamp[k]
        if last is not None and stamp <= last:
            self._fault("stamps_backwards", f"finger {k}: stamp {stamp} ns at or before "
                        f"{last} ns")
            return
        if self._stepped is not None and stamp <= self._stepped:
            self._fault("stale", f"finger {k}: stamp {stamp} ns older than the last step "
                        f"({self._stepped} ns)")
            self._last_stamp[k] = stamp
            return
        self._last_stamp[k] = stamp
        f, m = msg.wrench.force, msg.wrench.torque
        row = contact_wrench((f.x, f.y, f.z), (m.x, m.y, m.z), flip_normal=self._flip[k],
                             contact_offset=self._offset[k], floor=self._f_n_floor)
        frame = self._frames[k]
        if frame is not None and msg.header.frame_id != frame:
            self._fault("wrong_frame", f"finger {k}: frame_id '{msg.header.frame_id}', "
                        f"expected '{frame}'")
            row = np.full(4, np.nan)
        elif not all(map(math.isfinite, row)):
            self._fault("nan_wrench", f"finger {k}: non-finite wrench at stamp {stamp} ns")
            row = np.full(4, np.nan)
        self._queues[k].append((stamp, row))
        self._pair()

    def _pair(self) -> None:
        queues = self._queues
        if len(queues) == 1:
            while queues[0]:
                stamp, row = queues[0].popleft()
                self._step(stamp, row[None, :])
            return
        skew = self._skew_ns
        q0, q1 = queues
        while q0 and q1:
            (t0, w0), (t1, w1) = q0[0], q1[0]
            if abs(t0 - t1) <= skew:
                q0.popleft()
                q1.popleft()
                self._step(max(t0, t1), np.array((w0, w1)))
            elif t0 < t1:  # finger 1 has nothing at t0 and never will (its stamps increase)
                q0.popleft()
                self._fault("missing", f"finger 1: no sample within {skew} ns of {t0} ns")
                self._step(t0, np.vstack((w0, np.full(4, np.nan))))
            else:
                q1.popleft()
                self._fault("missing", f"finger 0: no sample within {skew} ns of {t1} ns")
                self._step(t1, np.vstack((np.full(4, np.nan), w1)))
        wait = self._wait_ns
        for k, q in enumerate(queues):  # the other finger has fallen silent
            while q and q[-1][0] - q[0][0] > wait:
                t, w = q.popleft()
                other = 1 - k
                self._fault("missing", f"finger {other}: no sample for {t} ns within "
                            f"pair_timeout")
                rows = np.full((2, 4), np.nan)
                rows[k] = w
                self._step(t, rows)

    def _step(self, stamp: int, rows: np.ndarray) -> None:
        dt = 0.0
        if self._stepped is not None:
            dt = (stamp - self._stepped) / 1e9
            if dt > self._gap_s:
                self._fault("gap", f"{dt * 1e3:.1f} ms between samples {self._stepped} ns "
                            f"and {stamp} ns")
        self._stepped = stamp
        out = self._sc.step(rows, dt)
        self.samples += 1
        self._last_output = out
        c = out.controller
        sec, nsec = divmod(stamp, 1_000_000_000)
        if c.command_issued:
            self._pubs["command"].publish(Float64(data=float(out.force)))
            js = JointState()
            js.header.stamp.sec, js.header.stamp.nanosec = int(sec), int(nsec)
            names = self._joint_names
            js.name = names
            js.effort = [float(out.force)] * len(names)
            self._pubs["joint"].publish(js)
        self._publish_status(sec, nsec, out)

    def _status_message(self) -> DiagnosticArray:
        """The ~/status message, built once per activation; each sample fills its values."""
        arr = DiagnosticArray()
        keys = ("command", "command_issued", "mode", "mu_belief", "held", "status",
                "static_force", "dynamic_force", "pivot_finished", "pivot_end")
        arr.status.append(DiagnosticStatus(name=f"{self.get_name()}: controller",
                                           values=[KeyValue(key=k) for k in keys]))
        for k in range(self._sc.fingers):
            arr.status.append(DiagnosticStatus(
                name=f"{self.get_name()}: finger {k}",
                values=[KeyValue(key=key) for key in ("S", "omega_hat", "c_tilde", "status")]))
        return arr

    def _publish_status(self, sec: int, nsec: int, out) -> None:
        c = out.controller
        arr = self._status
        arr.header.stamp.sec, arr.header.stamp.nanosec = int(sec), int(nsec)
        held = bool(c.held)
        top = arr.status[0]
        top.level = DiagnosticStatus.WARN if held else DiagnosticStatus.OK
        top.message = "held" if held else "ok"
        values = (repr(float(out.force)), str(int(c.command_issued)),
                  _MODES[int(getattr(c.mode, "value", c.mode))], repr(float(c.mu_belief)),
                  str(int(held)), str(int(getattr(out.status, "value", out.status))),
                  repr(float(c.static_force)), repr(float(c.dynamic_force)),
                  str(int(c.pivot_finished)), str(int(getattr(c.pivot_end, "value", c.pivot_end))))
        for kv, v in zip(top.values, values):
            kv.value = v
        for status, o in zip(arr.status[1:], out.fingers):
            st = int(getattr(o.status, "value", o.status))
            status.level = DiagnosticStatus.OK if st == 0 else DiagnosticStatus.WARN
            status.message = _STATUS_NAMES[st]
            for kv, v in zip(status.values, (repr(float(o.S)), repr(float(o.omega_hat)),
                                             repr(float(o.c_tilde)), str(st))):
                kv.value = v
        self._pubs["status"].publish(arr)

    # --- watchdog and /diagnostics ---------------------------------------------------------
    def _watchdog(self) -> None:
        if not self._active:
            return
        now = time.monotonic()
        timeout = self._silence_s
        for k, last in enumerate(self._last_arrival):
            if last is not None and now - last > timeout and not self._silent[k]:
                self._silent[k] = True
                self._fault("silent", f"finger {k}: nothing for {(now - last) * 1e3:.0f} ms "
                            f"(silence_timeout {timeout * 1e3:.0f} ms); command held")
        if now < self._diag_due:
            return
        self._diag_due = now + 1.0  # at least 1 Hz; a new cause brings it forward
        self._publish_diagnostics()

    def _publish_diagnostics(self) -> None:
        arr = DiagnosticArray()
        arr.header.stamp = self.get_clock().now().to_msg()
        waiting = [k for k, t in enumerate(self._last_arrival) if t is None]
        silent = [k for k, s in enumerate(self._silent) if s]
        if silent or self._recent:
            level = DiagnosticStatus.ERROR if silent else DiagnosticStatus.WARN
            message = "; ".join(f"{cause}: {detail}" for cause, detail in self._recent.items())
            if silent and "silent" not in self._recent:
                message = f"silent: finger(s) {silent}; " + message
        elif waiting:
            level, message = DiagnosticStatus.WARN, f"no wrench yet from finger(s) {waiting}"
        else:
            level, message = DiagnosticStatus.OK, "ok"
        out = self._last_output
        values = {**self._counts, "samples": self.samples}
        if out is not None:
            values.update(command=float(out.force), held=int(out.controller.held))
        arr.status.append(DiagnosticStatus(level=level, name=f"{self.get_name()}: input",
                                           hardware_id="lugrip", message=message.strip("; "),
                                           values=_key_values(values)))
        self._recent = {}
        self._pubs["diagnostics"].publish(arr)


def main(args=None, *, params_file: str | None = None, node_name: str = "lugrip",
         autostart: bool = True) -> int:
    """Run the node until shut down; ``autostart`` configures and activates it at once (the
    ``lugrip ros run`` default; without it a lifecycle manager drives the transitions)."""
    rclpy.init(args=args)
    node = SlipControlNode(node_name, params_file=params_file)
    try:
        if autostart:
            if node.trigger_configure() != TransitionCallbackReturn.SUCCESS:
                node.get_logger().error("configure failed: see the message above")
                return 2
            node.trigger_activate()
        rclpy.spin(node)
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        if rclpy.ok():
            rclpy.try_shutdown()
    return 0

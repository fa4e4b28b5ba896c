"""``lugrip ros sim``: the MuJoCo gripper of ``lugrip simulate --plant mujoco`` as a ROS 2 node.

The plant, the sensors (500 Hz, noise, bias) and the actuator (lag, rate limit) are those of
:func:`lugrip.sim.mujoco.loop.run_mujoco_loop`; only the controller is replaced by a proxy
that talks to the controller node over the middleware: each sensor sample is published as two
``geometry_msgs/WrenchStamped`` (stamped with the simulated time from the start of the run,
frame ids ``fingertip_0``/``fingertip_1``), with the true slip rate of the object on each pad
as ``~/omega_true_k`` (``TwistStamped`` angular.z: ground truth for recordings); the gripper
takes its command from the node's ``~/joint_command`` (effort [N]) and holds it between
commands, and the scenario's schedule
calls the node's ``~/pivot`` / ``~/slipping_avoidance`` / ``~/dynamic`` services. Before the run the simulation gives the node the scenario's
settings (contact model, observer, controller: deactivate, set the parameters, activate),
so both ends use what ``lugrip simulate`` uses in-process. The controller's start (both pads touching) sets
``initial_force`` to the closing force and calls ``~/reset``: bumpless, as in-process.

Lock-step (default): after publishing a sample the simulation waits for the node's status of
that stamp (and, when it says a command was issued, for that command), so the run is the
in-process run with the middleware in between, whatever the machine's load. ``real_time``
paces the samples at the wall clock instead and takes whatever command has arrived.
"""

from __future__ import annotations

import time
from types import SimpleNamespace
from typing import Any

import rclpy
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import TwistStamped, WrenchStamped
from lifecycle_msgs.msg import Transition
from lifecycle_msgs.srv import ChangeState
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import SetParameters
from rclpy.node import Node
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import JointState
from std_srvs.srv import SetBool, Trigger

from .. import _core
from .._contact import _as_params
from .._controller import _core_settings
from .._observer import Observer
from ._parameters import settings_parameters

__all__ = ["GripperSimNode", "RemoteSlipControl", "controller_parameters", "run_ros_scenario"]


class RosTimeout(RuntimeError):
    """The controller node did not answer in time."""


def _stamp_ns(stamp) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def _parse(status) -> dict[str, Any]:
    out = {}
    for kv in status.values:
        try:
            out[kv.key] = float(kv.value)
        except ValueError:
            out[kv.key] = kv.value
    return out


def parameter_value(value) -> ParameterValue:
    """An rcl_interfaces ParameterValue of a bool, int, str, float or a list of str."""
    v = ParameterValue()
    if isinstance(value, list):
        v.type, v.string_array_value = ParameterType.PARAMETER_STRING_ARRAY, [str(x) for x in value]
    elif isinstance(value, bool):
        v.type, v.bool_value = ParameterType.PARAMETER_BOOL, value
    elif isinstance(value, int):
        v.type, v.integer_value = ParameterType.PARAMETER_INTEGER, value
    elif isinstance(value, str):
        v.type, v.string_value = ParameterType.PARAMETER_STRING, value
    else:
        v.type, v.double_value = ParameterType.PARAMETER_DOUBLE, float(value)
    return v


class GripperSimNode(Node):
    """Publishes the fingertip wrenches, takes the command, calls the controller's services."""

    def __init__(self, controller: str = "lugrip", name: str = "lugrip_gripper_sim",
                 wrench_topics=("fingertip_0/wrench", "fingertip_1/wrench"),
                 frame_ids=("fingertip_0", "fingertip_1")):
        super().__init__(name)
        ns = "/" + controller.strip("/")
        # reliable (a test rig: recordings get every sample); best-effort subscribers such
        # as the controller node's still match
        qos = QoSProfile(reliability=ReliabilityPolicy.RELIABLE,
                         history=HistoryPolicy.KEEP_LAST, depth=1000)
        self.frame_ids = list(frame_ids)
        self.wrench = [self.create_publisher(WrenchStamped, t, qos) for t in wrench_topics]
        self.truth = [self.create_publisher(TwistStamped, f"~/omega_true_{k}", qos)
                      for k in range(len(wrench_topics))]
        self.statuses: dict[int, dict] = {}
        self.commands: dict[int, float] = {}
        self.last_command: float | None = None
        self.create_subscription(DiagnosticArray, f"{ns}/status", self._on_status, 1000)
        self.create_subscription(JointState, f"{ns}/joint_command", self._on_command, 100)
        self.clients_ = {name: self.create_client(Trigger, f"{ns}/{name}")
                         for name in ("pivot", "slipping_avoidance", "reset")}
        self.dynamic_client = self.create_client(SetBool, f"{ns}/dynamic")
        self.param_client = self.create_client(SetParameters, f"{ns}/set_parameters")
        self.change_state = self.create_client(ChangeState, f"{ns}/change_state")

    def _on_status(self, msg: DiagnosticArray) -> None:
        stamp = _stamp_ns(msg.header.stamp)
        ctrl = _parse(msg.status[0])
        fingers = [_parse(s) for s in msg.status[1:]]
        self.statuses[stamp] = {"controller": ctrl, "fingers": fingers}

    def _on_command(self, msg: JointState) -> None:
        if msg.effort:
            self.commands[_stamp_ns(msg.header.stamp)] = float(msg.effort[0])
            self.last_command = float(msg.effort[0])

    def wait_for_controller(self, timeout: float = 30.0) -> None:
        """Until the controller's services exist and it subscribes to both wrench topics
        (i.e. it is active)."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if (all(c.service_is_ready() for c in self.clients_.values())
                    and self.dynamic_client.service_is_ready()
                    and self.param_client.service_is_ready()
                    and all(p.get_subscription_count() > 0 for p in self.wrench)):
                return
            rclpy.spin_once(self, timeout_sec=0.05)
        raise RosTimeout("the controller node is not active (its services and wrench "
                         f"subscriptions did not appear within {timeout:g} s)")

    def call(self, client, request, timeout: float = 10.0):
        future = client.call_async(request)
        rclpy.spin_until_future_complete(self, future, timeout_sec=timeout)
        if not future.done():
            raise RosTimeout(f"no answer from {client.srv_name} within {timeout:g} s")
        return future.result()

    def trigger(self, name: str) -> None:
        result = self.call(self.clients_[name], Trigger.Request())
        if not result.success:
            raise RuntimeError(f"~/{name} refused: {result.message}")

    def set_dynamic(self, enabled: bool) -> None:
        result = self.call(self.dynamic_client, SetBool.Request(data=bool(enabled)))
        if not result.success:
            raise RuntimeError(f"~/dynamic refused: {result.message}")

    def set_parameters(self, values: dict[str, Any]) -> None:
        """Set the controller's parameters (bool, int, float or str values)."""
        params = [Parameter(name=name, value=parameter_value(value))
                  for name, value in values.items()]
        results = self.call(self.param_client, SetParameters.Request(parameters=params)).results
        for name, result in zip(values, results):
            if not result.successful:
                raise RuntimeError(f"parameter {name} refused: {result.reason}")

    def set_parameter(self, name: str, value) -> None:
        self.set_parameters({name: value})

    def transition(self, transition_id: int) -> None:
        req = ChangeState.Request()
        req.transition.id = transition_id
        if not self.call(self.change_state, req).success:
            raise RuntimeError(f"the controller refused lifecycle transition {transition_id}")

    def configure_controller(self, values: dict[str, Any]) -> None:
        """Give the controller these settings parameters: deactivate it, set them, activate
        it again (most settings are fixed while active)."""
        self.transition(Transition.TRANSITION_DEACTIVATE)
        self.set_parameters(values)
        self.transition(Transition.TRANSITION_ACTIVATE)
        self.wait_for_controller()

    def _stamped(self, cls, stamp_ns: int, k: int):
        msg = cls()
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(int(stamp_ns), 1_000_000_000)
        msg.header.frame_id = self.frame_ids[k]
        return msg

    def publish_truth(self, stamp_ns: int, omegas) -> None:
        """The true slip rate of the object relative to each pad [rad/s] (angular.z)."""
        for k, pub in enumerate(self.truth):
            msg = self._stamped(TwistStamped, stamp_ns, k)
            msg.twist.angular.z = float(omegas[k])
            pub.publish(msg)

    def publish(self, stamp_ns: int, meas) -> None:
        """One sample's wrenches, rows (f_n, f_x, f_y, tau) per finger, as the sensor reads."""
        for k, pub in enumerate(self.wrench):
            msg = self._stamped(WrenchStamped, stamp_ns, k)
            f_n, f_x, f_y, tau = (float(x) for x in meas[k])
            msg.wrench.force.x, msg.wrench.force.y, msg.wrench.force.z = f_x, f_y, f_n
            msg.wrench.torque.z = tau
            pub.publish(msg)


def controller_parameters(params, *, fingers=2, observer=None, stuck_samples=None,
                          healthy_finger_fallback=False, **controller) -> dict[str, Any]:
    """The node's settings parameters for SlipControl's arguments (as the MuJoCo loop builds
    its controller): the contact model, the effective observer (a file's block merged), the
    controller settings given and SlipControl's own."""
    contact = _as_params(params)
    obs = Observer(params, **dict(observer or {})).settings
    cor = {name for name, _k, _d in _core.CorSettings.fields}
    out: dict[str, Any] = {f"contact.{k}": v for k, v in contact.to_dict().items()}
    for k, v in obs.items():
        if k != "dt":
            out[f"observer.cor.{k}" if k in cor else f"observer.{k}"] = v
    out.update({f"controller.{k}": v for k, v in controller.items()})
    if stuck_samples is None:  # SlipControl's own default (the frozen-sensor check)
        stuck_samples = _core.SlipControlSettings().stuck_samples
    out.update(fingers=int(fingers), stuck_samples=int(stuck_samples),
               healthy_finger_fallback=bool(healthy_finger_fallback))
    kinds = {spec.name: spec.kind for spec in settings_parameters()}
    convert = {"float": float, "int": int, "bool": bool, "string": str}
    return {k: convert[kinds[k]](v) for k, v in out.items()}


class RemoteSlipControl:
    """Stands in for :class:`lugrip.SlipControl` inside the MuJoCo loop: the same calls, served
    by the controller node over ROS 2 (see the module docstring)."""

    def __init__(self, node: GripperSimNode, params, *, fingers=2, observer=None,
                 stuck_samples=None, healthy_finger_fallback=False, lockstep: bool = True,
                 timeout: float = 5.0, **controller):
        ctrl = _core_settings(controller)
        self.settings = SimpleNamespace(controller=ctrl)
        node.configure_controller(controller_parameters(
            params, fingers=fingers, observer=observer, stuck_samples=stuck_samples,
            healthy_finger_fallback=healthy_finger_fallback, **controller))
        self._period = 1.0 / ctrl.sensor_rate
        self.node = node
        self.lockstep = lockstep
        self.timeout = timeout
        self.base_ns = 1_000_000_000  # stamps: simulated time from 1 s on
        self.count = 0
        self.force = float(ctrl.f_min)
        self.timeouts = 0
        self._last_status = None
        self._mu = float(_as_params(params).mu)
        self.latencies: list[float] = []
        self._next_wall = None

    def reset(self, force: float | None = None) -> None:
        if force is not None:
            self.node.set_parameter("initial_force", float(force))
            self.force = float(force)
        self.node.trigger("reset")

    def request_pivoting(self) -> None:
        self.node.trigger("pivot")

    def request_slipping_avoidance(self) -> None:
        self.node.trigger("slipping_avoidance")

    def set_dynamic_enabled(self, enabled: bool) -> None:
        self.node.set_dynamic(bool(enabled))

    def ground_truth(self, omegas) -> None:
        """Publish the last sample's true slip rates (``~/omega_true_k``, stamped with it)."""
        self.node.publish_truth(self._stamp, omegas)

    def step(self, meas):
        node = self.node
        stamp = self.base_ns + round(self.count * self._period * 1e9)
        self._stamp = stamp
        self.count += 1
        if not self.lockstep:
            if self._next_wall is None:
                self._next_wall = time.monotonic()
            self._next_wall += self._period
            while time.monotonic() < self._next_wall:
                rclpy.spin_once(node, timeout_sec=max(0.0, self._next_wall - time.monotonic()))
        sent = time.perf_counter()
        node.publish(stamp, meas)
        status = None
        if self.lockstep:
            end = time.monotonic() + self.timeout
            while time.monotonic() < end:
                status = node.statuses.pop(stamp, None)
                if status is not None and (not status["controller"]["command_issued"]
                                           or stamp in node.commands):
                    break
                if status is not None:
                    node.statuses[stamp] = status
                    status = None
                rclpy.spin_once(node, timeout_sec=0.05)
            if status is None:
                self.timeouts += 1
            elif status["controller"]["command_issued"]:
                self.latencies.append(time.perf_counter() - sent)
        else:  # the newest status received so far (the node answers a sample or more later)
            rclpy.spin_once(node, timeout_sec=0.0)
            if node.statuses:
                self._last_status = node.statuses[max(node.statuses)]
                node.statuses.clear()
            status = self._last_status
        if node.commands:
            self.force = node.commands.pop(stamp, node.last_command)
            node.commands.clear()
        return self._output(status)

    def _output(self, status):
        if status is None:  # nothing from the controller: the gripper holds its command
            finger = SimpleNamespace(omega_hat=0.0, S=0.0, c_tilde=0.0, status=4)
            ctrl = SimpleNamespace(command_issued=0, pivot_finished=0, pivot_end=0,
                                   static_force=self.force, dynamic_force=0.0,
                                   mu_belief=self._mu, mode=0)
            return SimpleNamespace(force=self.force, status=4, controller=ctrl,
                                   fingers=[finger, finger])
        c = status["controller"]
        ctrl = SimpleNamespace(
            command_issued=int(c["command_issued"]), pivot_finished=int(c["pivot_finished"]),
            pivot_end=int(c["pivot_end"]), static_force=c["static_force"],
            dynamic_force=c["dynamic_force"], mu_belief=c["mu_belief"],
            mode=1 if c["mode"] == "PIVOTING" else 0)
        fingers = [SimpleNamespace(omega_hat=f["omega_hat"], S=f["S"], c_tilde=f["c_tilde"],
                                   status=int(f["status"])) for f in status["fingers"]]
        return SimpleNamespace(force=self.force, status=int(c["status"]), controller=ctrl,
                               fingers=fingers)


def run_ros_scenario(name: str, *, controller: str = "lugrip", short: bool = True,
                     lockstep: bool = True, timeout: float = 30.0,
                     node: GripperSimNode | None = None) -> dict[str, Any]:
    """Run scenario ``name`` on the MuJoCo plant with the controller node ``controller`` (which
    must be running; rclpy initialised). Returns {"scenario", "run" (the MujocoRun), "metrics"
    (lugrip's), "criteria" (the scenario's MuJoCo criteria that need no baseline run),
    "timeouts", "latencies" [s] (sample published -> its command received, lock-step)}."""
    from ..sim.scenarios import _evaluate, compute_metrics, load_scenario, simulate

    scn = load_scenario(name)
    if short:
        scn = scn.shortened()
    scn = scn.for_plant("mujoco")
    cfg = scn.plant_config("mujoco", None)
    own = node is None
    node = node or GripperSimNode(controller)
    proxies: list[RemoteSlipControl] = []

    def factory(*args, **kwargs):
        proxies.append(RemoteSlipControl(node, *args, lockstep=lockstep, **kwargs))
        return proxies[-1]

    try:
        node.wait_for_controller(timeout)
        run = simulate(scn, cfg, "mujoco", scn.schedule, controller_factory=factory)
    finally:
        if own:
            node.destroy_node()
    metrics = compute_metrics(scn, run, cfg=cfg)
    criteria = _evaluate(scn, {"lugrip": metrics}, None)
    proxy = proxies[0]
    return {"scenario": scn, "run": run, "metrics": metrics, "criteria": criteria,
            "timeouts": proxy.timeouts, "latencies": proxy.latencies}

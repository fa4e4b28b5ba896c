"""The lugrip ROS 2 node's latency and throughput over Fast DDS on loopback.

``lugrip ros run`` in its own process, pinned to one core (taskset); this script publishes two
fingertips' WrenchStamped at 500 Hz for ``--seconds`` and receives the node's outputs in a
second thread. Latency: from publishing a sample's second wrench to receiving the node's
``~/joint_command`` of that stamp (command samples, every 10th) and its ``~/status`` (every
sample); p50 / p99 / max. Throughput: ``--rates`` pushed for ``--burst`` s each; the fraction of
samples answered by a status, and the node's CPU time per sample (from /proc).

    python benchmarks/bench_ros_latency.py --seconds 60 --out BENCHMARKS.md
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import rclpy
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import WrenchStamped
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import JointState

sys.path.insert(0, str(Path(__file__).parent))
from sections import write_section  # noqa: E402

DOMAIN = 231


def _cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


class Receiver:
    def __init__(self):
        self.node = rclpy.create_node("lugrip_bench_receiver")
        self.status: dict[int, int] = {}
        self.command: dict[int, int] = {}
        self.node.create_subscription(DiagnosticArray, "/lugrip/status", self._status, 5000)
        self.node.create_subscription(JointState, "/lugrip/joint_command", self._command, 5000)
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        self.thread = threading.Thread(target=self._spin, daemon=True)
        self.thread.start()

    def _spin(self):
        try:
            self.executor.spin()
        except rclpy.executors.ExternalShutdownException:
            pass

    def _status(self, msg):
        self.status[msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec] = time.monotonic_ns()

    def _command(self, msg):
        self.command[msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec] = time.monotonic_ns()


def _publish(pubs, rate: float, seconds: float, base: int) -> dict[int, int]:
    """Wrenches at `rate` [Hz] (stamps 1/rate apart); returns stamp -> send time [ns]."""
    period = 1.0 / rate
    sent: dict[int, int] = {}
    rng = np.random.default_rng(1)
    n = int(seconds * rate)
    start = time.monotonic()
    for i in range(n):
        due = start + i * period
        while True:
            left = due - time.monotonic()
            if left <= 0:
                break
            time.sleep(min(left, 0.0005) if left > 0.0006 else 0)
        stamp = base + round(i * period * 1e9)
        for k, pub in enumerate(pubs):
            msg = WrenchStamped()
            msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp, 10**9)
            msg.header.frame_id = f"fingertip_{k}"
            msg.wrench.force.z = 5.0 + 0.01 * rng.standard_normal()
            msg.wrench.force.x = 0.5 + 0.01 * rng.standard_normal()
            msg.wrench.torque.z = 1e-4 + 1e-5 * rng.standard_normal()
            pub.publish(msg)
        sent[stamp] = time.monotonic_ns()
    return sent


def _percentiles(x) -> tuple[float, float, float]:
    a = np.asarray(x) / 1e6
    return float(np.percentile(a, 50)), float(np.percentile(a, 99)), float(a.max())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--rates", type=float, nargs="*", default=[500.0, 1000.0, 2000.0])
    ap.add_argument("--burst", type=float, default=5.0)
    ap.add_argument("--core", type=int, default=1)
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args(argv)

    env = dict(os.environ, ROS_DOMAIN_ID=str(DOMAIN), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST")
    cmd = [sys.executable, "-m", "lugrip", "ros", "run", "--ros-args", "-p", "qos_depth:=1000"]
    if shutil.which("taskset"):
        cmd = ["taskset", "-c", str(args.core), *cmd]
    node = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.environ.update(ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST")
    rclpy.init(domain_id=DOMAIN)
    try:
        rx = Receiver()
        tx = rclpy.create_node("lugrip_bench_sender")
        qos = QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT,
                         history=HistoryPolicy.KEEP_LAST, depth=1000)
        pubs = [tx.create_publisher(WrenchStamped, f"fingertip_{k}/wrench", qos) for k in (0, 1)]
        end = time.monotonic() + 60
        while not all(p.get_subscription_count() for p in pubs) and time.monotonic() < end:
            time.sleep(0.05)
        time.sleep(1.0)
        load0 = os.getloadavg()[0]
        cpu0 = _cpu_seconds(node.pid)
        sent = _publish(pubs, 500.0, args.seconds, 10**9)
        time.sleep(0.5)
        cpu = _cpu_seconds(node.pid) - cpu0
        lat_s = [rx.status[s] - t for s, t in sent.items() if s in rx.status]
        slow = sum(1 for s, t in sent.items() if s in rx.status and rx.status[s] - t > 1e7)
        lat_c = [rx.command[s] - t for s, t in sent.items() if s in rx.command]
        rows = []
        base = 10**9 + int(args.seconds * 1e9) + 10**9
        for rate in args.rates:
            rx.status.clear()
            c0 = _cpu_seconds(node.pid)
            burst = _publish(pubs, rate, args.burst, base)
            time.sleep(1.0)
            answered = sum(s in rx.status for s in burst) / len(burst)
            rows.append((rate, answered, (_cpu_seconds(node.pid) - c0) / len(burst) * 1e6))
            base += int(args.burst * 1e9) + 10**9
        load1 = os.getloadavg()[0]
    finally:
        rclpy.try_shutdown()
        node.terminate()
        node.wait(10)
    p_c, p_s = _percentiles(lat_c), _percentiles(lat_s)
    lines = [
        "<!-- ros:begin -->",
        "## ROS 2 node: wrench in to command out (Fast DDS, loopback)",
        "",
        f"`python benchmarks/bench_ros_latency.py --seconds {args.seconds:g}`: `lugrip ros run` "
        f"pinned to core {args.core} (taskset), two fingertips' WrenchStamped published at 500 Hz "
        f"for {args.seconds:g} s by another process on the same machine, both at normal priority "
        f"(ROS 2 Kilted pip wheels, "
        f"rclpy, Fast DDS; CPython {platform.python_version()}; load average {load0:.1f} before, "
        f"{load1:.1f} after, on a 2-core machine shared with other jobs).",
        "",
        "| from publishing a sample's wrenches to receiving | samples | p50 [ms] | p99 [ms] | max [ms] |",
        "|---|---:|---:|---:|---:|",
        f"| `~/joint_command` (command samples, 50 Hz) | {len(lat_c)} | {p_c[0]:.3f} | {p_c[1]:.3f} | {p_c[2]:.3f} |",
        f"| `~/status` (every sample) | {len(lat_s)} | {p_s[0]:.3f} | {p_s[1]:.3f} | {p_s[2]:.3f} |",
        "",
        f"Samples answered at 500 Hz: {len(lat_s)} of {len(sent)}, {slow} of them after more "
        f"than 10 ms; node CPU "
        f"{cpu / len(sent) * 1e6:.0f} µs per sample ({100 * cpu / args.seconds:.0f} % of its core).",
        "",
        f"| rate pushed [Hz] ({args.burst:g} s each) | samples answered | node CPU per sample [µs] |",
        "|---:|---:|---:|",
        *[f"| {r:g} | {100 * a:.1f} % | {c:.0f} |" for r, a, c in rows],
        "",
        "The latency includes both ends' rclpy (Python) work and the middleware; the core's own "
        "step is a few µs (section \"SlipControl from Python\"). The sustained rate is the "
        "highest pushed rate with every sample answered.",
        "<!-- ros:end -->",
        "",
    ]
    text = "\n".join(lines)
    print(text)
    if args.out is not None:
        write_section(args.out, text, "ros")
    return 0


if __name__ == "__main__":
    sys.exit(main())

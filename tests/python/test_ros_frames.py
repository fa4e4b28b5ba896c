"""The sensor-frame transform shared by the log readers and the ROS node
(lugrip.io.contact_wrench), and SlipControl.step's shape check. No ROS needed."""

from __future__ import annotations

import numpy as np
import pytest

import lugrip
from lugrip.io import contact_wrench


def test_contact_wrench_flip_and_offset_against_a_hand_computed_wrench():
    """Independent reference: a point contact at (x, y) on the pad surface z = -d below a
    sensor origin, force F and pure torsion t_z at the contact; the sensor measures
    M = r x F + (0, 0, t_z). The transform must return (F_z, F_x, F_y, t_z); flipped sensors
    (z toward the object) read the rotated wrench and must give the same row."""
    d, x, y = 0.012, 0.003, -0.002
    F = np.array([0.4, -0.7, 6.0])
    tz = 2.5e-3
    r = np.array([x, y, -d])
    M = np.cross(r, F) + [0.0, 0.0, tz]
    row = contact_wrench(F, M, contact_offset=d, floor=0.01)
    np.testing.assert_allclose(row, [F[2], F[0], F[1], tz], rtol=0, atol=1e-12)
    R = np.diag([1.0, -1.0, -1.0])  # the sensor's frame rotated by pi about x
    np.testing.assert_allclose(contact_wrench(R @ F, R @ M, flip_normal=True,
                                              contact_offset=d, floor=0.01),
                               row, atol=1e-12)
    # no offset: the moment's z is taken as it is
    np.testing.assert_allclose(contact_wrench(F, M), [F[2], F[0], F[1], M[2]])


def test_batch_and_row_agree_with_the_log_readers_rule():
    """A batch uses the log readers' floor (5 % of the median pressing force): tau moved to
    the centre of pressure above it (the formula written out here in numpy), m_z below; rows
    one by one with that floor give the same values."""
    rng = np.random.default_rng(3)
    f = np.c_[rng.normal(0, 0.5, (50, 2)), rng.uniform(0.0, 8.0, 50)]
    m = rng.normal(0, 1e-3, (50, 3))
    batch = contact_wrench(f, m, contact_offset=0.01)
    floor = max(1e-3, 0.05 * float(np.median(f[:, 2][f[:, 2] > 0])))
    x = -(m[:, 1] + 0.01 * f[:, 0]) / f[:, 2]
    y = (m[:, 0] - 0.01 * f[:, 1]) / f[:, 2]
    tau = np.where(f[:, 2] > floor, m[:, 2] - x * f[:, 1] + y * f[:, 0], m[:, 2])
    np.testing.assert_allclose(batch[:, 3], tau, rtol=1e-14, atol=1e-18)
    assert np.any(f[:, 2] <= floor) and np.any(f[:, 2] > floor)
    rows = np.array([contact_wrench(f[i], m[i], contact_offset=0.01, floor=floor)
                     for i in range(50)])
    np.testing.assert_allclose(rows, batch, rtol=0, atol=1e-15)
    with pytest.raises(ValueError, match="shape"):
        contact_wrench(np.zeros(2), np.zeros(3))


@pytest.mark.parametrize("shape", [(4, 2), (8,), (2, 4, 1), (1, 4), (3, 4)])
def test_step_refuses_any_shape_but_fingers_by_4(shape):
    """A transposed (4, 2) or flat (8,) array was read row by row; now every shape but
    (fingers, 4) is refused with a ValueError naming the shape. No plant."""
    sc = lugrip.SlipControl(lugrip.ContactParams.table1())
    with pytest.raises(ValueError, match=r"per finger, a \(2, 4\) array"):
        sc.step(np.ones(shape))
    assert sc.step(np.tile([5.0, 0.1, 0.0, 1e-4], (2, 1))).force > 0
    one = lugrip.SlipControl(lugrip.ContactParams.table1(), fingers=1)
    assert one.step([5.0, 0.1, 0.0, 1e-4]).force > 0
    with pytest.raises(ValueError, match=r"a \(1, 4\) array, or \(4,\)"):
        one.step(np.ones((4, 2)))


def _write_pose_mcap(out, t, omega_of, angle_of, f_n=5.0):
    """A rosbag2 MCAP (rosbags' writer, no ROS needed) with a WrenchStamped and a PoseStamped
    whose orientation is a fixed 20 degree swing about x composed with a twist of
    angle_of(t) about z (q = q_swing q_twist: the twist about z is angle_of(t), the swing
    must be left out)."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_KILTED)
    T = ts.types
    Time, Header = T["builtin_interfaces/msg/Time"], T["std_msgs/msg/Header"]
    V, W, WS = T["geometry_msgs/msg/Vector3"], T["geometry_msgs/msg/Wrench"], T["geometry_msgs/msg/WrenchStamped"]
    P, PS = T["geometry_msgs/msg/Pose"], T["geometry_msgs/msg/PoseStamped"]
    Pt, Q = T["geometry_msgs/msg/Point"], T["geometry_msgs/msg/Quaternion"]
    wt, pt = "geometry_msgs/msg/WrenchStamped", "geometry_msgs/msg/PoseStamped"
    with Writer(out, version=9, storage_plugin=StoragePlugin.MCAP) as w:
        cw = w.add_connection("/fingertip_0/wrench", wt, typestore=ts)
        cp = w.add_connection("/truth/pose", pt, typestore=ts)
        for ti in t:
            ns = 10**9 + int(round(ti * 1e9))
            h = Header(stamp=Time(sec=ns // 10**9, nanosec=ns % 10**9), frame_id="fingertip_0")
            w.write(cw, ns, ts.serialize_cdr(WS(header=h, wrench=W(
                force=V(x=0.3, y=0.0, z=f_n), torque=V(x=0.0, y=0.0, z=1e-4))), wt))
            a = angle_of(ti)
            # q_swing(x, b) q_twist(z, a) written out, with a sign flip of the quaternion on
            # every other sample (q and -q are one rotation)
            s = -1.0 if int(round(ti * 500)) % 2 else 1.0
            px, pw = np.sin(np.radians(10.0)), np.cos(np.radians(10.0))
            qz, qw = np.sin(a / 2), np.cos(a / 2)
            q = Q(x=s * qw * px, y=-s * px * qz, z=s * pw * qz, w=s * pw * qw)
            w.write(cp, ns, ts.serialize_cdr(PS(header=h, pose=P(position=Pt(x=0.0, y=0.0, z=0.0),
                                                                   orientation=q)), pt))
    return out / f"{out.name}.mcap"


def test_pose_topic_as_ground_truth_is_differentiated(tmp_path):
    """Independent reference: an analytic twist angle(t) = 0.8 sin(2 pi 3 t) + 7 t rad (past
    pi, so it must be unwrapped) under a fixed 20 degree swing, quaternion signs alternating:
    omega read from the PoseStamped topic equals its derivative within the central-difference
    error. No plant."""
    from lugrip.io import read_log

    t = np.arange(0, 1.0, 0.002)
    angle = lambda x: 0.8 * np.sin(2 * np.pi * 3 * x) + 7.0 * x  # noqa: E731
    rate = lambda x: 0.8 * 2 * np.pi * 3 * np.cos(2 * np.pi * 3 * x) + 7.0  # noqa: E731
    path = _write_pose_mcap(tmp_path / "run", t, rate, angle)
    log = read_log(path, wrench_topic="/fingertip_0/wrench", omega_topic="/truth/pose")
    # central differences: error <= h^2/6 max|angle'''| = (0.002^2 / 6) 0.8 (6 pi)^3
    bound = 0.002**2 / 6 * 0.8 * (6 * np.pi) ** 3
    inner = slice(1, -1)
    np.testing.assert_allclose(log.omega[inner], rate(log.t[inner]), rtol=0, atol=1.01 * bound)
    assert "atan2" in log.meta["omega_method"]
    np.testing.assert_array_equal(log.f_n, 5.0)

"""ROS recordings through ``lugrip observe``: bags written in the test with rosbags' own writers
and serialisers (no ROS installation), read back through rosbags' typestore, compared with the
same samples in CSV; maneuvers from a topic, windows or the motion; the wrench moved from the
sensor origin to the contact; hints in command-line syntax; a missing [io] extra.

These are I/O tests: the samples come from lugrip's synthetic slider (``simulate_maneuvers``),
but what is checked is that every container gives the observer the same numbers, so the plant
does not matter here. The contact-offset test builds the sensor-origin wrench from rigid-body
statics (r x F), independently of the reader's formula."""

from __future__ import annotations

import csv
import sys

import numpy as np
import pytest
from lugrip import ContactParams, LogError, LogWarning, read_log, write_log
from lugrip.cli import main
from lugrip.io import find_maneuvers, maneuvers_from_windows
from lugrip.sliding import simulate_maneuvers

typesys = pytest.importorskip("rosbags.typesys", reason="rosbags not installed")

T0_NS = 1_700_000_000_000_000_000


@pytest.fixture(scope="module")
def data():
    """Six Table 1 maneuvers (~2500 samples at 500 Hz) with ground-truth omega."""
    return simulate_maneuvers(ContactParams.table1(), 6, seed=17)


def _store(ros1):
    return typesys.get_typestore(typesys.Stores.ROS1_NOETIC if ros1
                                 else typesys.Stores.ROS2_HUMBLE)


def _header(ts, ros1, stamp_ns, frame):
    T = ts.types
    sec, nsec = divmod(int(stamp_ns), 1_000_000_000)
    stamp = T["builtin_interfaces/msg/Time"](sec=sec, nanosec=nsec)
    if ros1:
        return T["std_msgs/msg/Header"](seq=0, stamp=stamp, frame_id=frame)
    return T["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)


def write_two_finger_bag(path, log, *, ros1, with_maneuvers=True, torque_xy=None,
                         stamps=None, command=None, finger1_delay_ns=0):
    """Two WrenchStamped topics (finger 0 = the log, finger 1 its mirror, stamped
    ``finger1_delay_ns`` later), a TwistStamped ground truth, optionally the maneuver ids as
    std_msgs/Int32 at each change and a std_msgs/Float64 command per sample."""
    ts = _store(ros1)
    T = ts.types
    if ros1:
        from rosbags.rosbag1 import Writer

        writer, ser = Writer(path), ts.serialize_ros1
    else:
        from rosbags.rosbag2 import Writer

        writer, ser = Writer(path, version=9), ts.serialize_cdr
    V = T["geometry_msgs/msg/Vector3"]
    W, WS = T["geometry_msgs/msg/Wrench"], T["geometry_msgs/msg/WrenchStamped"]
    TW, TWS = T["geometry_msgs/msg/Twist"], T["geometry_msgs/msg/TwistStamped"]
    I32 = T["std_msgs/msg/Int32"]
    if stamps is None:
        stamps = T0_NS + np.round(log.t * 1e9).astype(np.int64)
    mx = np.zeros(len(log)) if torque_xy is None else torque_xy[:, 0]
    my = np.zeros(len(log)) if torque_xy is None else torque_xy[:, 1]
    wt, tt, it = ("geometry_msgs/msg/WrenchStamped", "geometry_msgs/msg/TwistStamped",
                  "std_msgs/msg/Int32")
    with writer:
        c0 = writer.add_connection("/finger0/wrench", wt, typestore=ts)
        c1 = writer.add_connection("/finger1/wrench", wt, typestore=ts)
        ct = writer.add_connection("/truth/twist", tt, typestore=ts)
        cm = writer.add_connection("/maneuver", it, typestore=ts) if with_maneuvers else None
        ft = "std_msgs/msg/Float64"
        cc = writer.add_connection("/gripper/command", ft, typestore=ts) if command is not None \
            else None
        for i, s in enumerate(stamps.tolist()):
            if cm is not None and (i == 0 or log.maneuver[i] != log.maneuver[i - 1]):
                writer.write(cm, s, ser(I32(data=int(log.maneuver[i])), it))
            for conn, sign, delay in ((c0, 1.0, 0), (c1, -1.0, finger1_delay_ns)):
                msg = WS(header=_header(ts, ros1, s + delay, "pad"), wrench=W(
                    force=V(float(log.f_x[i]), sign * float(log.f_y[i]), float(log.f_n[i])),
                    torque=V(float(mx[i]), float(my[i]), sign * float(log.tau[i]))))
                writer.write(conn, s + delay + 20_000, ser(msg, wt))  # log: 20 us after stamp
            if cc is not None:
                writer.write(cc, s + 10_000, ser(T[ft](data=float(command[i])), ft))
            tw = TWS(header=_header(ts, ros1, s, "pad"),
                     twist=TW(linear=V(0.0, 0.0, 0.0), angular=V(0.0, 0.0,
                                                                 float(log.omega[i]))))
            writer.write(ct, s + 30_000, ser(tw, tt))
    return path


def _estimates(path):
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    cols = {name: [r[i] for r in rows[1:]] for i, name in enumerate(rows[0])}
    return {k: (np.asarray(v, dtype=float) if k not in ("status",) else v)
            for k, v in cols.items()}


def _observe(capsys, *argv):
    rc = main(["observe", *map(str, argv)])
    out = capsys.readouterr()
    assert rc == 0, out.err
    return out.out


@pytest.mark.parametrize("ros1", [True, False], ids=["ros1", "ros2"])
def test_bag_gives_the_csv_observe_results(tmp_path, capsys, data, ros1):
    """A ROS 1 / ROS 2 bag with two wrench topics, a twist ground truth and a maneuver topic
    gives the observer the CSV's samples: equal estimates per sample, equal scores."""
    csv_log = write_log(data.log, tmp_path / "run.csv")
    bag = write_two_finger_bag(tmp_path / ("run.bag" if ros1 else "run"), data.log, ros1=ros1)
    out_csv = _observe(capsys, csv_log, "--preset", "table1", "--out", tmp_path / "e_csv.csv")
    out_bag = _observe(capsys, bag, "--preset", "table1", "--out", tmp_path / "e_bag.csv",
                       "--wrench-topic", "/finger0/wrench", "--omega-topic", "/truth/twist",
                       "--maneuver-topic", "/maneuver")
    a, b = _estimates(tmp_path / "e_csv.csv"), _estimates(tmp_path / "e_bag.csv")
    np.testing.assert_array_equal(a["maneuver"], b["maneuver"])
    assert a["status"] == b["status"]
    # the bag's times are whole nanoseconds: equal to the CSV's to 1e-9 s, estimates to 1e-9
    np.testing.assert_allclose(b["t"], a["t"], rtol=0, atol=1e-9)
    for col in ("omega_hat", "z_hat", "c_tilde", "S"):
        np.testing.assert_allclose(b[col], a[col], rtol=1e-9, atol=1e-9, err_msg=col)

    def scores(text):
        return [line for line in text.splitlines() if "RMSE" in line or "delay" in line]

    assert scores(out_csv) and scores(out_csv) == scores(out_bag)


def test_maneuvers_found_from_the_motion(tmp_path, capsys, data):
    """Without a maneuver topic and with --maneuvers file the observer never restarts;
    --maneuvers motion finds one maneuver per simulated maneuver (boundaries inside the
    unloaded rests) and brings the estimates back to the CSV's: their RMS difference is under a
    fifth of the no-restart one (measured: 1.5e-5 against 3.6e-4 rad/s). The default ('auto')
    is 'motion' for a recording without a maneuver topic: the same estimates."""
    log = data.log
    found = find_maneuvers(log)
    n_true = len(np.unique(log.maneuver))
    assert len(np.unique(found)) == n_true
    # each found start lies in the rest between two designed maneuvers
    starts = np.flatnonzero(np.diff(found)) + 1
    true_starts = np.flatnonzero(np.diff(log.maneuver)) + 1
    rest = round(0.2 / 0.002)
    assert np.all(np.abs(starts - true_starts) <= rest)

    write_log(log, tmp_path / "run.csv")
    bag = write_two_finger_bag(tmp_path / "bare", log, ros1=False, with_maneuvers=False)
    _observe(capsys, tmp_path / "run.csv", "--preset", "table1", "--out", tmp_path / "a.csv")
    _observe(capsys, bag, "--preset", "table1", "--out", tmp_path / "none.csv",
             "--wrench-topic", "/finger0/wrench", "--omega-topic", "/truth/twist",
             "--maneuvers", "file")
    _observe(capsys, bag, "--preset", "table1", "--out", tmp_path / "motion.csv",
             "--wrench-topic", "/finger0/wrench", "--omega-topic", "/truth/twist",
             "--maneuvers", "motion")
    _observe(capsys, bag, "--preset", "table1", "--out", tmp_path / "auto.csv",
             "--wrench-topic", "/finger0/wrench", "--omega-topic", "/truth/twist")
    ref = _estimates(tmp_path / "a.csv")["omega_hat"]
    none = _estimates(tmp_path / "none.csv")["omega_hat"]
    motion = _estimates(tmp_path / "motion.csv")["omega_hat"]
    np.testing.assert_array_equal(_estimates(tmp_path / "auto.csv")["omega_hat"], motion)
    ok = np.isfinite(ref) & np.isfinite(none) & np.isfinite(motion)
    rms_none = float(np.sqrt(np.mean((none[ok] - ref[ok]) ** 2)))
    rms_motion = float(np.sqrt(np.mean((motion[ok] - ref[ok]) ** 2)))
    assert rms_none > 5 * rms_motion, (rms_none, rms_motion)


def test_maneuver_windows(tmp_path, data):
    """Time windows number the samples inside them 1, 2, ... and the rest 0; bad windows are
    a LogError naming the window."""
    t = np.arange(10) * 0.1
    ids = maneuvers_from_windows(t, [(0.2, 0.5), (0.6, 0.8)])
    np.testing.assert_array_equal(ids, [0, 0, 1, 1, 1, 0, 2, 2, 0, 0])
    with pytest.raises(LogError, match="windows 1 and 2 overlap"):
        maneuvers_from_windows(t, [(0.0, 0.5), (0.4, 0.8)])
    with pytest.raises(LogError, match="window 1"):
        maneuvers_from_windows(t, [(0.5, 0.5)])
    path = write_log(data.log, tmp_path / "w.csv")
    log = read_log(path, maneuvers=[(0.0, 1.0), (1.0, 2.0)])
    assert log.meta["maneuvers_from"] == "windows"
    assert set(np.unique(log.maneuver)) == {0, 1, 2}
    assert np.all(log.maneuver[log.t < 1.0] == 1)


def test_wrench_at_the_sensor_origin_moved_to_the_contact(tmp_path):
    """A pad 6 mm thick: the contact force acts at the centre of pressure (x, y) on the
    surface, 6 mm in front of the sensor origin, with a torsional moment tau about the normal.
    The sensor reads M = r x F + tau z at its origin (statics, written out here); with
    --contact-offset the reader recovers tau, without it the torque.z it reads is off."""
    rng = np.random.default_rng(2)
    n, d = 300, 0.006
    t = np.arange(n) * 0.002
    f = np.c_[rng.uniform(-1, 1, (n, 2)), rng.uniform(2, 8, n)]  # object on fingertip
    cop = rng.uniform(-0.004, 0.004, (n, 2))
    tau = rng.uniform(-0.004, 0.004, n)
    r = np.c_[cop, np.full(n, -d)]  # the surface lies at z = -d (z points into the pad)
    m = np.cross(r, f) + np.c_[np.zeros((n, 2)), tau]

    rec = _Record(t=t, f_x=f[:, 0], f_y=f[:, 1], f_n=f[:, 2], tau=m[:, 2], omega=np.zeros(n),
                  maneuver=np.zeros(n, dtype=int))
    bag = write_two_finger_bag(tmp_path / "pad", rec, ros1=False, torque_xy=m[:, :2])
    moved = read_log(bag, wrench_topic="/finger0/wrench", contact_offset=d)
    np.testing.assert_allclose(moved.tau, tau, rtol=0, atol=1e-12)
    raw = read_log(bag, wrench_topic="/finger0/wrench", check_units=False)
    assert np.max(np.abs(raw.tau - tau)) > 1e-3
    assert moved.meta["contact_offset"] == d


class _Record:
    """Arrays under the names write_two_finger_bag reads, with the length of ``t``."""

    def __init__(self, **arrays):
        self.__dict__.update(arrays)

    def __len__(self):
        return len(self.t)


def test_duplicated_stamps_are_dropped_not_fatal(tmp_path, data):
    """Three duplicated header stamps: a warning naming the topic and first message, the three
    messages dropped, the rest read."""
    log = data.log.select(slice(0, 400))
    stamps = T0_NS + np.round(log.t * 1e9).astype(np.int64)
    stamps[[50, 51]] = stamps[49]
    stamps[200] = stamps[199]
    bag = write_two_finger_bag(tmp_path / "dup.bag", log, ros1=True, stamps=stamps)
    with pytest.warns(LogWarning, match=r"'/finger0/wrench': 3 message\(s\) with a duplicated "
                                        r"time, first message 51"):
        got = read_log(bag, wrench_topic="/finger0/wrench", omega_topic="/truth/twist",
                       maneuver_topic="/maneuver")
    keep = np.setdiff1d(np.arange(400), [50, 51, 200])
    assert len(got) == 397
    np.testing.assert_array_equal(got.tau, log.tau[keep])
    # messages after the dropped ones are still named by their number in the recording
    tau = log.tau.copy()
    tau[300] = np.nan
    rec = _Record(t=log.t, f_x=log.f_x, f_y=log.f_y, f_n=log.f_n, tau=tau, omega=log.omega,
                  maneuver=log.maneuver)
    bag = write_two_finger_bag(tmp_path / "dup_nan.bag", rec, ros1=True, stamps=stamps)
    with pytest.warns(LogWarning, match=r"message 301 on topic '/finger0/wrench' \(tau\)"):
        read_log(bag, wrench_topic="/finger0/wrench")


def test_cli_hints_use_option_syntax(tmp_path, capsys, data):
    """A torque in N mm is caught; the CLI's message says --units tau=N_mm (and the Python
    message units={'tau': 'N mm'}); the CLI option then reads it."""
    lg = data.log
    mm = type(lg)(t=lg.t, f_n=lg.f_n, f_t=lg.f_t, tau=lg.tau * 1000.0, f_x=lg.f_x, f_y=lg.f_y,
                  omega=lg.omega, maneuver=lg.maneuver)
    path = write_log(mm, tmp_path / "mm.csv")
    with pytest.raises(LogError, match=r"units=\{'tau': 'N mm'\}"):
        read_log(path)
    rc = main(["observe", str(path), "--preset", "table1", "--out", str(tmp_path / "e.csv")])
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1
    assert "--units tau=N_mm" in err and "units={" not in err
    _observe(capsys, path, "--preset", "table1", "--out", tmp_path / "e.csv",
             "--units", "tau=N_mm")
    rc = main(["observe", str(path), "--preset", "table1", "--out", str(tmp_path / "f.csv"),
               "--units", "tau"])
    assert rc == 2 and "COLUMN=UNIT" in capsys.readouterr().err


@pytest.mark.parametrize("suffix,module", [(".mcap", "mcap"), (".parquet", "pyarrow"),
                                           (".bag", "rosbags")])
def test_missing_io_extra_is_one_line_exit_2(tmp_path, capsys, monkeypatch, suffix, module):
    """Without the [io] packages, reading .mcap/.parquet/bags exits 2 with one line naming
    the extra (simulated by hiding the package from the import system)."""
    path = tmp_path / f"x{suffix}"
    path.write_bytes(b"not really")
    for name in list(sys.modules):
        if name == module or name.startswith(module + "."):
            monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, module, None)  # import raises ImportError
    rc = main(["observe", str(path), "--preset", "table1", "--out", str(tmp_path / "e.csv")])
    err = capsys.readouterr().err
    assert rc == 2, err
    assert len(err.strip().splitlines()) == 1
    assert "lugrip[io]" in err and "Traceback" not in err


# ---------------------------------------------------------------------------------------------
# Two-finger logs (the input of lugrip replay)
# ---------------------------------------------------------------------------------------------

def test_two_finger_table_round_trip_and_missing_columns(tmp_path, data):
    """write_grasp_log / read_grasp_log: per-finger suffixes, command, maneuver, bit-exact;
    a missing finger-1 column is named with its suffix."""
    from lugrip.io import GraspLog, read_grasp_log, write_grasp_log

    log = data.log
    n = len(log)
    w0 = np.stack([log.f_n, log.f_x, log.f_y, log.tau], axis=1)
    w1 = w0 * [1.0, 1.0, -1.0, -1.0]
    command = np.linspace(2.0, 5.0, n)
    g = GraspLog(t=log.t, wrench=np.stack([w0, w1], axis=1), command=command,
                 maneuver=log.maneuver, fingers=(log, log))
    for suffix in (".csv", ".parquet"):
        path = write_grasp_log(g, tmp_path / f"grasp{suffix}")
        back = read_grasp_log(path)
        np.testing.assert_array_equal(back.t, log.t)
        np.testing.assert_array_equal(back.wrench, g.wrench)
        np.testing.assert_array_equal(back.command, command)
        np.testing.assert_array_equal(back.maneuver, log.maneuver)
    bad = tmp_path / "one_finger.csv"
    bad.write_text("t,f_n_0,f_x_0,f_y_0,tau_0,f_n_1,f_x_1,f_y_1\n0,2,0,0.1,0.0001,2,0,0.1\n")
    with pytest.raises(LogError, match=r"missing required column\(s\) 'tau_1'"):
        read_grasp_log(bad)


@pytest.mark.parametrize("ros1", [True, False], ids=["ros1", "ros2"])
def test_two_finger_bag_on_finger0_clock(tmp_path, data, ros1):
    """Two wrench topics (finger 1 stamped 0.7 ms after finger 0) and a command topic: finger 1
    and the command are held at their latest value at or before each finger-0 sample."""
    from lugrip.io import read_grasp_log

    log = data.log.select(slice(0, 600))
    command = 3.0 + 0.001 * np.arange(len(log))
    bag = write_two_finger_bag(tmp_path / ("g.bag" if ros1 else "g"), log, ros1=ros1,
                               command=command, finger1_delay_ns=700_000)
    g = read_grasp_log(bag, finger_topics=["/finger0/wrench", "/finger1/wrench"],
                       command_topic="/gripper/command", maneuver_topic="/maneuver")
    np.testing.assert_allclose(g.t, log.t, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(g.wrench[:, 0, 0], log.f_n)
    # finger 1's sample k arrives 0.7 ms after finger 0's sample k: at finger 0's sample k
    # the latest finger-1 sample is k - 1 (none before the first)
    assert np.all(np.isnan(g.wrench[0, 1, :]))
    np.testing.assert_array_equal(g.wrench[1:, 1, 3], -log.tau[:-1])
    np.testing.assert_array_equal(g.wrench[1:, 1, 0], log.f_n[:-1])
    # the command (unstamped) is compared by log time: sent 10 us before finger 0's sample k
    # is logged, so it is the command of sample k
    np.testing.assert_array_equal(g.command, command)
    np.testing.assert_array_equal(g.maneuver, log.maneuver)
    with pytest.raises(LogError, match="wrench topic of each finger"):
        read_grasp_log(bag)


def test_mcap_decoders_agree(tmp_path, monkeypatch, data):
    """An MCAP decoded by mcap-ros2-support and by rosbags' typestore (the fallback when
    mcap-ros2-support is missing) gives the same log."""
    pytest.importorskip("mcap_ros2.decoder", reason="mcap-ros2-support not installed")
    path = write_log(data.log, tmp_path / "d.mcap")
    with_mcap_ros2 = read_log(path)
    monkeypatch.setitem(sys.modules, "mcap_ros2.decoder", None)
    with_typestore = read_log(path)
    for name in ("t", "f_n", "f_x", "f_y", "tau", "omega", "maneuver"):
        np.testing.assert_array_equal(getattr(with_mcap_ros2, name),
                                      getattr(with_typestore, name), err_msg=name)
    np.testing.assert_array_equal(with_typestore.tau, data.log.tau)


@pytest.mark.filterwarnings("ignore:the optimiser stopped without convergence")
def test_bag_gives_the_csv_identify_results(tmp_path, data):
    """Identification (mu and beta_A free, the rest fixed at Table 1) on the bag's samples
    gives the CSV's estimates: the reader hands identification the same numbers (8 iterations:
    the comparison needs equal inputs, not a converged fit)."""
    import lugrip

    p = ContactParams.table1()
    log = data.log.select(data.log.maneuver < 3)  # three maneuvers keep the fit short
    csv_log = read_log(write_log(log, tmp_path / "run.csv"))
    bag = write_two_finger_bag(tmp_path / "run.bag", log, ros1=True)
    bag_log = read_log(bag, wrench_topic="/finger0/wrench", omega_topic="/truth/twist",
                       maneuver_topic="/maneuver")
    fits = [lugrip.identify([lg], params0=p, free=["mu", "beta_a"], threads=1,
                            max_iterations=8) for lg in (csv_log, bag_log)]
    for name in ("mu", "beta_a"):
        a, b = (getattr(f.params, name) for f in fits)
        assert b == pytest.approx(a, rel=1e-8), name


def test_maneuvers_found_on_an_independent_plant():
    """The distributed grid-of-cells rig (its own physics: Stribeck friction, Hertzian
    pressure, force and torque offsets, normal-force ripple) under prescribed rubbing: every
    maneuver start is found, inside the 0.1 s approach that begins it (tuned on seeds 1-8,
    this is held-out seed 11)."""
    from lugrip.rigs import make_rig

    log = make_rig("grid-stribeck").simulate(n=10, seed=11).log
    found = np.flatnonzero(np.diff(find_maneuvers(log))) + 1
    true = np.flatnonzero(np.diff(log.maneuver)) + 1
    assert len(found) == len(true) == 9
    lag = found - true
    assert np.all((lag >= 0) & (lag <= 0.1 * 500)), lag


def test_identify_cli_reads_bags_with_the_observe_options(tmp_path, capsys, data):
    """`lugrip identify` takes observe's log options (--wrench-topic, --omega-topic,
    --maneuver-topic): the bag gives the CSV's fitted mu and beta_A (8 iterations; the
    comparison needs equal inputs, not a converged fit)."""
    import yaml

    log = data.log.select(data.log.maneuver < 4)
    csv_log = write_log(log, tmp_path / "run.csv")
    bag = write_two_finger_bag(tmp_path / "run.bag", log, ros1=True)
    start = tmp_path / "table1.yaml"
    ContactParams.table1().to_yaml(start)
    common = ["--params0", start, "--free", "mu,beta_a", "--max-iterations", "8", "--threads",
              "1", "--quiet"]
    fitted = []
    for name, src, extra in (("csv", csv_log, []),
                             ("bag", bag, ["--wrench-topic", "/finger0/wrench", "--omega-topic",
                                           "/truth/twist", "--maneuver-topic", "/maneuver"])):
        out = tmp_path / f"fit_{name}.yaml"
        rc = main(["identify", *map(str, [src, *common, *extra, "--out", out])])
        err = capsys.readouterr().err
        assert rc in (0, 3), err
        fitted.append(yaml.safe_load(out.read_text())["contact"])
    for key in ("mu", "beta_a"):
        a, b = fitted[0][key]["value"], fitted[1][key]["value"]
        assert b == pytest.approx(a, rel=1e-8), key
    # without the topic option the bag's two wrench topics are ambiguous: exit 2, one line
    rc = main(["identify", str(bag), *map(str, common), "--out", str(tmp_path / "x.yaml")])
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1, err

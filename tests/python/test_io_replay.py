"""``lugrip replay``: a two-finger grasp recorded from the closed-loop simulator (patch plant:
a distributed contact patch, its own physics) is replayed through SlipControl.

The recorded command comes from the same SlipControl settings inside the closed loop, so
getting it back to rounding is a consistency test of the replay path (log format, finger order,
clock, start force, settings), not of the controller; the bag test checks that a ROS recording
of the same grasp replays like the table; the other tests check that the replay reacts to
different parameters and holds the command through a contact loss in the log."""

from __future__ import annotations

import csv
import re

import numpy as np
import pytest
import yaml
from lugrip.cli import main
from lugrip.io import GraspLog, write_grasp_log
from lugrip.sim._closed_loop import estimator_params, run_closed_loop
from lugrip.sim.scenarios import load_scenario

DURATION = 6.0  # [s] lift at 1-4 s: loaded grasp, slip on lift-off


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """Experiment 1 (big resin block), 6 s in closed loop: the sensors' wrenches and the
    command sent, as a two-finger CSV; the parameters and settings the loop used as files."""
    d = tmp_path_factory.mktemp("replay")
    scn = load_scenario("exp1_big_resin_block").shortened()
    cfg = scn.plant_config(None, None)
    est = scn.estimator_for(cfg.model)
    run = run_closed_loop(cfg, scn.controller, scn.observer, scn.schedule, DURATION,
                          estimator=est)
    n = len(run["t"])
    w = np.zeros((n, 2, 4))
    for k in range(2):  # the loop's sensors give f_t: f_x = 0, f_y = f_t
        w[:, k, 0] = run[f"f_n_meas_{k}"]
        w[:, k, 2] = run[f"f_t_meas_{k}"]
        w[:, k, 3] = run[f"tau_meas_{k}"]
    glog = GraspLog(t=np.asarray(run["t"]), wrench=w, command=np.asarray(run["command"]),
                    maneuver=np.zeros(n, dtype=np.int64), fingers=())
    log_path = write_grasp_log(glog, d / "grasp.csv")
    params = d / "estimator.yaml"
    estimator_params(cfg.contact, est).to_yaml(params)
    settings = d / "settings.yaml"
    ratio = round(cfg.sensor.rate / cfg.actuator.command_rate)
    settings.write_text(yaml.safe_dump({
        "controller": {**scn.controller, "command_ratio": ratio},
        "observer": {**scn.observer, "torque_noise": float(cfg.sensor.torque_noise)}}))
    return {"dir": d, "log": log_path, "params": params, "settings": settings, "glog": glog}


def _replay(capsys, *argv):
    rc = main(["replay", *map(str, argv)])
    out = capsys.readouterr()
    return rc, out.out, out.err


def _table(path):
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    return {name: [r[i] for r in rows[1:]] for i, name in enumerate(rows[0])}


def _floats(col):
    return np.array([float(v) if v else np.nan for v in col])


def test_replay_reproduces_the_closed_loop_command(tmp_path, capsys, recorded):
    """Same parameters and settings as the loop: the replayed command is the recorded one to
    rounding; the summary and the figure are written."""
    out = tmp_path / "r.csv"
    rc, text, err = _replay(capsys, recorded["log"], "--params", recorded["params"],
                            "--settings", recorded["settings"], "--out", out,
                            "--plot", tmp_path / "fig")
    assert rc == 0, err
    got = _table(out)
    rec, rep = _floats(got["command_recorded"]), _floats(got["command_replay"])
    np.testing.assert_array_equal(rec, recorded["glog"].command)
    np.testing.assert_allclose(rep, rec, rtol=0, atol=1e-9)
    assert rep.max() > rep.min() + 0.5  # the command moved: the comparison is not trivial
    rms = float(re.search(r"RMS ([-+0-9.e]+) N", text).group(1))
    assert rms < 1e-9
    assert (tmp_path / "fig" / "replay_command.png").stat().st_size > 10_000
    assert set(got["status"]) <= {"ok", "no_contact", "invalid_sample", "saturated",
                                  "degenerate", "sensor_fault", "reinitialized"}
    # the belief and the reserve: mu as told (the probe is off by default), a reserve that is
    # never negative and below the load the 0.7 kg block puts on a finger (m g / 2 = 3.4 N)
    mu = _floats(got["mu_belief"])
    told = yaml.safe_load(recorded["params"].read_text())["contact"]["mu"]["value"]
    np.testing.assert_allclose(mu, told, rtol=1e-12)
    r = _floats(got["reserve_force"])
    assert np.all(r >= 0.0) and np.all(r < 3.4)
    assert np.all(_floats(got["reserve_torque"]) >= 0.0)


def test_replay_reacts_to_the_parameters(tmp_path, capsys, recorded):
    """A wrong friction coefficient (the Table 1 cardboard instead of the resin block) makes
    the replay command a different force: a nonzero difference, reported."""
    out = tmp_path / "r.csv"
    rc, text, err = _replay(capsys, recorded["log"], "--preset", "table1",
                            "--settings", recorded["settings"], "--out", out)
    assert rc == 0, err
    got = _table(out)
    d = _floats(got["command_replay"]) - _floats(got["command_recorded"])
    assert np.sqrt(np.mean(d * d)) > 0.05
    assert "replay - recorded" in text


def test_contact_loss_in_the_log_holds_the_command(tmp_path, capsys, recorded):
    """0.2 s of f_n = 0 on finger 1 in the middle of the hold: the replayed command never
    decreases during the loss and the cycles are flagged held."""
    g = recorded["glog"]
    w = g.wrench.copy()
    t = g.t
    lost = (t >= 4.5) & (t < 4.7)
    w[lost, 1, :] = 0.0
    path = write_grasp_log(GraspLog(t=t, wrench=w, command=g.command, maneuver=g.maneuver,
                                    fingers=()), tmp_path / "lost.csv")
    out = tmp_path / "r.csv"
    rc, text, err = _replay(capsys, path, "--params", recorded["params"], "--settings",
                            recorded["settings"], "--out", out)
    assert rc == 0, err
    got = _table(out)
    rep = _floats(got["command_replay"])
    held = np.array([int(v) for v in got["held"]], dtype=bool)
    idx = np.flatnonzero(lost)
    assert np.all(np.diff(rep[idx[0] - 1: idx[-1] + 1]) >= 0.0)
    assert held[idx].mean() > 0.9
    assert "held the command" in text


def test_bag_replays_like_the_table(tmp_path, capsys, recorded):
    """The same grasp as a ROS 2 bag (one WrenchStamped topic per finger, a Float64 command
    topic) replays to the table's command."""
    typesys = pytest.importorskip("rosbags.typesys")
    from rosbags.rosbag2 import Writer

    g = recorded["glog"]
    ts = typesys.get_typestore(typesys.Stores.ROS2_HUMBLE)
    T = ts.types
    V = T["geometry_msgs/msg/Vector3"]
    wt, ft = "geometry_msgs/msg/WrenchStamped", "std_msgs/msg/Float64"
    stamps = 1_700_000_000_000_000_000 + np.round(g.t * 1e9).astype(np.int64)
    bag = tmp_path / "grasp"
    with Writer(bag, version=9) as writer:
        conns = [writer.add_connection(f"/finger{k}/wrench", wt, typestore=ts) for k in (0, 1)]
        cc = writer.add_connection("/gripper/command", ft, typestore=ts)
        for i, s in enumerate(stamps.tolist()):
            sec, nsec = divmod(s, 1_000_000_000)
            header = T["std_msgs/msg/Header"](
                stamp=T["builtin_interfaces/msg/Time"](sec=sec, nanosec=nsec), frame_id="pad")
            writer.write(cc, s, ts.serialize_cdr(T[ft](data=float(g.command[i])), ft))
            for k, conn in enumerate(conns):
                f_n, f_x, f_y, tau = (float(v) for v in g.wrench[i, k])
                msg = T[wt](header=header, wrench=T["geometry_msgs/msg/Wrench"](
                    force=V(f_x, f_y, f_n), torque=V(0.0, 0.0, tau)))
                writer.write(conn, s + 1000, ts.serialize_cdr(msg, wt))
    out_bag, out_csv = tmp_path / "b.csv", tmp_path / "c.csv"
    common = ["--params", recorded["params"], "--settings", recorded["settings"]]
    rc, _, err = _replay(capsys, bag, *common, "--out", out_bag, "--finger-topics",
                         "/finger0/wrench", "/finger1/wrench", "--command-topic",
                         "/gripper/command")
    assert rc == 0, err
    rc, _, err = _replay(capsys, recorded["log"], *common, "--out", out_csv)
    assert rc == 0, err
    a, b = _table(out_csv), _table(out_bag)
    np.testing.assert_allclose(_floats(b["command_replay"]), _floats(a["command_replay"]),
                               rtol=0, atol=1e-9)
    np.testing.assert_array_equal(_floats(b["command_recorded"]), g.command)
    rc, _, err = _replay(capsys, bag, *common, "--out", tmp_path / "x.csv")
    assert rc == 2 and "--finger-topics" in err and len(err.strip().splitlines()) == 1


def test_replay_without_a_recorded_command_and_bad_settings(tmp_path, capsys, recorded):
    """A table without `command` replays and says there is nothing to compare; a settings
    file that is not a mapping of blocks is one line, exit 2."""
    g = recorded["glog"]
    path = write_grasp_log(GraspLog(t=g.t, wrench=g.wrench, command=None, maneuver=g.maneuver,
                                    fingers=()), tmp_path / "nocmd.csv")
    rc, text, err = _replay(capsys, path, "--params", recorded["params"], "--out",
                            tmp_path / "r.csv")
    assert rc == 0, err
    assert "no recorded command" in text
    bad = tmp_path / "bad.yaml"
    bad.write_text("- just\n- a list\n")
    rc, _, err = _replay(capsys, path, "--params", recorded["params"], "--settings", bad,
                         "--out", tmp_path / "s.csv")
    assert rc == 2 and "'controller:'" in err and len(err.strip().splitlines()) == 1

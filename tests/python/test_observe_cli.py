"""``lugrip simulate-sliding`` and ``lugrip observe``: logs written by a test as CSV, Parquet
and MCAP are replayed with identical estimates and the RMSE printed; bad files are rejected with
the LogError message and nothing is overwritten without --force."""

from __future__ import annotations

import csv
import os
import re

import lugrip
import numpy as np
import pytest
from lugrip import ContactParams, Observer, write_log
from lugrip.cli import main
from lugrip.sliding import score, simulate_maneuvers

TABLE1 = ContactParams.table1()


@pytest.fixture(scope="module")
def data():
    """Eight Table 1 maneuvers with ground truth (small, ~3000 samples)."""
    return simulate_maneuvers(TABLE1, 8, seed=31)


def _read_csv(path):
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    header, body = rows[0], rows[1:]
    return {name: [r[i] for r in body] for i, name in enumerate(header)}


def _observe(capsys, *argv):
    rc = main(["observe", *map(str, argv)])
    out = capsys.readouterr()
    return rc, out.out, out.err


def test_simulate_sliding_writes_a_log_and_refuses_to_overwrite(tmp_path, capsys):
    """simulate-sliding writes the log (same as the library with the same seed), prints a
    summary, and refuses an existing --out (file untouched) unless --force."""
    out = tmp_path / "d.csv"
    rc = main(["simulate-sliding", "--out", str(out), "--maneuvers", "5", "--seed", "2"])
    printed = capsys.readouterr()
    assert rc == 0, printed.err
    assert "5 maneuvers" in printed.out
    log = lugrip.read_log(out)
    ref = simulate_maneuvers(TABLE1, 5, seed=2).log
    np.testing.assert_array_equal(log.tau, ref.tau)
    np.testing.assert_array_equal(log.omega, ref.omega)
    before = out.read_bytes()
    rc = main(["simulate-sliding", "--out", str(out), "--maneuvers", "3"])
    err = capsys.readouterr().err
    assert rc == 2 and "exists" in err and "--force" in err
    assert out.read_bytes() == before
    rc = main(
        [
            "simulate-sliding",
            "--out",
            str(out),
            "--maneuvers",
            "3",
            "--force",
            "--preset",
            "aluminium_can",
            "--noise-force",
            "0",
            "--noise-torque",
            "0",
        ]
    )
    assert rc == 0
    assert len(np.unique(lugrip.read_log(out).maneuver)) == 3
    assert main(["simulate-sliding", "--out", str(tmp_path / "x.txt")]) == 2
    assert "suffix" in capsys.readouterr().err
    assert main(["simulate-sliding", "--out", str(tmp_path / "y.csv"), "--preset", "wood"]) == 2
    assert "unknown preset" in capsys.readouterr().err


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".mcap"])
def test_observe_replays_csv_parquet_and_mcap(tmp_path, capsys, data, suffix):
    """The same log as CSV, Parquet or MCAP (written by write_log) gives the estimates of the
    in-process observer, with the columns t, omega_hat, z_hat, c_tilde, S, status,
    speed_observable, maneuver, c_tilde_unclipped, omega_object, v_slip, and the RMSE printed
    equals the library's score."""
    if suffix == ".parquet":
        pytest.importorskip("pyarrow")
    if suffix == ".mcap":
        pytest.importorskip("mcap")
    log_path = write_log(data.log, tmp_path / f"log{suffix}")
    est_path = tmp_path / "est.csv"
    rc, out, err = _observe(capsys, log_path, "--preset", "table1", "--out", est_path)
    assert rc == 0, err
    cols = _read_csv(est_path)
    assert list(cols) == [
        "t",
        "omega_hat",
        "z_hat",
        "c_tilde",
        "S",
        "status",
        "speed_observable",
        "maneuver",
        "c_tilde_unclipped",
        "omega_object",
        "v_slip",
    ]
    n = len(data.log)
    assert len(cols["t"]) == n
    ref = Observer(TABLE1).run(data.log)
    tol = 1e-9 if suffix == ".mcap" else 0.0  # MCAP stores times in integer nanoseconds
    np.testing.assert_allclose(np.array(cols["t"], float), data.log.t, atol=tol, rtol=0)
    np.testing.assert_allclose(
        np.array(cols["omega_hat"], float), ref.omega_hat, rtol=1e-9, atol=1e-12
    )
    np.testing.assert_allclose(np.array(cols["S"], float), ref.S, rtol=1e-9, atol=1e-12)
    for name in ("c_tilde_unclipped", "omega_object", "v_slip"):
        np.testing.assert_allclose(np.array(cols[name], float), getattr(ref, name), rtol=1e-9, atol=1e-12)
    assert set(cols["status"]) <= {s.name.lower() for s in lugrip.Status}
    assert cols["status"][0] == "reinitialized"
    np.testing.assert_array_equal(np.array(cols["maneuver"], int), data.log.maneuver)
    sc = score(data, ref)
    printed = float(re.search(r"RMSE omega_hat: ([0-9.eE+-]+) rad/s", out).group(1))
    assert printed == pytest.approx(sc.rmse, rel=1e-3)
    assert sc.rmse <= 0.0222
    assert "slip detection" in out


def test_observe_parquet_output_params_file_and_plot(tmp_path, capsys, data):
    """--params YAML (as `lugrip params` writes it), Parquet output, and --plot writing the
    Figure-5 PNG; an existing figure is not overwritten without --force."""
    pa = pytest.importorskip("pyarrow.parquet")
    log_path = write_log(data.log, tmp_path / "log.csv")
    yaml_path = tmp_path / "p.yaml"
    TABLE1.to_yaml(yaml_path)
    est = tmp_path / "est.parquet"
    rc, _out, err = _observe(
        capsys, log_path, "--params", yaml_path, "--out", est, "--plot", tmp_path / "figs"
    )
    assert rc == 0, err
    table = pa.read_table(est)
    assert table.num_rows == len(data.log)
    assert table.column_names[:5] == ["t", "omega_hat", "z_hat", "c_tilde", "S"]
    png = tmp_path / "figs" / "fig05_observer.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rc, _out, err = _observe(
        capsys,
        log_path,
        "--preset",
        "table1",
        "--out",
        tmp_path / "e2.csv",
        "--plot",
        tmp_path / "figs",
    )
    assert rc == 2 and "fig05_observer.png exists" in err
    assert not (tmp_path / "e2.csv").exists()


def test_observe_options_reach_the_observer(tmp_path, capsys):
    """--integrator rk4 --gain 200 (the paper's scheme) diverges on fast slips at 1 N, which
    the command reports; the default does not."""
    d = simulate_maneuvers(
        TABLE1,
        2,
        seed=1,
        f_n_range=(1.0, 1.0),
        c_range=(0.05, 0.1),
        omega_range=(0.3, 0.4),
        stick_fraction=0.0,
    )
    log_path = write_log(d.log, tmp_path / "fast.csv")
    rc, out, err = _observe(
        capsys,
        log_path,
        "--preset",
        "table1",
        "--out",
        tmp_path / "rk4.csv",
        "--integrator",
        "rk4",
        "--gain",
        "200",
    )
    assert rc == 0, err
    assert "divergence guard" in out and "(rk4, fixed l = 200)" in out
    rc, out, err = _observe(capsys, log_path, "--preset", "table1", "--out", tmp_path / "ros.csv")
    assert rc == 0 and "divergence" not in out
    default_b = lugrip.Observer(TABLE1).settings["bandwidth"]
    assert f"(rosenbrock, l = {default_b:g}/sigma_1)" in out
    rc, out, err = _observe(
        capsys,
        log_path,
        "--preset",
        "table1",
        "--out",
        tmp_path / "x.csv",
        "--gain",
        "200",
        "--bandwidth",
        "50",
    )
    assert rc == 2 and "not allowed with" in err


def _write(path, text):
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("name", "content", "message"),
    [
        (
            "no_tau.csv",
            "t,f_n,f_x,f_y\n0,1,0,0.1\n0.002,1,0,0.1\n",
            "missing required column(s) 'tau'",
        ),
        (
            "backwards.csv",
            "t,f_n,f_t,tau\n0,1,0.1,0\n0.004,1,0.1,0\n0.002,1,0.1,0\n",
            "time goes backwards",
        ),
        ("letters.csv", "t,f_n,f_t,tau\n0,1,0.1,0\n0.002,abc,0.1,0\n", "'abc' is not a number"),
        ("empty.csv", "", "empty file"),
        ("broken.parquet", "this is not parquet", "not a readable Parquet file"),
        ("broken.mcap", "this is not mcap either", "not a readable MCAP file"),
        ("table.xlsx", "t,f_n,f_t,tau\n", "unknown file type"),
    ],
)
def test_bad_logs_are_rejected_and_nothing_is_written(tmp_path, capsys, name, content, message):
    """Malformed logs: exit code 2, the LogError message (file, row, column) on one line, no
    output file created."""
    if name.endswith(".parquet"):
        pytest.importorskip("pyarrow")
    if name.endswith(".mcap"):
        pytest.importorskip("mcap")
    bad = _write(tmp_path / name, content)
    est = tmp_path / "est.csv"
    rc, _out, err = _observe(capsys, bad, "--preset", "table1", "--out", est)
    assert rc == 2
    assert message in err and name in err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert not est.exists()
    assert [p.name for p in tmp_path.iterdir()] == [name]  # no temporary files left


def test_existing_output_and_input_are_never_overwritten(tmp_path, capsys, data):
    """An existing --out is refused before any work (content unchanged); --out equal to the
    log is refused even with --force; missing inputs and parameters are clear errors."""
    log_path = write_log(data.log, tmp_path / "log.csv")
    log_bytes = log_path.read_bytes()
    est = _write(tmp_path / "est.csv", "precious\n")
    rc, _, err = _observe(capsys, log_path, "--preset", "table1", "--out", est)
    assert rc == 2 and "exists" in err and "--force" in err
    assert est.read_text() == "precious\n"
    rc, _, err = _observe(capsys, log_path, "--preset", "table1", "--out", log_path, "--force")
    assert rc == 2 and "replace the input" in err
    assert log_path.read_bytes() == log_bytes
    rc, _, err = _observe(capsys, log_path, "--preset", "table1", "--out", est, "--force")
    assert rc == 0 and est.read_text().startswith("t,omega_hat")
    rc, _, err = _observe(
        capsys, tmp_path / "nope.csv", "--preset", "table1", "--out", tmp_path / "e3.csv"
    )
    assert rc == 2 and "no such file" in err
    rc, _, err = _observe(capsys, log_path, "--out", tmp_path / "e4.csv")
    assert rc == 2 and "--params" in err
    rc, _, err = _observe(
        capsys, log_path, "--params", tmp_path / "missing.yaml", "--out", tmp_path / "e5.csv"
    )
    assert rc == 2 and "missing.yaml" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["est.csv", "log.csv"]


def test_log_without_ground_truth_is_replayed_without_rmse(tmp_path, capsys, data):
    """A log without omega is replayed; no RMSE is printed."""
    log = lugrip.SlidingLog.from_arrays(
        data.log.t, data.log.f_n, data.log.tau, f_t=data.log.f_t, check_units=False
    )
    path = write_log(log, tmp_path / "raw.csv")
    rc, out, err = _observe(capsys, path, "--preset", "table1", "--out", tmp_path / "e.csv")
    assert rc == 0, err
    assert "RMSE not computed" in out and "RMSE omega_hat" not in out
    assert os.path.getsize(tmp_path / "e.csv") > 0


def test_log_options_parse_and_reach_the_reader(tmp_path, capsys, data):
    """--units and --maneuvers parse CLI syntax (bad values: one line, exit 2) and reach
    read_log: windows renumber the maneuvers of the estimate file."""
    import argparse

    from lugrip.commands._log_options import parse_maneuvers, parse_units

    assert parse_units("tau=N_mm,t=ms") == {"tau": "N mm", "t": "ms"}
    assert parse_maneuvers("motion") == "motion"
    assert parse_maneuvers("0:1.5, 2:3") == [(0.0, 1.5), (2.0, 3.0)]
    for bad in ("tau", "=N", "speed=m/s"):
        with pytest.raises(argparse.ArgumentTypeError):
            parse_units(bad)
    for bad in ("2:1", "a:b", "1", "0:inf"):
        with pytest.raises(argparse.ArgumentTypeError):
            parse_maneuvers(bad)
    log_path = write_log(data.log, tmp_path / "d.csv")
    out = tmp_path / "e.csv"
    rc, _, err = _observe(capsys, log_path, "--preset", "table1", "--out", out,
                          "--maneuvers", "0:2,2:4")
    assert rc == 0, err
    ids = np.array(_read_csv(out)["maneuver"], dtype=int)
    t = np.array(_read_csv(out)["t"], dtype=float)
    np.testing.assert_array_equal(ids, np.where(t < 2, 1, np.where(t < 4, 2, 0)))
    rc, _, err = _observe(capsys, log_path, "--preset", "table1", "--out", tmp_path / "f.csv",
                          "--maneuvers", "3:1")
    assert rc == 2 and "--maneuvers" in err and len(err.strip().splitlines()) == 1
    rc, _, err = _observe(capsys, log_path, "--preset", "table1", "--out", tmp_path / "g.csv",
                          "--wrench-topic", "/ft")
    assert rc == 2 and "--wrench-topic applies to ROS recordings" in err


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_replay_in_pieces_writes_what_one_run_writes(data, tmp_path, monkeypatch, capsys, suffix):
    """Plant: lugrip's own slider model (synthetic maneuvers). `lugrip observe` replays the
    log in pieces and writes them one by one; with pieces of 7 samples (pieces start inside
    maneuvers and on their boundaries) the estimates file holds exactly what one
    Observer.run over the whole log gives, and the printed scores are the same as with the
    default pieces (larger than this log: one piece)."""
    pytest.importorskip("pyarrow")
    import lugrip.commands.observe as cmd

    log_path = write_log(data.log, tmp_path / "d.csv")
    log = lugrip.read_log(log_path)
    assert len(log) > 7 * 50 and len(np.unique(log.maneuver)) == 8
    ref = cmd.write_estimates(tmp_path / f"ref{suffix}", log,
                              Observer(TABLE1, dt=log.sample_period).run(log))
    argv = [log_path, "--preset", "table1"]
    rc, whole_out, err = _observe(capsys, *argv, "--out", tmp_path / f"whole{suffix}")
    assert rc == 0, err
    monkeypatch.setattr(cmd, "CHUNK_ROWS", 7)
    rc, pieces_out, err = _observe(capsys, *argv, "--out", tmp_path / f"pieces{suffix}")
    assert rc == 0, err
    assert whole_out.splitlines()[1:] == pieces_out.splitlines()[1:]  # line 0: ns/sample
    assert "RMSE omega_hat" in pieces_out
    if suffix == ".csv":
        assert (tmp_path / "pieces.csv").read_bytes() == ref.read_bytes()
        assert (tmp_path / "whole.csv").read_bytes() == ref.read_bytes()
    else:
        import pyarrow.parquet as pq

        want = pq.read_table(ref).to_pydict()
        for name in ("pieces", "whole"):
            got = pq.read_table(tmp_path / f"{name}.parquet").to_pydict()
            assert list(got) == list(cmd.OUTPUT_COLUMNS)
            for k in want:
                np.testing.assert_array_equal(np.asarray(got[k]), np.asarray(want[k]), err_msg=k)

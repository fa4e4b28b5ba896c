"""Randomized grasp campaigns (lugrip.campaign, ``lugrip campaign``).

Kinds of test:

* definition checks (bad files -> exit 2 naming the field; hypothesis over ranges): no plant;
* reproducibility and backends: the shipped campaign on lugrip's distributed patch-contact plant
  (a grid of LuGre cells, not the lumped model the observers use: an independent plant for the
  controller), compared with itself across workers and backends -- consistency of the runner;
* resume: the CLI killed mid-campaign and rerun;
* report: the Wilson interval against published values and the failure map on rows whose
  answer is known.
"""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lugrip import cli
from lugrip.campaign import (
    Campaign,
    CampaignError,
    ResultStore,
    load_campaign,
    run_campaign,
    run_one,
    summarise,
    wilson,
)

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = ROOT / "campaigns" / "patch_blocks.yaml"


def _doc(**over):
    with open(SHIPPED) as f:
        d = yaml.safe_load(f)
    d.update(over)
    return d


def _write(tmp_path, doc, name="c.yaml"):
    p = tmp_path / name
    p.write_text(yaml.safe_dump(doc))
    return p


def _tiny(tmp_path, **over):
    """The shipped campaign, shortened (5 s, two controllers) for the slower tests."""
    d = _doc()
    d["duration"] = 5.0
    d["steady_window"] = [3.0, 3.9]
    d["controllers"] = {"lugrip": {}, "constant_force": {"force": 6.0}}
    d["parameters"]["push_time"] = {"distribution": "uniform", "low": 3.5, "high": 4.2}
    d.update(over)
    return _write(tmp_path, d, "tiny.yaml")


def _cli(*args) -> int:
    return cli.main(list(map(str, args)))


def _strip(rows):
    """Rows without the wall time, sorted by (run, controller)."""
    out = [{k: v for k, v in r.items() if k not in ("elapsed_s", "cpu_s")} for r in rows]
    return sorted(out, key=lambda r: (r["run"], r["controller"]))


# --- definitions -------------------------------------------------------------------------------


def test_shipped_campaigns_load():
    for p in sorted((ROOT / "campaigns").glob("*.yaml")):
        c = load_campaign(p)
        assert set(c.controllers) == {"lugrip", "paper", "constant_force", "friction_cone"}
        base = c.base_scenario()
        assert base.duration >= 8.0 and base.steady_window[1] < base.duration


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"mass": {"distribution": "gamma", "low": 0.1, "high": 0.2}}, "parameters.mass.distribution"),
        ({"mass": {"distribution": "uniform", "low": -0.1, "high": 0.2}}, "parameters.mass.low"),
        ({"mass": {"distribution": "uniform", "low": 0.3, "high": 0.3}}, "parameters.mass"),
        ({"mu": {"distribution": "uniform", "low": 0.9, "high": 0.4}}, "parameters.mu"),
        ({"mass": {"distribution": "normal", "mean": 0.2, "std": 0.05}}, "parameters.mass.low"),
        ({"mass": {"distribution": "constant", "value": -1.0}}, "parameters.mass.value"),
        ({"weight": {"distribution": "uniform", "low": 0.1, "high": 0.2}}, "parameters.weight"),
        ({"mu": {"distribution": "uniform", "low": 0.1}}, "parameters.mu"),
        ({"mismatch_mu": {"distribution": "uniform", "low": -1.0, "high": 0.1}},
         "parameters.mismatch_mu.low"),
    ],
)
def test_bad_parameter_exits_2_naming_the_field(tmp_path, capsys, change, field):
    d = _doc()
    d["parameters"] = dict(d["parameters"]) | change
    p = _write(tmp_path, d)
    assert _cli("campaign", p, "--runs", 1, "--out", tmp_path / "o") == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert field in err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("over", "field"),
    [
        ({"controllers": {"lugrip": {}, "pid": {}}}, "controllers.pid"),
        ({"controllers": {"constant_force": {}}}, "controllers.constant_force.force"),
        ({"seed": -3}, "seed"),
        ({"plant": "rubber"}, "plant"),
        ({"criteria": {"max_hold_slip_mm": -1.0}}, "criteria.max_hold_slip_mm"),
        ({"scenario": "no_such_scenario"}, "scenario"),
        ({"colour": "red"}, "colour"),
    ],
)
def test_bad_campaign_keys_exit_2(tmp_path, capsys, over, field):
    p = _write(tmp_path, _doc(**over))
    assert _cli("campaign", p, "--runs", 1, "--out", tmp_path / "o") == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and field in err


def test_pad_parameters_only_on_mujoco(tmp_path):
    d = _doc()
    d["parameters"]["pad_k_slide"] = {"distribution": "uniform", "low": 1e3, "high": 2e3}
    with pytest.raises(CampaignError, match="parameters.pad_k_slide"):
        Campaign.from_dict(d, SHIPPED)


_SETTINGS = settings(max_examples=60, deadline=None,
                     suppress_health_check=[HealthCheck.function_scoped_fixture])


@_SETTINGS
@given(low=st.floats(-1.0, 1.0), high=st.floats(-1.0, 1.0))
def test_uniform_mass_valid_iff_positive_nonempty(low, high):
    """A uniform mass is accepted exactly when 0 < low < high; accepted draws lie inside."""
    d = _doc()
    d["parameters"] = {"mass": {"distribution": "uniform", "low": low, "high": high}}
    if 0.0 < low < high:
        c = Campaign.from_dict(d, SHIPPED)
        for i in range(3):
            assert low <= c.draw(i)["mass"] <= high
    else:
        with pytest.raises(CampaignError, match="parameters.mass"):
            Campaign.from_dict(d, SHIPPED)


@_SETTINGS
@given(mean=st.floats(-0.2, 0.2), std=st.floats(0.01, 0.3), index=st.integers(0, 10**6))
def test_truncated_normal_stays_inside(mean, std, index):
    d = _doc()
    d["parameters"] = {
        "mismatch_mu": {"distribution": "normal", "mean": mean, "std": std, "low": -0.5, "high": 0.5}
    }
    v = Campaign.from_dict(d, SHIPPED).draw(index)["mismatch_mu"]
    assert -0.5 <= v <= 0.5


def test_draws_depend_on_campaign_and_index_only():
    """A run's draws come from (seed, index, parameter name): the same in any order, unchanged
    when a parameter is added, different for another index or seed."""
    c = load_campaign(SHIPPED)
    forward = [c.draw(i) for i in range(5)]
    backward = [c.draw(i) for i in reversed(range(5))][::-1]
    assert forward == backward
    assert forward[0] != forward[1]
    d = _doc()
    d["parameters"]["normal_bias"] = {"distribution": "uniform", "low": -0.01, "high": 0.01}
    bigger = Campaign.from_dict(d, SHIPPED).draw(3)
    assert {k: bigger[k] for k in forward[3]} == forward[3]
    other = Campaign.from_dict(_doc(seed=7), SHIPPED).draw(3)
    assert other["mass"] != forward[3]["mass"]


def test_draws_reach_the_scenario():
    c = load_campaign(SHIPPED)
    scn, p = c.run_scenario(4)
    obj = scn.plant["object"]
    assert obj["mass"] == p["mass"]
    assert obj["cog"] == [p["offset_x"], p["offset_y"]]
    assert math.isclose(obj["inertia"], p["mass"] * (p["length"] ** 2 + p["height"] ** 2) / 12)
    assert scn.plant["contact"]["mu"] == p["mu"]
    assert scn.plant["seed"] == p["plant_seed"]
    (push,) = scn.plant["disturbances"]
    assert math.isclose(math.hypot(*push["force"]), p["push_force"])
    est = scn.estimator["patch"]
    assert math.isclose(est["mu"], p["mu"] * (1 + p["mismatch_mu"]))
    assert math.isclose(est["sigma0"], p["sigma0"] * (1 + p["mismatch_sigma0"]))
    # the base scenario's own belief about sigma_z (its estimator block) is kept
    assert est["sigma_z"] == 3.3e-3
    assert scn.plant["sensor"]["bias"][0] == [0.0, p["force_bias"], p["force_bias"], p["torque_bias"]]


def test_mujoco_belief_takes_the_drawn_mu_over_the_identified_file():
    """The MuJoCo campaign's base scenario names an identified file (fitted on one block, its
    own mu) as the estimator: each run's belief keeps that file's pad parameters but takes the
    drawn object's mu, times the mismatch (before, every drawn object was observed with the
    file's mu, and S could not reach the slip threshold on low-friction objects)."""
    from lugrip import ContactParams

    c = load_campaign(ROOT / "campaigns" / "mujoco_blocks.yaml")
    pad = ContactParams.from_yaml(ROOT / "objects" / "mujoco" / "small_resin_block.yaml")
    for index in (0, 1, 2):
        scn, p = c.run_scenario(index)
        est = scn.estimator["mujoco"]
        assert math.isclose(est["mu"], p["mu"] * (1 + p["mismatch_mu"]))
        assert math.isclose(est["delta"], pad.delta)
        assert math.isclose(est["sigma_z"], pad.sigma_z)
        assert est["k"] == pad.k


# --- runs and backends --------------------------------------------------------------------------


def test_run_one_is_deterministic_and_flags_failures():
    """The same (campaign, index) gives the same rows; a 6 N constant force holds a light
    block and every row carries its drawn parameters and pass flags."""
    c = load_campaign(SHIPPED)
    a, b = run_one(c, 0), run_one(c, 0)
    assert _strip(a) == _strip(b)
    assert [r["controller"] for r in a] == list(c.controllers)
    for r in a:
        assert r["error"] is None
        assert r["success"] == all(r[f"pass_{k}"] for k in c.criteria)
        assert r["p_mass"] == c.draw(0)["mass"]
    cf = next(r for r in a if r["controller"] == "constant_force")
    assert math.isclose(cf["m_mean_force"], 6.0, rel_tol=1e-6)


def test_process_pool_same_rows_any_worker_count(tmp_path):
    c = load_campaign(_tiny(tmp_path))
    tables = []
    for workers in (1, 2):
        out = tmp_path / f"w{workers}"
        info = run_campaign(c, 3, out, workers=workers, progress=False)
        assert info["ran"] == 3
        assert (out / "results.parquet").is_file()
        assert not list((out / "parts").glob("*.parquet"))
        tables.append(_strip(ResultStore(out, c).rows()))
    assert tables[0] == tables[1]
    assert [r for r in tables[0] if r["run"] == 2] == _strip(run_one(c, 2))


def test_ray_backend_same_rows(tmp_path):
    pytest.importorskip("ray")
    c = load_campaign(SHIPPED)
    run_campaign(c, 3, tmp_path / "ray", workers=2, backend="ray", progress=False)
    run_campaign(c, 3, tmp_path / "proc", workers=2, backend="process", progress=False)
    a = ResultStore(tmp_path / "ray", c).rows()
    b = ResultStore(tmp_path / "proc", c).rows()
    assert len(a) == 3 * len(c.controllers)
    assert _strip(a) == _strip(b)


def test_other_campaign_in_the_same_directory_is_refused(tmp_path, capsys):
    p = _tiny(tmp_path)
    out = tmp_path / "o"
    assert _cli("campaign", p, "--runs", 1, "--workers", 1, "--out", out, "--quiet",
                "--no-figures") == 0
    q = _tiny(tmp_path, seed=99)
    assert _cli("campaign", q, "--runs", 1, "--out", out) == 2
    assert "another campaign" in capsys.readouterr().err


def test_killed_campaign_resumes_without_redoing_or_losing_runs(tmp_path):
    """Kill the CLI after some runs are stored; the rerun keeps them (same files, untouched),
    runs only the rest, and the final table equals an uninterrupted campaign's."""
    p = _tiny(tmp_path)
    out = tmp_path / "o"
    n = 8
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    cmd = [sys.executable, "-m", "lugrip", "campaign", str(p), "--runs", str(n), "--workers", "1",
           "--out", str(out), "--quiet", "--no-report"]
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)
    parts = out / "parts"
    deadline = time.monotonic() + 120
    try:
        while time.monotonic() < deadline and len(list(parts.glob("run-*.parquet"))) < 2:
            time.sleep(0.05)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    kept = {f.name: f.stat().st_mtime_ns for f in parts.glob("run-*.parquet")}
    assert 2 <= len(kept) < n, "the campaign must be killed mid-way"
    assert not (out / "results.parquet").exists()
    c = load_campaign(p)
    seen = []
    info = run_campaign(c, n, out, workers=1, progress=False,
                        on_run=lambda i, rows: seen.append(i))
    assert info["skipped"] == len(kept) and info["ran"] == n - len(kept)
    done_before = {int(k[4:11]) for k in kept}
    assert not done_before & set(seen)
    rows = ResultStore(out, c).rows()
    assert sorted({r["run"] for r in rows}) == list(range(n))
    assert len(rows) == n * len(c.controllers)
    assert _strip(rows) == _strip([r for i in range(n) for r in run_one(c, i)])
    # a third call with the same --out has nothing left to do
    assert run_campaign(c, n, out, progress=False)["ran"] == 0


# --- report and replay -------------------------------------------------------------------------


def test_wilson_against_published_values():
    """Wilson 95 % score intervals as tabulated by Newcombe (1998), Stat. Med. 17, 857, Table I:
    81/263 -> 0.2553-0.3662, 15/148 -> 0.0624-0.1605, 0/20 -> 0-0.1611, 1/29 -> 0.0061-0.1718."""
    for k, n, lo, hi in [(81, 263, 0.2553, 0.3662), (15, 148, 0.0624, 0.1605),
                         (0, 20, 0.0, 0.1611), (1, 29, 0.0061, 0.1718)]:
        a, b = wilson(k, n)
        assert a == pytest.approx(lo, abs=6e-5) and b == pytest.approx(hi, abs=6e-5)
    assert wilson(0, 0) == (0.0, 1.0)


def test_failure_map_finds_the_parameter_that_decides(tmp_path):
    """Rows where success is decided by mass alone: the map flags mass, not mu; the worst run is
    the heaviest drop; rates and paired counts are the counted ones."""
    c = load_campaign(SHIPPED)
    rows = []
    for i in range(200):
        p = c.draw(i)
        for ctrl in c.controllers:
            ok = p["mass"] < 0.25 if ctrl == "friction_cone" else True
            rows.append({
                "run": i, "controller": ctrl, "success": ok, "error": None,
                "m_dropped": not ok, "m_finite": True, "m_mean_force": 5.0 if ok else 1.0,
                "m_hold_slip_mm": 0.0, "m_hold_rotation_deg": p["mass"],
                **{f"p_{k}": p[k] for k in c.parameters},
                **{f"pass_{k}": True for k in c.criteria},
            })
    data = summarise(rows, c, out_dir="DIR")
    n_ok = sum(c.draw(i)["mass"] < 0.25 for i in range(200))
    assert data["summary"]["friction_cone"]["successes"] == n_ok
    assert data["summary"]["lugrip"]["success_rate"] == 1.0
    assert data["paired_with_lugrip"]["friction_cone"]["lugrip_holds_other_fails"] == 200 - n_ok
    assert data["failure_map"]["mass"]["controllers"]["friction_cone"]["effect"]
    assert not data["failure_map"]["mu"]["controllers"]["friction_cone"]["effect"]
    assert not data["failure_map"]["mass"]["controllers"]["lugrip"]["effect"]
    worst = data["worst_runs"]["friction_cone"]
    assert len(worst) == 5 and all(w["parameters"]["mass"] >= 0.25 for w in worst)
    assert worst[0]["replay"].startswith("lugrip campaign replay DIR --run ")


def test_cli_report_and_replay(tmp_path, capsys):
    p = _tiny(tmp_path)
    out = tmp_path / "o"
    assert _cli("campaign", p, "--runs", 2, "--workers", 1, "--out", out, "--quiet") == 0
    text = capsys.readouterr().out
    assert "lugrip:" in text and "95 % interval" in text
    assert (out / "report.md").is_file() and (out / "failure_map.png").is_file()
    assert _cli("campaign", "replay", out, "--run", 1, "--controller", "lugrip") == 0
    text = capsys.readouterr().out
    assert "same as stored" in text
    assert (out / "replay_1_lugrip.png").is_file() and (out / "replay_1.json").is_file()
    assert _cli("simulate", "--campaign", out, "--run", 0, "--out", tmp_path / "sim") == 0
    text = capsys.readouterr().out
    assert text.count("same as stored") == 2  # both controllers of the tiny campaign
    assert (tmp_path / "sim" / "replay_0_baselines.png").is_file()
    assert _cli("simulate", "--campaign", out) == 2
    assert "--run" in capsys.readouterr().err
    assert _cli("campaign", "replay", out, "--run", 1, "--controller", "pid") == 2
    assert "pid" in capsys.readouterr().err
    assert _cli("campaign", "replay", tmp_path, "--run", 0) == 2
    assert "campaign.json" in capsys.readouterr().err


def test_mujoco_campaign_one_run():
    """One grasp of the shipped MuJoCo campaign (MuJoCo's own contact solver and pads: an
    independent plant), lugrip only: the drawn box size and pad springs reach the scene, the
    scene works, the row is complete and the run is repeatable."""
    pytest.importorskip("mujoco")
    with open(ROOT / "campaigns" / "mujoco_blocks.yaml") as f:
        d = yaml.safe_load(f)
    d["controllers"] = {"lugrip": {}}
    c = Campaign.from_dict(d, ROOT / "campaigns" / "mujoco_blocks.yaml")
    scn, p = c.run_scenario(0)
    assert scn.mujoco["size"][1:] == [0.5 * p["length"], 0.5 * p["height"]]
    assert scn.mujoco["pad"] == {"k_slide": p["pad_k_slide"], "k_twist": p["pad_k_twist"]}
    (row,) = run_one(c, 0)
    assert row["error"] is None and row["m_scene_status"] == "ok" and row["pass_scene_ok"]
    assert row["m_finite"] and row["m_mean_force"] > 0.0
    assert _strip([row]) == _strip(run_one(c, 0))

"""Campaign definitions are checked completely at load (exit 2, one line naming file and field,
nothing written), never stored as failed runs; every YAML the tool reads goes through the
limited loader; the run count is checked before any list is built; process-pool workers die
with their parent (docs/reliability.md)."""

from __future__ import annotations

import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml
from lugrip import cli
from lugrip.campaign import CampaignError, load_campaign, run_campaign

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = ROOT / "campaigns" / "patch_blocks.yaml"
SCENARIO = ROOT / "scenarios" / "exp2_small_resin_block.yaml"


def _doc(**over):
    d = yaml.safe_load(SHIPPED.read_text())
    d["scenario"] = str(SCENARIO)
    d.update(over)
    return d


def _write(tmp_path, doc, name="c.yaml") -> Path:
    p = tmp_path / name
    p.write_text(yaml.safe_dump(doc))
    return p


def _exit_2(capsys, *argv) -> str:
    rc = cli.main([str(a) for a in argv])
    err = capsys.readouterr().err.strip()
    assert rc == 2, err
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    return err


def _bad_estimator(tmp_path):
    bad = tmp_path / "est.yaml"
    bad.write_text("contact: {mu: {value: -3, unit: '-'}}\n")
    d = _doc()
    d["overrides"]["estimator"] = {"patch": str(bad)}
    return d


@pytest.mark.parametrize(
    ("make", "field"),
    [
        (lambda tmp: _doc(duration=-1), "duration"),
        (lambda tmp: _doc(seed=2**80), "seed"),
        (_bad_estimator, "est.yaml"),
        (lambda tmp: _doc(parameters=_doc()["parameters"] | {
            "mass": {"distribution": "constant", "value": 1e-300}}), "parameters.mass"),
        (lambda tmp: _doc(parameters=_doc()["parameters"] | {
            "mass": {"distribution": "uniform", "low": 1e-300, "high": 0.4}}),
         "low bound of parameters.mass"),
    ],
    ids=["duration-negative", "seed-2**80", "estimator-file", "mass-1e-300", "mass-range-to-1e-300"],
)
def test_definition_errors_are_exit_2_at_load(tmp_path, capsys, make, field):
    """Each was 0 % success with exit 0 (every run stored as failed): now exit 2 naming the
    field, before any run, and no results directory."""
    path = _write(tmp_path, make(tmp_path))
    out = tmp_path / "out"
    err = _exit_2(capsys, "campaign", path, "--runs", 3, "--workers", 1, "--out", out,
                  "--quiet")
    assert str(path) in err and field in err
    assert not out.exists()
    with pytest.raises(CampaignError, match=field.split(" ")[-1]):
        run_campaign(load_campaign(path), 1, tmp_path / "lib", workers=1, progress=False)
    assert not (tmp_path / "lib").exists()


def test_shipped_campaigns_pass_the_load_checks():
    from lugrip.campaign.validate import validate_campaign

    for name in ("patch_blocks", "mujoco_blocks"):
        validate_campaign(load_campaign(ROOT / "campaigns" / f"{name}.yaml"))


def _child_peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0


_BOMB = "".join(
    [f"a0: &a0 [{', '.join(['x'] * 10)}]\n"]
    + [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]\n" for i in range(1, 9)]
)


@pytest.mark.parametrize("kind", ["campaign", "settings"])
def test_alias_bombs_are_refused_quickly_in_a_small_memory(tmp_path, kind):
    """A 2.6 KB campaign file cost 768 MB and a 405 B settings file 810 MB: both now go
    through lugrip._yaml.load_yaml (exit 2, < 500 MB; the time each refusal takes is measured by
    benchmarks/reliability_cases.py, not here)."""
    bomb = tmp_path / f"{kind}.yaml"
    if kind == "campaign":
        bomb.write_text(SHIPPED.read_text() + _BOMB)
        argv = ["campaign", str(bomb), "--runs", "1", "--out", str(tmp_path / "o")]
    else:
        bomb.write_text("controller:\n  f_min: 0.1\n" + _BOMB)
        log = tmp_path / "g.csv"
        log.write_text("t,f_n_0,f_t_0,tau_0,f_n_1,f_t_1,tau_1\n0,1,0.1,0,1,0.1,0\n"
                       "0.002,1,0.1,0,1,0.1,0\n")
        argv = ["replay", str(log), "--preset", "table1", "--settings", str(bomb), "--out",
                str(tmp_path / "r.csv")]
    code = ("import sys, resource; from lugrip.cli import main; rc = main(sys.argv[1:]); "
            "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss); sys.exit(rc)")
    proc = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True,
                          check=False,
                          timeout=60)
    assert proc.returncode == 2, proc.stderr
    assert "aliases" in proc.stderr and str(bomb) in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    assert int(proc.stdout.strip()) / 1024.0 < 500.0  # peak [MB] of the refusing process


def _children(pid: int) -> list[int]:
    out = []
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            stat = (d / "stat").read_text()
            cmd = (d / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            continue
        ppid = int(stat.rsplit(")", 1)[1].split()[1])
        if ppid == pid and "spawn_main" in cmd:
            out.append(int(d.name))
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_workers_die_with_a_killed_campaign(tmp_path):
    """SIGKILL to a running `lugrip campaign --workers 2`: its pool workers exit within a few
    seconds (they ran on, 113 MB each)."""
    path = _write(tmp_path, _doc())
    proc = subprocess.Popen([sys.executable, "-m", "lugrip", "campaign", str(path), "--runs",
                             "50", "--workers", "2", "--out", str(tmp_path / "o"), "--quiet"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60.0
        workers: list[int] = []
        while time.monotonic() < deadline and len(workers) < 2:
            time.sleep(0.2)
            workers = _children(proc.pid)
        assert len(workers) == 2, "the campaign did not start its two workers"
        time.sleep(0.5)  # let the initializers run
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=10)
        deadline = time.monotonic() + 5.0
        while time.monotonic() < deadline and any(_alive(w) for w in workers):
            time.sleep(0.1)
        survivors = [w for w in workers if _alive(w)]
    finally:
        if proc.poll() is None:
            proc.kill()
        for w in _children(proc.pid) + [w for w in locals().get("workers", []) if _alive(w)]:
            try:
                os.kill(w, signal.SIGKILL)
            except OSError:
                pass
    assert survivors == []


@pytest.mark.parametrize("text", ["{not json", '{"name": "x"}', "[1, 2]", ""],
                         ids=["broken", "no-campaign", "a-list", "empty"])
def test_broken_campaign_json_is_named(tmp_path, capsys, text):
    """A results folder whose campaign.json is broken: replay, report and a resumed run exit
    2 naming the file (the message named no file)."""
    d = tmp_path / "res"
    d.mkdir()
    (d / "campaign.json").write_text(text)
    for argv in (["campaign", "report", d], ["campaign", "replay", d, "--run", 0]):
        err = _exit_2(capsys, *argv)
        assert "campaign.json" in err
    err = _exit_2(capsys, "campaign", _write(tmp_path, _doc()), "--runs", 1, "--out", d)
    assert "campaign.json" in err

"""Running a campaign: one run (every controller on one drawn grasp), the process-pool and Ray
backends, and the results directory (Parquet, resumable).

Results directory layout::

    DIR/campaign.json        the campaign with its base scenario written out, and its fingerprint
    DIR/parts/run-<i>.parquet one file per finished run (all its controllers), written to a
                             temporary name and renamed, so a file is either complete or absent
    DIR/results.parquet      every finished run, sorted by (run, controller): written when the
                             requested runs are done (the parts are then removed)

A rerun with the same DIR reads both, skips the runs already there and runs the rest; a run that
was in progress when the campaign was killed is run again (nothing of it was kept).
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
import traceback
import types
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .._controller import controller_settings
from .definition import FRONTIER_DEFAULTS, Campaign, CampaignError, _controller_call

__all__ = ["BACKENDS", "ResultStore", "run_campaign", "run_one"]

BACKENDS = ("process", "ray")

#: Metrics kept per row (compute_metrics keys; None where a run has no value).
METRICS = (
    "dropped",
    "drop_time",
    "hold_slip_mm",
    "hold_rotation_deg",
    "lift_slip_mm",
    "lift_rotation_deg",
    "max_slip_mm",
    "max_rotation_deg",
    "peak_force",
    "mean_force",
    "steady_force",
    "steady_slippage",
    "finite",
    "command_in_limits",
    "scene_status",
    "peak_command",
    "mu_belief_start",
    "mu_belief_end",
)


def _criteria(campaign: Campaign, m: dict) -> dict[str, bool]:
    """Pass flags of the campaign's criteria for the metrics `m` (``no_crush`` reads the run's
    ``crush_force`` from `m`)."""
    out = {}
    for k, limit in campaign.criteria.items():
        if limit is False:
            continue
        if k == "no_crush":
            crush = m.get("crush_force")
            out[k] = crush is None or m.get("peak_command", math.inf) <= crush
            continue
        if k == "no_drop":
            out[k] = not m["dropped"]
        elif k == "no_nan":
            out[k] = bool(m["finite"])
        elif k == "command_in_limits":
            out[k] = bool(m["command_in_limits"])
        elif k == "max_hold_slip_mm":
            out[k] = m["hold_slip_mm"] <= float(limit)
        elif k == "max_hold_rotation_deg":
            out[k] = m["hold_rotation_deg"] <= float(limit)
        elif k == "scene_ok":
            out[k] = m.get("scene_status", "ok") == "ok"
    return out


def _simulate(campaign: Campaign, scn, cfg, name: str, opts: dict):
    """(run, metrics) of controller `name` with options `opts` on the run's scenario `scn`.
    The metrics gain ``peak_command``: the largest command over the whole run, from t = 0 (the
    metric ``peak_force`` starts at the lift), per finger [N]."""
    from ..sim.scenarios import Scenario, compute_metrics, simulate

    kind, ctrl, obs, sim_opts = _controller_call(name, opts, scn)
    s = Scenario.from_dict(scn.to_dict() | {"controller": ctrl, "observer": obs}, scn.source)
    schedule = s.schedule if kind == "lugrip" else None
    run = simulate(s, cfg, campaign.plant, schedule, kind=kind, **sim_opts)
    m = compute_metrics(s, run, cfg=cfg, pivot=kind == "lugrip")
    cmd = np.asarray(run["command"], dtype=float)
    m["peak_command"] = float(np.max(cmd)) if np.all(np.isfinite(cmd)) else math.inf
    return run, m


def simulate_run(campaign: Campaign, index: int, controllers: Sequence[str] | None = None):
    """Scenario, drawn parameters and {controller: (run, metrics)} of run `index`."""
    scn, params = campaign.run_scenario(index)
    cfg = scn.plant_config(campaign.plant)
    out = {}
    for name in controllers or campaign.controllers:
        out[name] = _simulate(campaign, scn, cfg, name, campaign.controllers[name])
    return scn, params, out


def search_constant(passes: Callable[[float], bool], low: float, high: float, *,
                    tolerance: float = 0.02, max_evaluations: int = 12,
                    scan: float = math.sqrt(2.0)) -> dict[str, Any]:
    """The smallest force in [low, high] for which ``passes(force)`` is true, by bisection on
    log(force); `passes` is called at most `max_evaluations` times, plus once at `low` (below).

    1. ``high`` first. When it fails, forces below it are scanned downward by factors of
       `scan` (not below `low`): on a plant where more force can lose a grasp (MuJoCo's pads
       chatter in torsion at high grip forces) a force below the top may still pass. The
       smallest force tried above the first passing one that failed is ``fail_above``; when no
       force passes, ``force`` is None.
    2. Bisection between the largest failing force below the passing one (else ``low``, assumed
       to fail) and the passing one, to a bracket of relative width `tolerance`.
    3. When every force tried passed, ``low`` itself is tried (``floor_passed``: the force is
       then only an upper bound).

    Returns {force, found, fail_above, floor_passed, history: [[force, passed], ...]}.
    """
    history: list[list[Any]] = []

    def test(f: float) -> bool:
        ok = bool(passes(f))
        history.append([float(f), ok])
        return ok

    out: dict[str, Any] = {"force": None, "found": False, "fail_above": None,
                           "floor_passed": False, "history": history}
    if high <= low:
        return out
    hi = high
    if not test(hi):
        fail = hi
        f = hi / scan
        while f > low * (1.0 + tolerance) and len(history) < max_evaluations:
            if test(f):
                hi = f
                out["fail_above"] = fail
                break
            fail = f
            f /= scan
        else:  # no force in the scan passed
            return out
    lo = max([f for f, ok in history if not ok and f < hi], default=low)
    while hi / lo > 1.0 + tolerance and len(history) < max_evaluations:
        mid = math.sqrt(lo * hi)
        if test(mid):
            hi = mid
        else:
            lo = mid
    if all(ok for _, ok in history) and test(low):
        hi = low  # every force tried passed, and so does the bottom assumed to fail
        out["floor_passed"] = True
    out.update(force=float(hi), found=True)
    return out


def constant_frontier(campaign: Campaign, scn, limits: Mapping[str, Any],
                      criteria: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The smallest constant grasp force [N] that passes the run `scn` (every criterion of the
    campaign, as the constant_force controller is judged), by :func:`search_constant`.

    The bracket: top ``min(crush force, f_max)`` (f_max: the gripper's range in the run's
    controller block), bottom ``max(f_min, low_fraction x min_static_force)`` (assumed to fail:
    below the static force the hanging load alone makes the object slide); ``max_evaluations``
    simulations at most, to a bracket of relative width ``tolerance``.

    Assumption: below the crush force, success of a constant force is monotone in the force
    (more force never loses a grasp that less force held); then the success of ANY constant F
    on this run is F_pass <= F <= crush. It does not hold on every plant: on MuJoCo the pads'
    torsional contact can chatter at high grip forces and ratchet the object round, so a high
    constant fails where a lower one holds. The search therefore scans down from a failing top,
    and records the failing force above the passing one (``fail_above``): the report then counts
    the run as held by F only for F_pass <= F < fail_above (the true upper end lies between the
    largest passing and that failing force: the count errs toward the constant). Where the top
    passes, forces between F_pass and the top are not all tried; the report compares the
    simulated constant_force controller with this verdict run by run.

    Returns {force (None when no constant passes), found, fail_above, low, high, evaluations,
    history: [[force, passed], ...], floor_passed, error}.
    """
    opt = campaign.frontier or dict(FRONTIER_DEFAULTS)
    crit = dict(campaign.criteria if criteria is None else criteria)
    cfg = scn.plant_config(campaign.plant)
    f_min = float(scn.controller.get("f_min", controller_settings()["f_min"]))
    f_max = float(scn.controller.get("f_max", controller_settings()["f_max"]))
    crush = limits.get("crush_force")
    hi = f_max if crush is None else min(float(crush), f_max)
    lo = max(f_min, opt["low_fraction"] * float(limits["min_static_force"]))
    shadow = types.SimpleNamespace(criteria=crit)
    history: list[list[Any]] = []

    def passes(f: float) -> bool:
        _, m = _simulate(campaign, scn, cfg, "constant_force", {"force": f})
        ok = all(_criteria(shadow, dict(m, crush_force=crush)).values())
        history.append([float(f), bool(ok)])
        return ok

    out = {"force": None, "found": False, "fail_above": None, "low": lo, "high": hi,
           "evaluations": 0, "history": history, "floor_passed": False, "error": None}
    try:
        res = search_constant(passes, lo, hi, tolerance=opt["tolerance"],
                              max_evaluations=opt["max_evaluations"])
        out.update(force=res["force"], found=res["found"], fail_above=res["fail_above"],
                   floor_passed=res["floor_passed"])
    except Exception as err:  # noqa: BLE001 (a rejected simulation is recorded, not raised)
        out["error"] = f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}"
        out["force"], out["found"], out["fail_above"] = None, False, None
    out["evaluations"] = len(history)
    return out


def run_one(campaign: Campaign, index: int) -> list[dict[str, Any]]:
    """The result rows of run `index` (one per controller): run, controller, seeds, drawn
    parameters (``p_<name>``), metrics (``m_<name>``), criteria (``pass_<name>``), success,
    error (the exception's last line when the simulation failed; then success is False), the
    wall and CPU time of the run shared out over its controllers (``elapsed_s``, ``cpu_s``).
    Every row also carries the run's ``set`` (tuning or evaluation), ``min_static_force`` and
    ``crush_force`` (:meth:`Campaign.run_limits`) and, with the campaign's ``frontier``, the
    run's smallest passing constant force (:func:`constant_frontier`: ``frontier_force``, None
    when no constant passes, ``frontier_found``, ``frontier_fail_above``, ``frontier_low``,
    ``frontier_high``, ``frontier_evaluations``, ``frontier_floor_passed``,
    ``frontier_history`` as JSON, ``frontier_error``, ``frontier_elapsed_s``). A pure function
    of (campaign, index) but for the times."""
    rows = []
    t0 = time.perf_counter()
    c0 = time.process_time()
    limits: dict[str, Any] = {"min_static_force": None, "crush_force": None}
    frontier: dict[str, Any] | None = None
    frontier_s = 0.0
    try:
        scn, params, runs = simulate_run(campaign, index)
        limits = campaign.run_limits(scn, params)
        error = None
    except Exception as err:  # noqa: BLE001 (a grasp the simulator rejects is a recorded failed run)
        params = campaign.draw(index)
        runs = {}
        error = f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}"
        if os.environ.get("LUGRIP_CAMPAIGN_TRACEBACK"):
            traceback.print_exc()
    elapsed = time.perf_counter() - t0
    cpu = time.process_time() - c0
    if campaign.frontier is not None and error is None:
        t1 = time.perf_counter()
        frontier = constant_frontier(campaign, scn, limits)
        frontier_s = time.perf_counter() - t1
    run_cols: dict[str, Any] = {
        "set": campaign.result_set,
        "min_static_force": limits["min_static_force"],
        "crush_force": limits["crush_force"],
    }
    if campaign.frontier is not None:
        f = frontier or {}
        run_cols.update(
            frontier_force=f.get("force"),
            frontier_found=bool(f.get("found", False)),
            frontier_fail_above=f.get("fail_above"),
            frontier_low=f.get("low"),
            frontier_high=f.get("high"),
            frontier_evaluations=int(f.get("evaluations", 0)),
            frontier_floor_passed=bool(f.get("floor_passed", False)),
            frontier_history=json.dumps(f.get("history", [])),
            frontier_error=f.get("error") if frontier is not None else error,
            frontier_elapsed_s=frontier_s,
        )
    for name in campaign.controllers:
        row: dict[str, Any] = {
            "run": int(index),
            "controller": name,
            "campaign_seed": campaign.draw_seed,
            "plant_seed": int(params["plant_seed"]),
        }
        for k in campaign.columns():
            v = params.get(k)
            row[f"p_{k}"] = None if v is None else float(v)
        row.update(run_cols)
        if name in runs:
            m = dict(runs[name][1], crush_force=limits["crush_force"])
            for k in METRICS:
                v = m.get(k)
                row[f"m_{k}"] = v if v is None or isinstance(v, (bool, str)) else float(v)
            crit = _criteria(campaign, m)
            for k, ok in crit.items():
                row[f"pass_{k}"] = bool(ok)
            row["success"] = all(crit.values())
            row["error"] = None
        else:
            for k in METRICS:
                row[f"m_{k}"] = None
            for k, limit in campaign.criteria.items():
                if limit is not False:
                    row[f"pass_{k}"] = False
            row["success"] = False
            row["error"] = error
        row["elapsed_s"] = elapsed / max(len(campaign.controllers), 1)
        row["cpu_s"] = cpu / max(len(campaign.controllers), 1)
        rows.append(row)
    return rows


# --- results directory ------------------------------------------------------------------------


class ResultStore:
    """The Parquet results of one campaign in `directory` (see the module docstring)."""

    def __init__(self, directory: str | Path, campaign: Campaign):
        self.dir = Path(directory)
        self.campaign = campaign
        self.parts = self.dir / "parts"
        self.results = self.dir / "results.parquet"
        self.meta = self.dir / "campaign.json"

    def open(self) -> None:
        """Create the directory or check that it holds this campaign."""
        fp = self.campaign.fingerprint()
        if self.meta.is_file():
            old = json.loads(self.meta.read_text())
            if old.get("fingerprint") != fp:
                raise CampaignError(
                    f"{self.dir} holds results of another campaign definition "
                    f"({old.get('name')}, fingerprint {old.get('fingerprint')}); use a new --out"
                )
            return
        self.parts.mkdir(parents=True, exist_ok=True)
        # the base scenario written out: the directory replays without the original files
        doc = {"name": self.campaign.name, "set": self.campaign.result_set,
               "seed": self.campaign.draw_seed, "fingerprint": fp,
               "campaign": self.campaign.portable()}
        tmp = self.meta.with_suffix(".tmp")
        tmp.write_text(json.dumps(doc, indent=1, default=str))
        os.replace(tmp, self.meta)

    def _files(self) -> list[Path]:
        files = [self.results] if self.results.is_file() else []
        if self.parts.is_dir():
            files += sorted(self.parts.glob("run-*.parquet"))
        return files

    def rows(self) -> list[dict[str, Any]]:
        """Every stored row, one copy per (run, controller), sorted."""
        import pyarrow.parquet as pq

        seen: dict[tuple[int, str], dict] = {}
        for f in self._files():
            for r in pq.read_table(f).to_pylist():
                seen.setdefault((int(r["run"]), str(r["controller"])), r)
        return [seen[k] for k in sorted(seen)]

    def done(self) -> set[int]:
        """Indices of the finished runs."""
        import pyarrow.parquet as pq

        out: set[int] = set()
        for f in self._files():
            out.update(int(v) for v in pq.read_table(f, columns=["run"]).column("run").to_pylist())
        return out

    def write_run(self, index: int, rows: list[dict[str, Any]]) -> None:
        import pyarrow as pa
        import pyarrow.parquet as pq

        self.parts.mkdir(parents=True, exist_ok=True)
        path = self.parts / f"run-{index:07d}.parquet"
        tmp = path.with_suffix(f".tmp{os.getpid()}")
        pq.write_table(pa.Table.from_pylist(rows), tmp)
        os.replace(tmp, path)

    def consolidate(self) -> None:
        """Write every row to results.parquet and remove the parts."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        parts = sorted(self.parts.glob("run-*.parquet")) if self.parts.is_dir() else []
        if not parts:
            return
        rows = self.rows()
        tmp = self.results.with_suffix(".tmp")
        pq.write_table(pa.Table.from_pylist(rows), tmp)
        os.replace(tmp, self.results)
        for p in parts:
            p.unlink()

    def table(self):
        """The stored rows as a pyarrow Table."""
        import pyarrow as pa

        return pa.Table.from_pylist(self.rows())


# --- backends ----------------------------------------------------------------------------------

_WORKER_CAMPAIGN: Campaign | None = None


def _init_worker(campaign: Campaign) -> None:
    global _WORKER_CAMPAIGN
    from ._lifetime import die_with_parent

    die_with_parent()  # a killed campaign leaves no worker behind
    _WORKER_CAMPAIGN = campaign


def _pool_task(index: int) -> tuple[int, list[dict]]:
    assert _WORKER_CAMPAIGN is not None
    return index, run_one(_WORKER_CAMPAIGN, index)


def _process_backend(campaign: Campaign, todo: Sequence[int], workers: int) -> Iterable:
    import multiprocessing as mp
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    ctx = mp.get_context("spawn")  # no inherited threads or MuJoCo/GL state
    with ProcessPoolExecutor(workers, mp_context=ctx, initializer=_init_worker,
                             initargs=(campaign,)) as pool:
        pending = set()
        queue = list(todo)[::-1]
        while queue or pending:
            while queue and len(pending) < 2 * workers:
                pending.add(pool.submit(_pool_task, queue.pop()))
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            for fut in finished:
                yield fut.result()


def _ray_backend(campaign: Campaign, todo: Sequence[int], workers: int, address: str | None):
    try:
        import ray
    except ImportError:
        raise CampaignError(
            "--backend ray needs Ray: pip install 'lugrip[cluster]'"
        ) from None
    started = False
    if not ray.is_initialized():
        kwargs: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False}
        if address:
            kwargs["address"] = address
        else:
            kwargs["num_cpus"] = workers
        ray.init(**kwargs)
        started = True
    try:
        task = ray.remote(num_cpus=1)(_ray_task)
        ref = ray.put(campaign.portable())
        limit = 2 * workers if not address else 4 * max(int(ray.cluster_resources().get("CPU", 1)), 1)
        queue = list(todo)[::-1]
        pending = []
        while queue or pending:
            while queue and len(pending) < limit:
                pending.append(task.remote(ref, queue.pop()))
            finished, pending = ray.wait(pending, num_returns=1)
            for f in finished:
                yield ray.get(f)
    finally:
        if started:
            ray.shutdown()


def _ray_task(campaign_doc: dict, index: int) -> tuple[int, list[dict]]:
    return index, run_one(campaign_from_doc(campaign_doc), index)


def campaign_from_doc(doc: dict) -> Campaign:
    """The Campaign of a ``to_dict`` document (as stored in campaign.json)."""
    return Campaign.from_dict(dict(doc))


class Progress:
    """The campaign's progress bar on stderr (tqdm): runs done, rate, ETA and the success rate
    per controller so far. Redraws in place on a terminal; elsewhere (a log file, CI) tqdm
    writes a line at most every 30 s."""

    def __init__(self, total: int, controllers: Sequence[str], stream=None, enabled=True):
        from tqdm import tqdm

        self.ok = dict.fromkeys(controllers, 0)
        self.n = dict.fromkeys(controllers, 0)
        stream = stream or sys.stderr
        tty = bool(getattr(stream, "isatty", lambda: False)())
        self.bar = tqdm(total=total, unit="run", desc="campaign", file=stream,
                        disable=not enabled, mininterval=0.5 if tty else 30.0,
                        dynamic_ncols=tty, leave=True)

    def update(self, rows: Sequence[dict]) -> None:
        for r in rows:
            self.n[r["controller"]] += 1
            self.ok[r["controller"]] += bool(r["success"])
        self.bar.set_postfix_str(
            " ".join(f"{c} {100.0 * self.ok[c] / self.n[c]:.0f}%" for c in self.ok if self.n[c]),
            refresh=False,
        )
        self.bar.update(1)
        if self.bar.n >= self.bar.total:
            self.bar.close()


def run_campaign(
    campaign: Campaign,
    runs: int,
    out: str | Path,
    *,
    workers: int = 1,
    backend: str = "process",
    ray_address: str | None = None,
    progress: bool = True,
    on_run: Callable[[int, list[dict]], None] | None = None,
) -> dict[str, Any]:
    """Run indices 0 .. runs-1 of `campaign` that `out` does not hold yet, streaming each
    finished run to `out`. Returns {done, ran, skipped, elapsed_s, runs_per_s}."""
    if backend not in BACKENDS:
        raise CampaignError(f"backend {backend!r}: expected one of {', '.join(BACKENDS)}")
    if runs < 1 or workers < 1:
        raise CampaignError("--runs and --workers must be >= 1")
    from .validate import validate_campaign

    validate_campaign(campaign)  # a definition error is exit 2 at load, never failed runs
    store = ResultStore(out, campaign)
    store.open()
    done = store.done()
    todo = [i for i in range(runs) if i not in done]
    bar = Progress(len(todo), list(campaign.controllers), enabled=progress)
    t0 = time.perf_counter()
    if todo:
        if backend == "process":
            results = _process_backend(campaign, todo, workers)
        else:
            results = _ray_backend(campaign, todo, workers, ray_address)
        for index, rows in results:
            store.write_run(index, rows)
            bar.update(rows)
            if on_run is not None:
                on_run(index, rows)
    elapsed = time.perf_counter() - t0
    finished = store.done()  # read once: it opens every part file
    if all(i in finished for i in range(runs)):
        store.consolidate()
    return {
        "requested": runs,
        "ran": len(todo),
        "skipped": runs - len(todo),
        "elapsed_s": elapsed,
        "runs_per_s": len(todo) / elapsed if todo and elapsed > 0 else math.nan,
    }

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
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any

from .._controller import PAPER_SETTINGS
from .definition import Campaign, CampaignError

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
)


def _controller_call(name: str, opts: dict, scenario) -> tuple[str, dict, dict, dict]:
    """(kind, controller settings, observer settings, options of simulate) of a controller."""
    ctrl = dict(scenario.controller)
    obs = dict(scenario.observer)
    if name in ("lugrip", "paper"):
        if name == "paper":
            ctrl.update(PAPER_SETTINGS)
        ctrl.update(opts.get("controller") or {})
        obs.update(opts.get("observer") or {})
        return "lugrip", ctrl, obs, {}
    if name == "constant_force":
        return "constant_force", ctrl, obs, {"constant_force": float(opts["force"])}
    return "friction_cone", ctrl, obs, dict(opts)


def _criteria(campaign: Campaign, m: dict) -> dict[str, bool]:
    out = {}
    for k, limit in campaign.criteria.items():
        if limit is False:
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


def simulate_run(campaign: Campaign, index: int, controllers: Sequence[str] | None = None):
    """Scenario, drawn parameters and {controller: (run, metrics)} of run `index`."""
    from ..sim.scenarios import Scenario, compute_metrics, simulate

    scn, params = campaign.run_scenario(index)
    cfg = scn.plant_config(campaign.plant)
    out = {}
    for name in controllers or campaign.controllers:
        kind, ctrl, obs, opts = _controller_call(name, campaign.controllers[name], scn)
        s = Scenario.from_dict(scn.to_dict() | {"controller": ctrl, "observer": obs}, scn.source)
        schedule = s.schedule if kind == "lugrip" else None
        run = simulate(s, cfg, campaign.plant, schedule, kind=kind, **opts)
        out[name] = (run, compute_metrics(s, run, cfg=cfg, pivot=kind == "lugrip"))
    return scn, params, out


def run_one(campaign: Campaign, index: int) -> list[dict[str, Any]]:
    """The result rows of run `index` (one per controller): run, controller, seeds, drawn
    parameters (``p_<name>``), metrics (``m_<name>``), criteria (``pass_<name>``), success,
    error (the exception's last line when the simulation failed; then success is False), the
    wall and CPU time of the run shared out over its controllers (``elapsed_s``, ``cpu_s``). A
    pure function of (campaign, index) but for those two."""
    rows = []
    t0 = time.perf_counter()
    c0 = time.process_time()
    try:
        _, params, runs = simulate_run(campaign, index)
        error = None
    except Exception as err:  # noqa: BLE001 (a grasp the simulator rejects is a recorded failed run)
        params = campaign.draw(index)
        runs = {}
        error = f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}"
        if os.environ.get("LUGRIP_CAMPAIGN_TRACEBACK"):
            traceback.print_exc()
    elapsed = time.perf_counter() - t0
    cpu = time.process_time() - c0
    for name in campaign.controllers:
        row: dict[str, Any] = {
            "run": int(index),
            "controller": name,
            "campaign_seed": campaign.seed,
            "plant_seed": int(params["plant_seed"]),
        }
        for k in campaign.parameters:
            row[f"p_{k}"] = float(params[k])
        if name in runs:
            m = runs[name][1]
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
        doc = {"name": self.campaign.name, "fingerprint": fp, "campaign": self.campaign.portable()}
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
    """One status line on stderr: runs done, rate, success rate per controller."""

    def __init__(self, total: int, controllers: Sequence[str], stream=None, enabled=True):
        self.total, self.done = total, 0
        self.ok = dict.fromkeys(controllers, 0)
        self.n = dict.fromkeys(controllers, 0)
        self.stream = stream or sys.stderr
        self.enabled = enabled
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.t0 = time.perf_counter()
        self._last = -1.0

    def update(self, rows: Sequence[dict]) -> None:
        self.done += 1
        for r in rows:
            self.n[r["controller"]] += 1
            self.ok[r["controller"]] += bool(r["success"])
        if not self.enabled:
            return
        frac = self.done / max(self.total, 1)
        if not self.tty and self.done < self.total and frac - self._last < 0.1:
            return
        self._last = frac
        dt = time.perf_counter() - self.t0
        rates = " ".join(
            f"{c} {100.0 * self.ok[c] / self.n[c]:.0f}%" for c in self.ok if self.n[c]
        )
        width = 20
        bar = "#" * int(width * frac) + "-" * (width - int(width * frac))
        line = f"[{bar}] {self.done}/{self.total} {self.done / dt if dt > 0 else 0:.2f} runs/s  {rates}"
        self.stream.write(("\r" + line) if self.tty else (line + "\n"))
        if self.tty and self.done == self.total:
            self.stream.write("\n")
        self.stream.flush()


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

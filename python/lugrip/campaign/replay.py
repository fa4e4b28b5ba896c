"""Replaying one run of a campaign alone, with its figures: the grasp is rebuilt from the
results directory's campaign and the run index (nothing else is needed)."""

from __future__ import annotations

import json
import types
from pathlib import Path
from typing import Any

from .._atomic import write_text_atomic
from .definition import Campaign, CampaignError
from .runner import campaign_from_doc, simulate_run

__all__ = ["load_results_campaign", "replay", "replay_command"]


def load_results_campaign(directory: str | Path) -> Campaign:
    """The campaign a results directory was written by (its campaign.json)."""
    meta = Path(directory) / "campaign.json"
    if not meta.is_file():
        raise CampaignError(f"{directory}: not a campaign results directory (no campaign.json)")
    try:
        doc = json.loads(meta.read_text(encoding="utf-8"))
        return campaign_from_doc(doc["campaign"])
    except (ValueError, KeyError, TypeError) as err:  # broken JSON or not lugrip's document
        if isinstance(err, CampaignError):
            raise CampaignError(f"{meta}: {err}") from None
        raise CampaignError(f"{meta}: not a campaign.json lugrip wrote ({type(err).__name__}"
                            f"{': ' + str(err).splitlines()[0][:120] if str(err) else ''})"
                            ) from None


def replay(directory: str | Path, index: int, *, controllers=None, out: str | Path | None = None,
           figures: bool = True) -> dict[str, Any]:
    """Run `index` of the campaign stored in `directory` again (every controller, or
    `controllers`), write replay_<index>.json and, with `figures`, replay_<index>_baselines.png
    (command, slip, rotation of every controller) and replay_<index>_<controller>.png (force,
    load, S and c~, omega_hat) into `out` (default: the directory). Returns the metrics, the
    drawn parameters and whether the stored rows are reproduced."""
    from .runner import ResultStore, _criteria

    campaign = load_results_campaign(directory)
    names = list(controllers or campaign.controllers)
    unknown = [c for c in names if c not in campaign.controllers]
    if unknown:
        raise CampaignError(
            f"--controller {', '.join(unknown)}: not in the campaign "
            f"({', '.join(campaign.controllers)})"
        )
    scn, params, runs = simulate_run(campaign, index, names)
    out_dir = Path(out) if out is not None else Path(directory)
    out_dir.mkdir(parents=True, exist_ok=True)
    stored = {r["controller"]: r for r in ResultStore(directory, campaign).rows()
              if int(r["run"]) == index}
    limits = campaign.run_limits(scn, params)
    doc: dict[str, Any] = {"run": index, "parameters": params, "limits": limits,
                           "controllers": {}}
    for name, (_, m) in runs.items():
        crit = _criteria(campaign, dict(m, crush_force=limits["crush_force"]))
        row = stored.get(name)
        same = None
        if row is not None:
            same = all(
                row.get(f"m_{k}") == (float(m[k]) if isinstance(m.get(k), (int, float))
                                      and not isinstance(m.get(k), bool) else m.get(k))
                for k in ("hold_slip_mm", "hold_rotation_deg", "mean_force", "dropped")
            )
        doc["controllers"][name] = {
            "success": all(crit.values()),
            "criteria": crit,
            "metrics": {k: v for k, v in m.items() if isinstance(v, (int, float, bool, str))
                        or v is None},
            "matches_stored_row": same,
        }
    paths = {}
    if figures:
        from .. import plot
        from ..plot.experiments import _force_s_omega, figure_baselines

        res = types.SimpleNamespace(
            scenario=scn, runs={k: v[0] for k, v in runs.items()},
            metrics={k: v[1] for k, v in runs.items()},
        )
        paths["baselines"] = plot.save(figure_baselines(res), out_dir / f"replay_{index}_baselines.png")
        for name in names:
            if campaign.controllers and name in ("lugrip", "paper"):
                one = types.SimpleNamespace(scenario=scn, runs={"lugrip": runs[name][0]},
                                            metrics={"lugrip": runs[name][1]})
                fig = _force_s_omega(one, f"{campaign.name} run {index}: {name}",
                                     tangential=True, torque=True)
                paths[name] = plot.save(fig, out_dir / f"replay_{index}_{name}.png")
    doc["figures"] = {k: str(v) for k, v in paths.items()}
    path = out_dir / f"replay_{index}.json"
    write_text_atomic(path, json.dumps(doc, indent=1, default=str))
    doc["json"] = str(path)
    return doc


def replay_command(directory, index: int, *, controllers=None, out=None, figures=True) -> int:
    """:func:`replay` with a summary on stdout (``lugrip campaign replay`` and ``lugrip
    simulate --campaign``); returns the exit code 0."""
    doc = replay(directory, index, controllers=controllers, out=out, figures=figures)
    nan = float("nan")
    for c, d in doc["controllers"].items():
        m = d["metrics"]
        same = {True: "same as stored", False: "DIFFERS from stored", None: "not stored"}[
            d["matches_stored_row"]]
        print(f"run {index} {c}: {'held' if d['success'] else 'FAILED'}; hold slip "
              f"{m.get('hold_slip_mm', nan):.3f} mm, rotation "
              f"{m.get('hold_rotation_deg', nan):.3f} deg, mean force "
              f"{m.get('mean_force', nan):.2f} N, dropped {m.get('dropped')} ({same})")
    for name, path in doc["figures"].items():
        print(f"figure ({name}): {path}")
    print(f"metrics: {doc['json']}")
    return 0

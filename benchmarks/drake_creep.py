"""Open-loop creep of a grasp on Drake (BENCHMARKS.md, "Closed loop on three plants"; docs/drake.md).

exp2's block (its off-CoG load: half the weight and half the gravity torque per finger) lifted
from 1 s to 4 s and held at a constant grip force, no pushes; the rotation and slip rates of the
object relative to the pads over 5-9 s, for Drake's discrete contact approximations, stiction
tolerances and time steps. A constant force above the static minimum that still turns the
object measures the engine's friction, not lugrip's controller.

Usage: python benchmarks/drake_creep.py OUT.jsonl CONFIG.json [CONFIG.json ...]
where each CONFIG is a JSON object {"force": N, and DrakePlant options: "approximation",
"stiction_tolerance", "timestep"}, e.g. '{"force": 6.0, "approximation": "sap"}'. One JSON line
per configuration is appended to OUT.jsonl as it finishes (it takes minutes on Drake).
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np

from lugrip._controller import static_grasp_force
from lugrip.sim.drake.plant import DrakePlant
from lugrip.sim.runner import run_plant_loop
from lugrip.sim.scenario_file import Scenario
from lugrip.sim.scenarios import load_scenario

#: the window the rates are fitted over [s] (the lift ends at 4 s)
WINDOW = (5.0, 9.0)


def scene() -> Scenario:
    base = load_scenario("exp2_small_resin_block")
    d = base.to_dict()
    d["duration"] = WINDOW[1]
    d["plant"] = dict(d["plant"], disturbances=[])
    d["steady_window"] = None
    return Scenario.from_dict(d, base.source).for_plant("drake")


def measure(s: Scenario, config: dict) -> dict:
    c = dict(config)
    force = float(c.pop("force"))
    cfg = s.plant_config("drake")
    plant = DrakePlant(**c)
    est = plant.estimator(cfg)
    m, g = cfg.object.mass, float(cfg.gravity)
    f_min = float(static_grasp_force(est, 0.5 * m * g, 0.5 * m * g * abs(cfg.object.cog[0]),
                                     s_ref=1.0))
    t0 = time.perf_counter()
    run = run_plant_loop(plant, s, cfg, s.controller, s.observer, None, s.duration,
                         kind="constant_force", constant_force=force)
    t = run["t"]
    w = (t >= WINDOW[0]) & (t < WINDOW[1])
    rot = np.degrees(run["rotation"][w])
    slip = run["slip"][w] * 1e3
    return dict(c, force=force, static_min=f_min, force_over_min=force / f_min,
                rot_rate_deg_s=float(np.polyfit(t[w], rot, 1)[0]),
                slip_rate_mm_s=float(np.polyfit(t[w], slip, 1)[0]),
                scene=plant.scene_status()["status"], wall_s=time.perf_counter() - t0)


def main(argv=None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) < 2:
        print(__doc__)
        return 2
    s = scene()
    with open(args[0], "a") as out:
        for text in args[1:]:
            print(json.dumps(measure(s, json.loads(text))), file=out, flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Per-cycle cost of SlipControl from Python against the hand-wired path it replaces.

Measured in one run on the same recorded two-finger wrenches (a quasi-static grip with noise):
* hand-wired: two ``lugrip.Observer.step_vector`` calls and one ``lugrip.GraspController.step``
  with every observer value and status passed by hand (the wiring SlipControl replaces);
* ``lugrip.SlipControl.step`` on a (2, 4) float64 array;
* ``lugrip.SlipControl.run`` over (N, 2, 4) in one C++ loop (per cycle);
* the C++ core alone is ``bench_core``'s business; here its cost shows up in run().

Writes the ``slip_control`` section of BENCHMARKS.md (``--out``); prints it otherwise.
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
from pathlib import Path

import numpy as np

import lugrip

sys.path.insert(0, str(Path(__file__).resolve().parent))
from sections import markers, write_section  # noqa: E402

PARAMS = "aluminium_can"


def wrenches(n: int, seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    w = np.empty((n, 2, 4))
    w[:, :, 0] = 2.0 + 0.005 * rng.standard_normal((n, 2))
    w[:, :, 1] = 0.3 + 0.005 * rng.standard_normal((n, 2))
    w[:, :, 2] = 0.005 * rng.standard_normal((n, 2))
    w[:, :, 3] = 2e-3 + 1e-5 * rng.standard_normal((n, 2))
    return w


def hand_wired(w: np.ndarray) -> float:
    obs = [lugrip.Observer(PARAMS), lugrip.Observer(PARAMS)]
    ctrl = lugrip.GraspController(PARAMS)
    t0 = time.perf_counter()
    for k in range(len(w)):
        o0 = obs[0].step_vector(*w[k, 0])
        o1 = obs[1].step_vector(*w[k, 1])
        ctrl.step(omega_hat=[o0.omega_hat, o1.omega_hat], S=[o0.S, o1.S], c_tilde=[o0.c_tilde, o1.c_tilde],
                  f_t=[np.hypot(w[k, 0, 1], w[k, 0, 2]), np.hypot(w[k, 1, 1], w[k, 1, 2])],
                  status=[int(o0.status), int(o1.status)],
                  omega_resolution=[o0.omega_resolution, o1.omega_resolution])
    return (time.perf_counter() - t0) / len(w)


def slip_step(w: np.ndarray) -> float:
    sc = lugrip.SlipControl(PARAMS)
    rows = [np.ascontiguousarray(w[k]) for k in range(len(w))]  # as a driver would hand them over
    t0 = time.perf_counter()
    for r in rows:
        sc.step(r)
    return (time.perf_counter() - t0) / len(w)


def core_step(w: np.ndarray) -> float:
    """The nanobind method without the Python wrapper (argument parsing + the C++ cycle)."""
    sc = lugrip.SlipControl(PARAMS)._sc
    rows = [np.ascontiguousarray(w[k]) for k in range(len(w))]
    t0 = time.perf_counter()
    for r in rows:
        sc.step(r, 0.0)
    return (time.perf_counter() - t0) / len(w)


def slip_run(w: np.ndarray) -> float:
    sc = lugrip.SlipControl(PARAMS)
    t0 = time.perf_counter()
    sc.run(w)
    return (time.perf_counter() - t0) / len(w)


def best(fn, w, repeats: int) -> float:
    return min(fn(w) for _ in range(repeats))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=20000)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--out", type=Path, help="BENCHMARKS.md to update")
    args = ap.parse_args(argv)
    w = wrenches(args.samples)
    slip_step(w[:1000])  # warm-up (contact tables cached)
    t_hand = best(hand_wired, w[: max(2000, args.samples // 5)], args.repeats)
    t_step = best(slip_step, w, args.repeats)
    t_core = best(core_step, w, args.repeats)
    t_run = best(slip_run, w, args.repeats)
    begin, end = markers("slip_control")
    lines = [
        begin,
        "## SlipControl from Python (per two-finger cycle)",
        "",
        f"`python benchmarks/bench_slip_control.py --samples {args.samples} --repeats {args.repeats}`"
        f" (best of {args.repeats}; {platform.python_implementation()} {platform.python_version()},"
        f" {platform.machine()}; the machine is shared, so absolute figures vary, the ratios were measured"
        " in the same run).",
        "",
        "| path | µs per cycle | vs hand-wired |",
        "|---|---:|---:|",
        f"| hand-wired: 2 × `Observer.step_vector` + `GraspController.step` | {t_hand * 1e6:.2f} | 1.0× |",
        f"| `SlipControl.step` on a (2, 4) array | {t_step * 1e6:.2f} | {t_hand / t_step:.1f}× faster |",
        f"| `lugrip._core.SlipControl.step` (no Python wrapper) | {t_core * 1e6:.2f} | {t_hand / t_core:.1f}× faster |",
        f"| `SlipControl.run` over (N, 2, 4), per cycle (70 output columns written) | {t_run * 1e6:.2f} | {t_hand / t_run:.1f}× faster |",
        "",
        "The step figure includes the core's own work (two observer updates and the controller),"
        " i.e. the Python overhead is below it.",
        end,
        "",
    ]
    text = "\n".join(lines)
    print(text)
    if args.out:
        write_section(args.out, text, "slip_control")
    return 0


if __name__ == "__main__":
    sys.exit(main())

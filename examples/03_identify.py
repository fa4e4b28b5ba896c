"""Example 03 (Python): identify the contact parameters from sliding logs, then an object's
mu and beta_A (paper Sections 4 and 6).

1. Simulate Section-4 maneuvers of a fingertip on the Table 1 slider (the "fingertip logs",
   with ground-truth velocity) and write them as a CSV sliding log.
2. Identify all six parameters (and the pressure exponent k) with lugrip.identify: stages from
   the data (limit surface from the gross-sliding wrench, viscous shear with a significance
   test, bristles from the loading runs, noise from the still samples), then the online
   observer's velocity error (eq. 32, C++ with its exact gradient) as a regularised
   refinement; the fit reports each stage, the validation RMSE, sandwich standard errors and
   what the data cannot separate.
   The parameters are identified FOR that observer (default settings: bandwidth 3000/s), so
   the YAML carries its settings as an observer: block, and the online observer built from the
   YAML (lugrip.Observer("fingertip.yaml"), lugrip observe --params) is the same one.
3. Per-object step: a few fast maneuvers on a Table 2 object, refit of mu and beta_A only,
   starting from the fingertip's YAML (its parameters and its observer block).
4. The rubbing alternative: rub the fingertip at known angular speeds and regress the torque.

    python examples/03_identify.py [OUT_DIR]

The same with the command line:
    lugrip simulate-sliding --out fingertip.csv --maneuvers 60
    lugrip identify fingertip.csv --out fingertip.yaml --report OUT_DIR
    lugrip identify object.csv --free mu,beta_a --params0 fingertip.yaml --out object.yaml
    lugrip observe object.csv --params object.yaml --out est.csv
"""

from __future__ import annotations

import sys
import tempfile
import warnings
from pathlib import Path

import lugrip
import numpy as np
from lugrip.identification import IdentificationWarning
from lugrip.sim import PatchContact
from lugrip.sliding import simulate_sliding


def main(out_dir: str | None = None) -> lugrip.ContactParams:
    with tempfile.TemporaryDirectory() as tmp:
        return _main(Path(tmp), out_dir)


def _main(tmp: Path, out_dir: str | None) -> lugrip.ContactParams:
    truth = lugrip.ContactParams.table1()
    log = simulate_sliding(truth, 60, seed=3, c_range=(0.02, 1.4), omega_range=(0.002, 0.5))
    log = lugrip.read_log(lugrip.write_log(log, tmp / "fingertip.csv"))
    print(f"fingertip logs: {len(np.unique(log.maneuver))} maneuvers, {len(log)} samples")

    # The observer inside the cost has the default settings (bandwidth 3000/s: fast enough that
    # the physical parameters come back; a slow observer's lag would be absorbed by sigma0 and
    # sigma_z, BENCHMARKS.md issue 4). Pass observer={...} to identify for another one.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IdentificationWarning)
        fit = lugrip.identify(log)  # stages from the data, then eq. 32; all six free
    print(fit.summary())
    for name in ("mu", "beta_a", "sigma0", "sigma_z", "delta", "gamma"):
        print(
            f"  {name:8s} identified / true = {getattr(fit.params, name) / getattr(truth, name):.4f}"
        )

    # The YAML keeps the parameters with the observer they were identified for.
    fingertip_yaml = fit.save_yaml(tmp / "fingertip.yaml")
    block = lugrip.read_observer_settings(fingertip_yaml)
    print(
        f"{fingertip_yaml.name}: observer block {block['integrator']}, {block['gain_mode']} "
        f"{block['bandwidth']:g}/s"
    )
    online = lugrip.Observer(fingertip_yaml)  # the identified parameters and their observer
    print(f"online observer from the YAML: RMSE {online.run(log).rmse(log.omega):.4g} rad/s")
    if out_dir is not None:
        from lugrip.commands.identify import write_report

        for path in write_report(fit, out_dir):
            print(f"wrote {path}")

    # Per-object step: the fingertip's parameters stay, mu and beta_A are refitted from ten
    # maneuvers that slide fast enough (0.5-5 rad/s) for the weak viscous friction to show.
    obj = lugrip.ContactParams.preset("aluminium_can")
    # params0 = the fingertip's YAML: its parameters and, from its observer block, its observer.
    obj_log = simulate_sliding(
        obj, 10, seed=4, c_range=(0.02, 1.4), omega_range=(0.5, 5.0), stick_fraction=0.0
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IdentificationWarning)
        refit = lugrip.identify(obj_log, fingertip_yaml, free="mu,beta_a", validation=0.0)
    print(
        f"object refit: mu {refit.params.mu:.4f} (true {obj.mu}), beta_A "
        f"{refit.params.beta_a:.4g} (true {obj.beta_a:.4g}) in {refit.fit_time:.2f} s, observer "
        f"bandwidth {refit.observer['bandwidth']:g}/s (the fingertip YAML's)"
    )

    # Rubbing: rotate the fingertip on the object at known speeds (here on the distributed
    # patch-contact model) and regress |tau| = mu xi rho f_n + beta_A (pi/2) rho^4 |omega|.
    pad = PatchContact(obj)
    f_n, tau, omega = [], [], []
    for w in (2.0, 4.0, 8.0):
        for _ in range(200):
            _, _, tz = pad.advance(5.0, 0.0, 0.0, w, 0.002)
            f_n.append(5.0)
            tau.append(-tz)
            omega.append(w)
    est = lugrip.estimate_rubbing(
        None,
        fit.params,
        mode="rotation",
        velocity=np.array(omega),
        f_n=np.array(f_n),
        tau=np.array(tau),
        t=np.arange(len(f_n)) * 0.002,
    )
    print(est)
    return fit.params


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)

"""The lumped model (paper eqs. 1-2 about the prescribed CoR) driven by prescribed motion.

This rig is lugrip's own contact model: data from it check that the identification is
consistent with the model it assumes, not that it holds on a real contact (use the grid and
MuJoCo rigs for that). The motion comes from :func:`lugrip.rigs.plan_maneuvers`, as for every
rig: the bristle state follows the prescribed angular velocity exactly,

    dz/dt = omega - sigma0 |omega| z / g(f_n, c),

integrated with the exponential update for frozen omega on sub-steps of the sample period;
the friction torque about the CoR is y = sigma0 z + sigma_z dz/dt + sigma_1 omega and the
sensor reads the wrench :func:`lugrip.sensor_wrench` gives for it at that CoR, in-plane force
along a random direction, plus the plan's offsets and noise.
"""

from __future__ import annotations

import math

import numpy as np

from .._contact import _as_params
from .._contact import g as _g
from .._contact import sigma_1 as _sigma_1
from .._observer import sensor_wrench
from .._params import ContactParams
from ..io import SlidingLog
from ._data import RigTruth, RubbingData
from .motion import RubbingDesign, plan_maneuvers, stack_times

__all__ = ["lumped_rubbing"]

_SLIDING = 0.98  # sigma0 |z| / g above which the lumped contact counts as in gross sliding


def lumped_rubbing(
    params: ContactParams | str,
    n: int,
    seed: int = 0,
    *,
    design: RubbingDesign | None = None,
    substeps: int = 8,
    resolution_max: float = 0.02,
) -> RubbingData:
    """``n`` prescribed-motion maneuvers through the lumped model with ``params``.

    Phase labels: 0 before the motion, 3 after it, 2 where sigma0 |z| >= 0.98 g (the
    bristles at their bound: gross sliding), 1 otherwise; load_ratio = |y| / g. The truth's
    ``viscous`` says whether the speed resolution torque_noise / sigma_1 (c~ = 0, median
    force) is at most ``resolution_max`` [rad/s].
    """
    p = _as_params(params)
    design = RubbingDesign() if design is None else design
    plans = plan_maneuvers(design, n, seed, radius=(p.delta, p.gamma))
    dt = 1.0 / design.sample_rate
    starts = stack_times(plans, dt)
    rng = np.random.default_rng(seed + 7)
    cols = {k: [] for k in ("t", "f_n", "f_x", "f_y", "tau", "omega", "maneuver")}
    phase, ratio, ct_true, v_true = [], [], [], []
    for plan, t0 in zip(plans, starts):
        m = len(plan.t)
        fn = plan.f_n
        om = plan.omega
        rho = p.delta * fn**p.gamma
        ct = plan.c_tilde_signed(rho)
        gg = np.asarray(_g(p, fn, ct), dtype=float)
        s1 = np.asarray(_sigma_1(p, fn, ct), dtype=float)
        z = np.zeros(m)
        zd = np.zeros(m)
        zi = 0.0
        for i in range(1, m):
            ts = plan.t[i - 1] + (np.arange(substeps) + 0.5) * dt / substeps
            for w in plan.omega_pad_at(ts):
                w = -float(w)  # the slider's omega relative to the fingertip
                a = p.sigma0 * abs(w) / gg[i] * dt / substeps
                if a > 0.0:
                    z_inf = math.copysign(gg[i] / p.sigma0, w)
                    zi = z_inf + (zi - z_inf) * math.exp(-a)
            z[i] = zi
            zd[i] = om[i] - p.sigma0 * abs(om[i]) * zi / gg[i]
        y = p.sigma0 * z + p.sigma_z * zd + s1 * om
        ft, tau = sensor_wrench(p, fn, np.abs(ct), y)
        ang = rng.uniform(0.0, 2.0 * np.pi)
        f_n_s, f_x, f_y, tau_s = plan.sensor(fn, ft * math.cos(ang), ft * math.sin(ang), tau)
        cols["t"].append(t0 + plan.t)
        cols["f_n"].append(f_n_s)
        cols["f_x"].append(f_x)
        cols["f_y"].append(f_y)
        cols["tau"].append(tau_s)
        cols["omega"].append(om)
        cols["maneuver"].append(np.full(m, plan.index))
        ph = plan.commanded_phase()
        moving = ph == 1
        ph[moving & (p.sigma0 * np.abs(z) >= _SLIDING * gg)] = 2
        phase.append(ph)
        ratio.append(np.abs(p.sigma0 * z) / gg)
        ct_true.append(ct)
        v_true.append(np.abs(om) * np.abs(ct) * rho)
    log = SlidingLog.from_arrays(
        **{k: np.concatenate(v) for k, v in cols.items()}, source="lumped", check_units=False
    )
    from .._contact import LimitSurface

    xi = LimitSurface(p.k).xi
    f_pts = (1.0, 2.0, 4.0, 8.0, 16.0)
    truth = RigTruth(
        name="lumped",
        mu_static=p.mu,
        mu_kinetic=p.mu,
        mu=p.mu,
        beta_a=p.beta_a,
        viscous=bool(
            design.noise_torque
            <= resolution_max * float(np.median(_sigma_1(p, np.concatenate(cols["f_n"]), 0.0)))
        ),
        delta=p.delta,
        gamma=p.gamma,
        pressure=f"k = {p.k:g}",
        tau_max_points=tuple((f, p.mu * xi * p.delta * f ** (1.0 + p.gamma)) for f in f_pts),
        notes="lugrip's own lumped model (consistency data)",
    )
    return RubbingData(
        log=log,
        phase=np.concatenate(phase),
        load_ratio=np.concatenate(ratio),
        c_tilde_true=np.concatenate(ct_true),
        v_true=np.concatenate(v_true),
        truth=truth,
        meta={"params": p.to_dict(), "seed": seed, "design": design.to_dict()},
    )

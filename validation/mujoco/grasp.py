"""lugrip in closed loop on MuJoCo: a parallel gripper lifts and holds a block off its CoG.

The plant here is not lugrip's: MuJoCo's soft-constraint contact with an elliptic friction cone
and torsional friction (condim 4), i.e. a limit surface that is an ellipse, (f_t / mu f_n)^2 +
(tau / mu_spin f_n)^2 <= 1, with a torsional capacity linear in f_n, no viscous friction and no
bristles. lugrip's observers and controller run on what the fingertip sensors would read (the
wrench the object exerts on each pad, 500 Hz, noise), command the gripper at 50 Hz through a
30 ms first-order force lag, and must hold the block through the lift and a push.

MuJoCo settings that matter (MuJoCo's defaults let a held object creep under a constant load):
elliptic cone, noslip_iterations >= 5, impratio 10, condim 4 on the pad contacts.

    python validation/mujoco/grasp.py [--out DIR] [--duration S] [--constant-force F]

Writes DIR/mujoco_grasp.json (metrics and pass flags) and DIR/mujoco_grasp.png.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import asdict, dataclass, field
from pathlib import Path

import lugrip
import mujoco
import numpy as np
from lugrip import ContactParams, GraspController, Observer

__all__ = ["GraspSetup", "build_model", "evaluate", "main", "run", "settings_sweep"]


@dataclass
class GraspSetup:
    """One grasp: object, contact, gripper and the controller that commands it."""

    contact: str = "small_resin_block"  #: preset: mu, beta_A from Table 2, the rest Table 1
    mass: float = 0.245  #: [kg] as scenarios/exp2_small_resin_block.yaml
    half_size: tuple[float, float, float] = (0.015, 0.05, 0.015)  #: box half sizes x, y, z [m]
    cog_offset: float = 0.0035  #: CoG beside the grasp point along y [m]: torque m g d
    pad_radius: float = 0.012  #: spherical fingertip pads [m]
    spin_force: float = 5.0  #: f_n [N] at which mu_spin f_n equals lugrip's tau_max(f_n)
    timestep: float = 0.001  #: MuJoCo step [s] (the robot's 1 kHz)
    noslip_iterations: int = 10
    impratio: float = 10.0
    cone: str = "elliptic"
    f_init: float = 2.0  #: grasp force at t = 0 [N]
    actuator_tau: float = 0.03  #: gripper force lag [s]
    lift_start: float = 1.0
    lift_duration: float = 3.0
    lift_height: float = 0.10
    duration: float = 10.0
    #: pushes on the object: (t_start [s], duration [s], world force (x, y, z) [N], torque
    #: about the grasp axis [N m]), half-sine in time
    pushes: list = field(
        default_factory=lambda: [
            (6.5, 0.5, (0.0, 0.0, -1.0), 0.0),
            (8.0, 0.5, (0.0, 0.0, 0.0), 0.003),
        ]
    )
    force_noise: float = 0.005  #: sensor noise std [N]
    torque_noise: float = 1e-5  #: [N m]
    seed: int = 0
    #: "lugrip" (observers + GraspController) or "constant" (the gripper holds `constant_force`)
    controller: str = "lugrip"
    constant_force: float = 2.0
    #: the observers' sigma_z: a pad without lugrip's bristle damping, as the patch scenarios
    estimator_sigma_z: float = 3.3e-3

    @property
    def sensor_ratio(self) -> int:
        return round(0.002 / self.timestep)


def _contact_params(s: GraspSetup) -> ContactParams:
    return ContactParams.preset(s.contact)


def spin_coefficient(s: GraspSetup) -> float:
    """MuJoCo's torsional friction coefficient [m]: mu xi rho(f) at f = spin_force, so that
    its torsional capacity mu_spin f_n equals lugrip's tau_max = mu xi rho f_n there."""
    p = _contact_params(s)
    return p.mu * lugrip.LimitSurface(p.k).xi * p.delta * s.spin_force**p.gamma


def build_model(s: GraspSetup) -> mujoco.MjModel:
    """The MJCF: table, block on planar joints (y, z, rotation about the grasp axis x, and x
    to centre between the pads), a hand on a vertical slide with two finger slides along x,
    force motors on the fingers, a stiff position servo on the lift."""
    p = _contact_params(s)
    hx, hy, hz = s.half_size
    r = s.pad_radius
    inertia_x = s.mass * ((2 * hy) ** 2 + (2 * hz) ** 2) / 12.0
    inertia_y = s.mass * ((2 * hx) ** 2 + (2 * hz) ** 2) / 12.0
    inertia_z = s.mass * ((2 * hx) ** 2 + (2 * hy) ** 2) / 12.0
    spin = spin_coefficient(s)
    z0 = hz  # the block rests on the table; the pads grasp it at the height of its centre
    xml = f"""
<mujoco model="lugrip_grasp">
  <option timestep="{s.timestep}" cone="{s.cone}" noslip_iterations="{s.noslip_iterations}"
          impratio="{s.impratio}" integrator="implicitfast" gravity="0 0 -9.81"/>
  <worldbody>
    <geom name="table" type="plane" size="0.3 0.3 0.01" friction="0.5 0.005 0.0001"/>
    <body name="block" pos="0 {s.cog_offset} {z0}">
      <joint name="bx" type="slide" axis="1 0 0"/>
      <joint name="by" type="slide" axis="0 1 0"/>
      <joint name="bz" type="slide" axis="0 0 1"/>
      <joint name="btheta" type="hinge" axis="1 0 0"/>
      <inertial pos="0 0 0" mass="{s.mass}" diaginertia="{inertia_x} {inertia_y} {inertia_z}"/>
      <geom name="box" type="box" size="{hx} {hy} {hz}" friction="{p.mu} 0.005 0.0001"/>
    </body>
    <body name="hand" pos="0 0 {z0}" gravcomp="1">
      <joint name="lift" type="slide" axis="0 0 1" damping="50"/>
      <inertial pos="0 0 0" mass="1.0" diaginertia="1e-3 1e-3 1e-3"/>
      <body name="finger0" pos="{-(hx + r)} 0 0" gravcomp="1">
        <joint name="f0" type="slide" axis="1 0 0" damping="2"/>
        <inertial pos="0 0 0" mass="0.05" diaginertia="1e-5 1e-5 1e-5"/>
        <geom name="pad0" type="sphere" size="{r}" contype="0" conaffinity="0"/>
      </body>
      <body name="finger1" pos="{hx + r} 0 0" gravcomp="1">
        <joint name="f1" type="slide" axis="1 0 0" damping="2"/>
        <inertial pos="0 0 0" mass="0.05" diaginertia="1e-5 1e-5 1e-5"/>
        <geom name="pad1" type="sphere" size="{r}" contype="0" conaffinity="0"/>
      </body>
    </body>
  </worldbody>
  <contact>
    <pair geom1="pad0" geom2="box" condim="4" friction="{p.mu} {p.mu} {spin} 0 0"/>
    <pair geom1="pad1" geom2="box" condim="4" friction="{p.mu} {p.mu} {spin} 0 0"/>
  </contact>
  <actuator>
    <motor name="m0" joint="f0" gear="1" ctrllimited="true" ctrlrange="0 30"/>
    <motor name="m1" joint="f1" gear="-1" ctrllimited="true" ctrlrange="0 30"/>
    <position name="lift" joint="lift" kp="20000" kv="300"/>
  </actuator>
</mujoco>
"""
    return mujoco.MjModel.from_xml_string(xml)


def _min_jerk(t: float, t0: float, T: float) -> float:
    u = min(max((t - t0) / T, 0.0), 1.0)
    return u**3 * (10.0 - 15.0 * u + 6.0 * u * u)


def _pad_wrenches(m, d, ids) -> np.ndarray:
    """Per pad: (f_n, f_y, f_z, tau) of the wrench the block exerts on the pad, in the pad's
    sensor frame (normal = from the pad toward the block, tau about it) [N, N m]."""
    out = np.zeros((2, 4))
    f6 = np.zeros(6)
    for i in range(d.ncon):
        c = d.contact[i]
        for k, pad in enumerate(ids["pads"]):
            if {c.geom1, c.geom2} != {pad, ids["box"]}:
                continue
            mujoco.mj_contactForce(m, d, i, f6)
            frame = np.asarray(c.frame).reshape(3, 3)  # rows: normal (geom1 -> geom2), tangents
            f_on_2 = frame.T @ f6[:3]  # force geom1 exerts on geom2, world coordinates
            t_on_2 = f6[3] * frame[0]  # its torsional moment about the normal
            # what the pad's sensor reads: the block's action on the pad
            f_pad, t_pad = (f_on_2, t_on_2) if c.geom2 == pad else (-f_on_2, -t_on_2)
            inward = np.array([1.0, 0.0, 0.0]) if k == 0 else np.array([-1.0, 0.0, 0.0])
            out[k, 0] += -float(f_pad @ inward)
            out[k, 1] += float(f_pad[1])
            out[k, 2] += float(f_pad[2])
            out[k, 3] += float(t_pad @ inward)
    return out


def run(s: GraspSetup) -> dict[str, np.ndarray]:
    """Simulate the grasp; returns per-sensor-sample (500 Hz) arrays."""
    m = build_model(s)
    d = mujoco.MjData(m)
    ids = {
        "pads": [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, f"pad{k}") for k in (0, 1)],
        "box": mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "box"),
        "block": mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "block"),
    }
    jy, jz, jth, jlift = (m.joint(j).qposadr[0] for j in ("by", "bz", "btheta", "lift"))
    est = _contact_params(s).replace(sigma_z=s.estimator_sigma_z)
    observers = [Observer(est, torque_noise=s.torque_noise, dt=0.002) for _ in range(2)]
    ctrl = GraspController(est)
    ctrl.reset(current_force=s.f_init)
    rng = np.random.default_rng(s.seed)
    h = m.opt.timestep
    decay = math.exp(-h / s.actuator_tau)
    f_act, command = s.f_init, s.f_init
    n_steps = round(s.duration / h)
    ratio = s.sensor_ratio
    keys = (
        "t",
        "command",
        "f_act",
        "S",
        "c_tilde",
        "omega_hat",
        "f_n",
        "f_y",
        "f_z",
        "f_t",
        "tau",
        "slip_y",
        "slip_z",
        "theta",
        "status",
    )
    log: dict[str, list] = {k: [] for k in keys}
    acc = np.zeros((2, 4))
    for n in range(n_steps):
        t = n * h
        # pushes on the block (half-sine)
        d.xfrc_applied[ids["block"]] = 0.0
        for t0, dur, force, torque in s.pushes:
            if t0 <= t < t0 + dur:
                a = math.sin(math.pi * (t - t0) / dur)
                d.xfrc_applied[ids["block"], :3] = a * np.asarray(force, dtype=float)
                d.xfrc_applied[ids["block"], 3] = a * torque
        f_act = command + (f_act - command) * decay
        d.ctrl[0] = d.ctrl[1] = f_act
        d.ctrl[2] = s.lift_height * _min_jerk(t, s.lift_start, s.lift_duration)
        mujoco.mj_step(m, d)
        acc += _pad_wrenches(m, d, ids)
        if (n + 1) % ratio:
            continue
        w = acc / ratio  # the sensor's average over its sample period (anti-alias)
        acc[:] = 0.0
        w = w + rng.normal(0.0, 1.0, (2, 4)) * np.array([s.force_noise] * 3 + [s.torque_noise])
        samples = [
            observers[k].step(w[k, 0], math.hypot(w[k, 1], w[k, 2]), w[k, 3]) for k in (0, 1)
        ]
        if s.controller == "lugrip":
            out = ctrl.step(
                omega_hat=[o.omega_hat for o in samples],
                S=[o.S for o in samples],
                c_tilde=[o.c_tilde for o in samples],
                f_t=[math.hypot(w[k, 1], w[k, 2]) for k in (0, 1)],
                status=[o.status for o in samples],
                omega_resolution=[o.omega_resolution for o in samples],
            )
            command = out.force
        else:
            command = s.constant_force
        log["t"].append(d.time)
        log["command"].append(command)
        log["f_act"].append(f_act)
        log["S"].append([o.S for o in samples])
        log["c_tilde"].append([o.c_tilde for o in samples])
        log["omega_hat"].append([o.omega_hat for o in samples])
        log["f_n"].append(w[:, 0].copy())
        log["f_y"].append(w[:, 1].copy())
        log["f_z"].append(w[:, 2].copy())
        log["f_t"].append(np.hypot(w[:, 1], w[:, 2]))
        log["tau"].append(w[:, 3].copy())
        log["slip_y"].append(d.qpos[jy])
        log["slip_z"].append(d.qpos[jz] - d.qpos[jlift])  # the block's height above the hand's
        log["theta"].append(d.qpos[jth])
        log["status"].append([int(o.status) for o in samples])
    return {k: np.asarray(v) for k, v in log.items()}


def evaluate(s: GraspSetup, r: dict[str, np.ndarray]) -> dict:
    """Metrics of a run and the pass flag of every criterion (held from the lift start)."""
    t = r["t"]
    hold = t >= s.lift_start
    i0 = int(np.argmax(hold))
    # the block's displacement relative to the hand from the lift start; its grasp point moves
    # by the translation plus the rotation about the CoG, d x theta
    dy = r["slip_y"] - r["slip_y"][i0]
    dz = r["slip_z"] - r["slip_z"][i0]
    dth = r["theta"] - r["theta"][i0]
    gy = dy - s.cog_offset * (np.cos(dth) - 1.0)
    gz = dz - s.cog_offset * np.sin(dth)
    slip = np.hypot(gy, gz)[hold]
    rot = np.abs(dth)[hold]
    lift_end = s.lift_start + s.lift_duration
    first_push = min((p[0] for p in s.pushes), default=s.duration)
    steady = (t >= lift_end + 1.0) & (t < first_push)
    S = np.max(r["S"], axis=1)
    limits = lugrip.controller_settings()  # the GraspController's defaults, used by run()
    f_min, f_max = limits["f_min"], limits["f_max"]
    finite = all(np.all(np.isfinite(v)) for v in r.values())
    dropped = bool(
        np.max(slip) > 0.02
        or np.max(rot) > math.radians(30.0)
        or np.min(r["f_n"][hold].mean(axis=1)) < 0.02
    )
    metrics = {
        "hold_slip_mm": 1e3 * float(np.max(slip)),
        "hold_rotation_deg": math.degrees(float(np.max(rot))),
        "dropped": dropped,
        "steady_force": float(np.mean(r["command"][steady])) if steady.any() else float("nan"),
        "peak_force": float(np.max(r["command"][hold])),
        "steady_slippage": float(np.mean(S[steady])) if steady.any() else float("nan"),
        "steady_c_tilde": float(np.mean(np.abs(r["c_tilde"][steady])))
        if steady.any()
        else float("nan"),
        "steady_f_t": float(np.mean(r["f_t"][steady])) if steady.any() else float("nan"),
        "steady_tau": float(np.mean(np.abs(r["tau"][steady]))) if steady.any() else float("nan"),
        "steady_f_t_per_finger": [float(x) for x in np.mean(r["f_t"][steady], axis=0)],
        "steady_tau_per_finger": [float(x) for x in np.mean(np.abs(r["tau"][steady]), axis=0)],
        "finite": finite,
        "command_in_limits": bool(np.all((r["command"] >= f_min) & (r["command"] <= f_max))),
    }
    if steady.any():
        # the force each model asks for at the steady loads of the more loaded finger (the
        # controller regulates S = max_i S_i): lugrip's at its set point S = 0.8, and the force
        # at which MuJoCo's elliptic cone would let that finger slip
        p = _contact_params(s)
        ft = np.asarray(metrics["steady_f_t_per_finger"])
        tq = np.asarray(metrics["steady_tau_per_finger"])
        metrics["static_force_lugrip_model"] = float(
            np.max(lugrip.static_grasp_force(p, ft, tq, s_ref=0.8))
        )
        metrics["slip_force_lugrip_model"] = float(
            np.max(lugrip.static_grasp_force(p, ft, tq, s_ref=1.0))
        )
        metrics["slip_force_mujoco_cone"] = float(
            np.max(np.hypot(ft / p.mu, tq / spin_coefficient(s)))
        )
    criteria = {
        "no_drop": not dropped,
        "finite": finite,
        "command_in_limits": metrics["command_in_limits"],
        "max_hold_slip_mm <= 1": metrics["hold_slip_mm"] <= 1.0,
        "max_hold_rotation_deg <= 1": metrics["hold_rotation_deg"] <= 1.0,
    }
    return {"metrics": metrics, "criteria": criteria, "pass": all(criteria.values())}


def plot(s: GraspSetup, r: dict[str, np.ndarray], path: Path, baseline=None) -> None:
    """The run's figure; `baseline` = (label, run) of a comparison, drawn in the rotation panel."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = r["t"]
    fig, ax = plt.subplots(4, 1, figsize=(9, 9), sharex=True, constrained_layout=True)
    ax[0].plot(t, r["f_act"], label="grasp force $f_n$ (gripper)")
    ax[0].plot(t, r["command"], "k--", lw=0.8, label="command")
    ax[0].plot(t, r["f_t"][:, 0], label="$f_t$ finger 0")
    ax[0].set_ylabel("force [N]")
    tw = ax[0].twinx()
    tw.plot(t, 1e3 * np.abs(r["tau"][:, 0]), color="tab:pink", lw=0.8, label=r"$|\tau|$ finger 0")
    tw.set_ylabel(r"$|\tau|$ [N mm]", color="tab:pink")
    ax[0].legend(loc="upper right", fontsize=8)
    ax[1].plot(t, np.max(r["S"], axis=1), label="S = max(S$_0$, S$_1$)")
    ax[1].plot(t, np.abs(r["c_tilde"][:, 0]), label=r"$|\tilde c|$ finger 0")
    ax[1].axhline(0.8, color="k", lw=0.6, ls=":")
    ax[1].set_ylabel("S, $|\\tilde c|$ [-]")
    ax[1].set_ylim(0, 1.6)
    ax[1].legend(loc="upper right", fontsize=8)
    ax[2].plot(t, r["omega_hat"][:, 0], lw=0.8, label=r"$\hat\omega$ finger 0")
    ax[2].set_ylabel(r"$\hat\omega$ [rad/s]")
    ax[2].legend(loc="upper right", fontsize=8)
    ax[3].plot(t, np.degrees(r["theta"] - r["theta"][0]), label="lugrip: rotation [deg]")
    if baseline is not None:
        label, rb = baseline
        ax[3].plot(
            rb["t"], np.degrees(rb["theta"] - rb["theta"][0]), label=f"{label}: rotation [deg]"
        )
    ax[3].set_ylabel("block rotation [deg]")
    ax[3].set_xlabel("time $t$ [s]")
    ax[3].legend(loc="upper left", fontsize=8)
    for a in ax:
        a.axvspan(s.lift_start, s.lift_start + s.lift_duration, color="0.92", zorder=0)
        for t0, dur, *_ in s.pushes:
            a.axvspan(t0, t0 + dur, color="tab:orange", alpha=0.2, zorder=0)
        a.grid(alpha=0.3)
    fig.suptitle("lugrip on MuJoCo (elliptic cone, condim 4): block lifted off its CoG and pushed")
    fig.savefig(path, dpi=110)
    plt.close(fig)


#: MuJoCo settings compared by --settings-sweep: the validation's, and MuJoCo's defaults step by step
SETTINGS_SWEEP = (
    ("elliptic cone, noslip 10, impratio 10 (this validation)", {}),
    ("elliptic cone, noslip 5, impratio 10", {"noslip_iterations": 5}),
    ("elliptic cone, noslip 0, impratio 10", {"noslip_iterations": 0}),
    ("elliptic cone, noslip 0, impratio 1", {"noslip_iterations": 0, "impratio": 1.0}),
    (
        "pyramidal cone, noslip 0, impratio 1 (MuJoCo's defaults)",
        {"noslip_iterations": 0, "impratio": 1.0, "cone": "pyramidal"},
    ),
)


def settings_sweep(duration: float, seed: int) -> str:
    """Markdown table: lugrip's grasp under each MuJoCo setting of SETTINGS_SWEEP."""
    header = (
        "| MuJoCo contact settings | pass | hold slip [mm] | hold rotation [deg] | steady force [N] "
        "| steady S |"
    )
    rows = [header, "|---|---|---|---|---|---|"]
    for label, kw in SETTINGS_SWEEP:
        s = GraspSetup(duration=duration, seed=seed, **kw)
        e = evaluate(s, run(s))
        m = e["metrics"]
        rows.append(
            f"| {label} | {'yes' if e['pass'] else 'no'} | {m['hold_slip_mm']:.3f} | "
            f"{m['hold_rotation_deg']:.3f} | {m['steady_force']:.2f} | {m['steady_slippage']:.3f} |"
        )
    return "\n".join(rows)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=Path("out"))
    ap.add_argument("--duration", type=float, default=GraspSetup.duration)
    ap.add_argument(
        "--constant-force",
        type=float,
        default=None,
        help="baseline: hold this constant force [N] (default: half lugrip's steady force)",
    )
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument(
        "--settings-sweep",
        action="store_true",
        help="print a Markdown table of the grasp under MuJoCo's default contact settings too",
    )
    args = ap.parse_args(argv)
    if args.settings_sweep:
        print(settings_sweep(args.duration, args.seed))
        return 0
    args.out.mkdir(parents=True, exist_ok=True)
    s = GraspSetup(duration=args.duration, seed=args.seed)
    r = run(s)
    res = evaluate(s, r)
    f_const = args.constant_force
    if f_const is None:
        f_const = 0.5 * res["metrics"]["steady_force"]
    b = GraspSetup(
        duration=args.duration, seed=args.seed, controller="constant", constant_force=f_const
    )
    rb = run(b)
    res_b = evaluate(b, rb)
    doc = {
        "setup": {k: v for k, v in asdict(s).items()},
        "mujoco": mujoco.__version__,
        "spin_coefficient_m": spin_coefficient(s),
        "lugrip": res,
        "constant_force": dict(res_b, force=f_const),
    }
    (args.out / "mujoco_grasp.json").write_text(json.dumps(doc, indent=2))
    plot(s, r, args.out / "mujoco_grasp.png", baseline=(f"constant {f_const:.2f} N", rb))
    m = res["metrics"]
    print(
        f"lugrip on MuJoCo {mujoco.__version__}: {'pass' if res['pass'] else 'FAIL'}; "
        f"hold slip {m['hold_slip_mm']:.3f} mm, rotation {m['hold_rotation_deg']:.3f} deg, "
        f"steady force {m['steady_force']:.2f} N at S {m['steady_slippage']:.3f} (lugrip's model at "
        f"S = 0.8: {m.get('static_force_lugrip_model', float('nan')):.2f} N; slips below "
        f"{m.get('slip_force_lugrip_model', float('nan')):.2f} N in lugrip's model, below "
        f"{m.get('slip_force_mujoco_cone', float('nan')):.2f} N in MuJoCo's cone)"
    )
    mb = res_b["metrics"]
    print(
        f"constant {f_const:.2f} N: hold slip {mb['hold_slip_mm']:.3f} mm, rotation "
        f"{mb['hold_rotation_deg']:.3f} deg, dropped {mb['dropped']}"
    )
    for name, ok in res["criteria"].items():
        if not ok:
            print(f"  failed: {name}", file=sys.stderr)
    return 0 if res["pass"] else 1


if __name__ == "__main__":
    sys.exit(main())

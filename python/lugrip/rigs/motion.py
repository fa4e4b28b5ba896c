"""Prescribed-motion rubbing: the maneuvers a robot runs to collect sliding data.

The finger (with the fingertip sensor) is pressed onto a fixed slider and then moved in the
pad plane as a rigid body about a centre of rotation (CoR) that is fixed in the finger frame
for the whole maneuver. Every maneuver is

1. **approach**: the normal force rises to its nominal value, no tangential motion;
2. **motion**: the angular velocity of the pad ramps smoothly from 0 to its peak (the
   wrench builds up through presliding), holds, optionally reverses once or twice
   (back-and-forth rubs, passing through presliding again), and ramps back to 0;
3. **loaded rest**: the pad stands still, still pressed; the friction stays loaded.

A maneuver is described by :class:`ManeuverPlan`; :func:`plan_maneuvers` draws ``n`` of them
from the ranges of a :class:`RubbingDesign`, reproducibly from the seed. A plan is a
function of time (``omega_pad_at``, ``f_n_at``) so that a plant can integrate on a finer
step than the sample period. The sensor's noise and offsets belong to the plan too
(:meth:`ManeuverPlan.sensor`), so that every plant driven by the same plans reads through the
same sensor.

Sign convention of the motion: ``omega_pad`` is the pad's angular velocity relative to the
slider (counter-clockwise about the sensor z positive); the slider's angular velocity
relative to the fingertip, the ``omega`` column of a sliding log, is ``-omega_pad``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np

__all__ = ["ManeuverPlan", "RubbingDesign", "plan_maneuvers", "stack_times"]

RadiusLaw = Callable[[float], float]


@dataclasses.dataclass(frozen=True)
class RubbingDesign:
    """Ranges of a prescribed-motion rubbing campaign (SI units).

    Attributes:
        c_tilde_range: |CoR distance from the patch centre| / true contact radius, drawn
            log-uniform (rotation-dominated to translation-dominated) [-].
        omega_range: peak |omega| of the pad in pure rotation, drawn log-uniform [rad/s].
        equal_patch_speed: when True (default) the peak |omega| of a maneuver about a CoR
            at c~ is the drawn value divided by sqrt(1 + 2 c~^2), so that the RMS sliding
            speed over the patch, omega rho sqrt(c~^2 + 1/2), does not depend on the CoR
            (a robot rubbing at similar speeds in every direction; translation-dominated
            rubs turn slowly); when False the drawn value is used for every CoR.
        edge_speed_range: when given, the peak sliding speed at the patch edge,
            |omega| rho (c~ + 1), drawn log-uniform [m/s]; it replaces omega_range and
            equal_patch_speed (None: omega_range as described above).
        hold_slip: with edge_speed_range, each constant-speed leg lasts at least this slip
            distance at the patch edge [m] (slow rubs reach gross sliding); 0: no minimum.
        v_max: cap on the patch-centre speed |omega| |c| at the peak [m/s]; the peak
            |omega| of a maneuver is lowered to respect it.
        f_n_range: nominal normal force, drawn uniform (stratified) [N].
        approach: duration of the approach (force rising, no motion) [s].
        f_n_start: normal force at t = 0 as a fraction of the nominal one [-].
        accel_range: duration of each smooth speed ramp (0 to peak, peak to 0, and half of
            a reversal), drawn log-uniform [s].
        hold_range: duration of each constant-speed leg, drawn uniform [s].
        reverse_fraction: fraction of maneuvers whose motion reverses [-].
        max_reversals: a reversing maneuver reverses 1 .. max_reversals times [-].
        rest_range: duration of the loaded rest after the motion, drawn uniform [s].
        sample_rate: sensor sample rate [Hz].
        noise_force: white noise std on f_n, f_x, f_y [N].
        noise_torque: white noise std on tau [N m].
        offset_force: std of the constant force offsets drawn per maneuver and axis [N].
        offset_torque: std of the constant torque offset drawn per maneuver [N m].
        ripple: relative amplitude of a sinusoidal normal-force ripple [-].
        ripple_freq_range: frequency of that ripple, drawn uniform [Hz].
        nominal_radius: (delta [m/N^gamma], gamma [-]) used to turn c~ into metres when the
            caller gives no radius law of its own (plants always give theirs).
    """

    c_tilde_range: tuple[float, float] = (0.05, 20.0)
    omega_range: tuple[float, float] = (0.2, 2.0)
    equal_patch_speed: bool = True
    edge_speed_range: tuple[float, float] | None = None
    hold_slip: float = 0.0
    v_max: float = 0.1
    f_n_range: tuple[float, float] = (1.0, 10.0)
    approach: float = 0.1
    f_n_start: float = 0.3
    accel_range: tuple[float, float] = (0.03, 0.3)
    hold_range: tuple[float, float] = (0.2, 0.5)
    reverse_fraction: float = 0.3
    max_reversals: int = 2
    rest_range: tuple[float, float] = (0.2, 0.4)
    sample_rate: float = 500.0
    noise_force: float = 0.01
    noise_torque: float = 2.0e-5
    offset_force: float = 0.01
    offset_torque: float = 2.0e-5
    ripple: float = 0.01
    ripple_freq_range: tuple[float, float] = (1.0, 4.0)
    nominal_radius: tuple[float, float] = (3.0e-3, 0.22)

    def __post_init__(self):
        for name in ("c_tilde_range", "omega_range", "f_n_range", "accel_range",
                     "hold_range", "rest_range", "ripple_freq_range", "nominal_radius",
                     "edge_speed_range"):
            if name == "edge_speed_range" and self.edge_speed_range is None:
                continue
            pair = tuple(float(v) for v in getattr(self, name))
            if len(pair) != 2 or not all(math.isfinite(v) and v > 0.0 for v in pair):
                raise ValueError(f"RubbingDesign.{name} = {getattr(self, name)!r}: "
                                 "two finite numbers > 0 expected")
            if name != "nominal_radius" and pair[0] > pair[1]:
                raise ValueError(f"RubbingDesign.{name} = {pair!r}: low > high")
            object.__setattr__(self, name, pair)
        for name in ("v_max", "approach", "sample_rate"):
            v = float(getattr(self, name))
            if not (math.isfinite(v) and v > 0.0):
                raise ValueError(f"RubbingDesign.{name} = {v!r}: must be finite and > 0")
            object.__setattr__(self, name, v)
        for name in ("noise_force", "noise_torque", "offset_force", "offset_torque", "ripple",
                     "hold_slip"):
            v = float(getattr(self, name))
            if not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f"RubbingDesign.{name} = {v!r}: must be finite and >= 0")
            object.__setattr__(self, name, v)
        object.__setattr__(self, "equal_patch_speed", bool(self.equal_patch_speed))
        if not 0.0 < self.f_n_start <= 1.0:
            raise ValueError(f"RubbingDesign.f_n_start = {self.f_n_start!r}: must be in (0, 1]")
        if not 0.0 <= self.reverse_fraction <= 1.0:
            raise ValueError("RubbingDesign.reverse_fraction must be in [0, 1]")
        if int(self.max_reversals) < 1:
            raise ValueError("RubbingDesign.max_reversals must be >= 1")
        object.__setattr__(self, "max_reversals", int(self.max_reversals))
        if self.ripple >= 0.5:
            raise ValueError("RubbingDesign.ripple must be < 0.5 (the force must stay > 0)")

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


def _smooth(x: np.ndarray) -> np.ndarray:
    """Raised-cosine ramp from 0 (x <= 0) to 1 (x >= 1), continuous first derivative."""
    x = np.clip(x, 0.0, 1.0)
    return 0.5 - 0.5 * np.cos(np.pi * x)


@dataclasses.dataclass(frozen=True)
class ManeuverPlan:
    """One prescribed-motion maneuver, in its own time (t = 0 at its start).

    Attributes:
        index: maneuver id.
        t: sample times [s] at the design's sample rate, from 0.
        knots_t, knots_omega: the pad's angular-velocity profile: raised-cosine transitions
            between consecutive knots (times [s], values [rad/s]).
        cor: CoR position in the finger (sensor) frame [m], fixed during the maneuver.
        c_tilde: |cor| / rho(f_n_nominal) [-].
        rho_nominal: true contact radius at the nominal normal force [m].
        f_n_nominal: nominal normal force [N].
        approach: duration of the approach [s] (motion starts at this time).
        motion_end: time at which the motion has stopped for good [s].
        f_n_start: normal force at t = 0 as a fraction of the nominal one [-].
        ripple, ripple_freq, ripple_phase: relative amplitude [-], frequency [Hz] and phase
            [rad] of the normal-force ripple.
        reversals: number of reversals of the motion.
        offset: constant sensor offsets (f_n, f_x, f_y [N], tau [N m]).
        noise: white-noise std (force [N], torque [N m]).
        noise_seed: seed of this maneuver's sensor noise.
    """

    index: int
    t: np.ndarray
    knots_t: np.ndarray
    knots_omega: np.ndarray
    cor: np.ndarray
    c_tilde: float
    rho_nominal: float
    f_n_nominal: float
    approach: float
    motion_end: float
    f_n_start: float
    ripple: float
    ripple_freq: float
    ripple_phase: float
    reversals: int
    offset: np.ndarray
    noise: tuple[float, float]
    noise_seed: int

    def __len__(self) -> int:
        return len(self.t)

    @property
    def duration(self) -> float:
        return float(self.t[-1])

    def omega_pad_at(self, t) -> np.ndarray:
        """Angular velocity of the pad relative to the slider at times ``t`` [rad/s]."""
        t = np.asarray(t, dtype=float)
        kt, kw = self.knots_t, self.knots_omega
        j = np.clip(np.searchsorted(kt, t, side="right") - 1, 0, len(kt) - 2)
        span = kt[j + 1] - kt[j]
        x = (t - kt[j]) / span
        out = kw[j] + (kw[j + 1] - kw[j]) * _smooth(x)
        return np.where(t >= kt[-1], kw[-1], np.where(t <= kt[0], kw[0], out))

    @property
    def omega_pad(self) -> np.ndarray:
        """Pad angular velocity at the sample times [rad/s]."""
        return self.omega_pad_at(self.t)

    @property
    def omega(self) -> np.ndarray:
        """Slider angular velocity relative to the fingertip about the sensor z [rad/s]
        (the sliding log's ``omega``): ``-omega_pad``."""
        return -self.omega_pad

    def f_n_at(self, t) -> np.ndarray:
        """True normal force at times ``t`` [N]."""
        t = np.asarray(t, dtype=float)
        rise = self.f_n_start + (1.0 - self.f_n_start) * _smooth(t / (0.6 * self.approach))
        wave = 1.0 + self.ripple * np.sin(2.0 * np.pi * self.ripple_freq * t + self.ripple_phase)
        return self.f_n_nominal * rise * wave

    @property
    def f_n(self) -> np.ndarray:
        """True normal force at the sample times [N]."""
        return self.f_n_at(self.t)

    @property
    def moving(self) -> np.ndarray:
        """Mask of samples between the motion start and its end."""
        return (self.t > self.approach) & (self.t < self.motion_end)

    def c_tilde_signed(self, rho) -> np.ndarray:
        """Prescribed CoR over the true contact radius ``rho`` (per sample [m]), signed as in
        the sensor frame (y along the in-plane force on the fingertip, x = y cross z), where
        sign(c~) = -sign(omega): while the slider turns, the sign of its omega; before the
        motion the sign of the first leg, after it that of the last leg."""
        w = self.omega
        s = np.sign(w)
        nz = np.flatnonzero(s)
        if len(nz) == 0:
            s = np.ones_like(w)
        else:
            idx = np.maximum.accumulate(np.where(s != 0, np.arange(len(s)), -1))
            s = np.where(idx >= 0, s[np.maximum(idx, 0)], s[nz[0]])
        return -s * float(np.hypot(*self.cor)) / np.asarray(rho, dtype=float)

    def commanded_phase(self) -> np.ndarray:
        """0 before the motion starts, 1 while it is under way, 3 after it has stopped
        (plants refine 1 into presliding/sliding from their own state)."""
        ph = np.ones(len(self.t), dtype=np.int8)
        ph[self.t <= self.approach] = 0
        ph[self.t >= self.motion_end] = 3
        return ph

    def sensor(self, f_n, f_x, f_y, tau) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Sensor readings of the true wrench at the sample times: the true values plus this
        maneuver's constant offsets and white noise (same draws for every plant)."""
        rng = np.random.default_rng(self.noise_seed)
        n = len(self.t)
        sf, st = self.noise
        noise = rng.standard_normal((4, n))
        return (np.asarray(f_n, float) + self.offset[0] + sf * noise[0],
                np.asarray(f_x, float) + self.offset[1] + sf * noise[1],
                np.asarray(f_y, float) + self.offset[2] + sf * noise[2],
                np.asarray(tau, float) + self.offset[3] + st * noise[3])

    def to_dict(self) -> dict:
        d = {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name != "t"}
        d["n_samples"] = len(self.t)
        return {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in d.items()}


def _stratified(rng: np.random.Generator, n: int) -> np.ndarray:
    """n numbers in [0, 1), one in each of n equal bins, in random order."""
    return (rng.permutation(n) + rng.random(n)) / n


def _radius_law(design: RubbingDesign, radius) -> RadiusLaw:
    if radius is None:
        delta, gamma = design.nominal_radius
        return lambda f: delta * f ** gamma
    if callable(radius):
        return radius
    delta, gamma = (float(v) for v in radius)
    return lambda f: delta * f ** gamma


def plan_maneuvers(design: RubbingDesign, n: int, seed: int = 0, *,
                   radius: RadiusLaw | tuple[float, float] | None = None) -> list[ManeuverPlan]:
    """Draw ``n`` maneuvers from ``design``, reproducibly from ``seed``.

    ``radius`` is the plant's true contact-radius law (a callable f_n -> rho [m], or a
    (delta, gamma) pair) that turns c~ into a CoR position in metres and sets the speed cap;
    without it the design's ``nominal_radius`` is used. c~, f_n and the peak |omega| are
    stratified so that even a handful of maneuvers spans their ranges.
    """
    n = int(n)
    if n < 1:
        raise ValueError(f"plan_maneuvers: n = {n}: at least one maneuver")
    if not isinstance(design, RubbingDesign):
        raise TypeError("plan_maneuvers: design must be a RubbingDesign")
    rho_of = _radius_law(design, radius)
    rng = np.random.default_rng(seed)
    lo, hi = np.log(design.c_tilde_range)
    c_tilde = np.exp(lo + (hi - lo) * _stratified(rng, n))
    f_lo, f_hi = design.f_n_range
    f_nom = f_lo + (f_hi - f_lo) * _stratified(rng, n)
    w_lo, w_hi = np.log(design.omega_range if design.edge_speed_range is None
                        else design.edge_speed_range)
    w_peak = np.exp(w_lo + (w_hi - w_lo) * _stratified(rng, n))
    phi = rng.uniform(0.0, 2.0 * np.pi, n)
    sign = rng.choice((-1.0, 1.0), n)
    a_lo, a_hi = np.log(design.accel_range)
    reverse = rng.random(n) < design.reverse_fraction
    n_rev = np.where(reverse, rng.integers(1, design.max_reversals + 1, n), 0)
    seeds = rng.integers(0, 2**63 - 1, n)
    dt = 1.0 / design.sample_rate
    plans = []
    for i in range(n):
        r = np.random.default_rng(int(seeds[i]))
        rho = float(rho_of(float(f_nom[i])))
        if not (math.isfinite(rho) and rho > 0.0):
            raise ValueError(f"plan_maneuvers: radius law gave rho = {rho!r} at f_n = "
                             f"{f_nom[i]:.3g} N")
        c = float(c_tilde[i]) * rho
        peak = float(w_peak[i])
        if design.edge_speed_range is not None:  # drawn as the speed at the patch edge
            peak /= rho * (float(c_tilde[i]) + 1.0)
        elif design.equal_patch_speed:
            peak /= math.sqrt(1.0 + 2.0 * float(c_tilde[i]) ** 2)
        peak = min(peak, design.v_max / c)
        accel = float(np.exp(r.uniform(a_lo, a_hi)))
        legs = int(n_rev[i]) + 1
        holds = r.uniform(*design.hold_range, legs)
        if design.edge_speed_range is not None and design.hold_slip > 0.0:
            holds = np.maximum(holds, design.hold_slip / float(w_peak[i]))
        rest = float(r.uniform(*design.rest_range))
        kt = [0.0, design.approach]
        kw = [0.0, 0.0]
        w = sign[i] * peak
        t_now = design.approach + accel
        kt.append(t_now)
        kw.append(w)
        for leg in range(legs):
            t_now += holds[leg]
            kt.append(t_now)
            kw.append(w)
            if leg < legs - 1:  # reverse through zero: two ramps back to back
                t_now += 2.0 * accel
                w = -w
                kt.append(t_now)
                kw.append(w)
        t_now += accel
        kt.append(t_now)
        kw.append(0.0)
        motion_end = t_now
        total = motion_end + rest
        t = np.arange(math.floor(total / dt) + 1) * dt
        cor = c * np.array([math.cos(phi[i]), math.sin(phi[i])])
        offset = np.array([r.normal(0.0, design.offset_force),
                           r.normal(0.0, design.offset_force),
                           r.normal(0.0, design.offset_force),
                           r.normal(0.0, design.offset_torque)])
        for a in (t, cor, offset):
            a.setflags(write=False)
        knots_t = np.array(kt)
        knots_w = np.array(kw)
        knots_t.setflags(write=False)
        knots_w.setflags(write=False)
        plans.append(ManeuverPlan(
            index=i, t=t, knots_t=knots_t, knots_omega=knots_w, cor=cor,
            c_tilde=float(c_tilde[i]), rho_nominal=rho, f_n_nominal=float(f_nom[i]),
            approach=design.approach, motion_end=motion_end, f_n_start=design.f_n_start,
            ripple=design.ripple, ripple_freq=float(r.uniform(*design.ripple_freq_range)),
            ripple_phase=float(r.uniform(0.0, 2.0 * np.pi)), reversals=int(n_rev[i]),
            offset=offset, noise=(design.noise_force, design.noise_torque),
            noise_seed=int(r.integers(0, 2**63 - 1))))
    return plans


def stack_times(plans: list[ManeuverPlan], dt: float) -> np.ndarray:
    """Start time of each maneuver in one log (maneuvers back to back, one sample period
    apart), so that the log's time is strictly increasing."""
    starts = np.zeros(len(plans))
    for i in range(1, len(plans)):
        starts[i] = starts[i - 1] + plans[i - 1].t[-1] + dt
    return starts

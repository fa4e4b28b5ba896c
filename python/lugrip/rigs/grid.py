"""A distributed planar LuGre contact: a grid of cells, each with its own bristle.

The plant is written from contact mechanics, not from lugrip's limit-surface or observer
equations (docs/rigs.md):

* the contact is a disc of radius ``rho = delta f_n**gamma`` fixed in the fingertip, covered
  by an ``n_grid x n_grid`` grid of equal square cells (the cells whose centre lies inside
  the disc);
* Hertzian pressure ``p(r) ~ sqrt(1 - r^2/rho^2)`` (or, with ``pressure="uniform"``, a
  constant pressure), scaled so that the cells carry exactly the normal force:
  ``p_i A_i = f_n w_i`` with ``sum w_i = 1``;
* each cell has a 2-D bristle ``z_i`` [m] with LuGre dynamics driven by the slider's
  velocity relative to the pad at the cell, ``v_i``::

      dz_i/dt = v_i - sigma0 |v_i| z_i / s(|v_i|),
      s(v) = mu_k + (mu_s - mu_k) exp(-(v / v_s)^2)        (Stribeck)

* the cell's shear force on the fingertip is
  ``f_n w_i (sigma0 z_i + sigma1 dz_i/dt + sigma2 v_i) + beta_a A_i v_i``
  (the last term: an optional viscous shear uniform over the patch);
* the pad moves as a rigid body about the prescribed CoR ``c`` (fixed in the finger frame):
  relative to the pad, the slider's material point at ``r`` moves with
  ``omega (-(r - c)_y, (r - c)_x)``, ``omega = -omega_pad``;
* the sensor reads the sum of the cell forces and their moment about the patch centre.

The bristles are stiff, so every internal step uses the exact solution of the bristle
equation for the velocity frozen at the step's midpoint; the cell positions are held over
each sample interval (radius at the interval's mean force). All maneuvers of a batch and all
cells are integrated together as (maneuvers x cells) numpy arrays; the sums over cells are
matrix-vector products, and the uniform viscous shear, linear in position, is summed over
the cells in closed form.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Sequence

import numpy as np

from ._data import RigTruth, RubbingData
from ._run import RigRun, assemble
from .motion import ManeuverPlan, RubbingDesign, plan_maneuvers

__all__ = ["GridContactRig"]

_SLIDING_LOAD = 0.95  # gross sliding: this fraction of f_n carried by sliding cells [-]
_STEADY = 0.9  # a cell slides when its bristle is at >= this fraction of its sliding value [-]
_BATCH = 48  # maneuvers integrated together (sorted by length, so little padding)


@dataclasses.dataclass(frozen=True)
class GridContactRig:
    """A grid-of-cells LuGre contact rubbed by prescribed motion.

    Attributes:
        name: plant name.
        n_grid: cells per side of the square grid over the contact disc [-].
        delta: contact radius law coefficient, rho = delta f_n**gamma [m/N^gamma].
        gamma: contact radius law exponent [-].
        mu_s: static friction coefficient (Stribeck curve at zero speed) [-].
        mu_k: kinetic friction coefficient (Stribeck curve at high speed) [-].
        v_s: Stribeck speed [m/s].
        sigma0: bristle stiffness per unit normal load [1/m].
        sigma1: bristle damping per unit normal load [s/m].
        sigma2: viscous friction per unit normal load [s/m].
        beta_a: viscous shear per unit area and unit speed, uniform over the patch [N s/m^3].
        substeps: internal integration steps per sensor sample [-].
        pressure: "hertz" (p ~ sqrt(1 - r^2/rho^2)) or "uniform" (p constant over the disc).
    """

    name: str = "grid-stribeck"
    n_grid: int = 31
    delta: float = 2.2e-3
    gamma: float = 0.22
    mu_s: float = 0.55
    mu_k: float = 0.45
    v_s: float = 5.0e-4
    sigma0: float = 5.0e4
    sigma1: float = 0.1
    sigma2: float = 0.0
    beta_a: float = 0.0
    substeps: int = 2
    pressure: str = "hertz"

    def __post_init__(self):
        if self.pressure not in ("hertz", "uniform"):
            raise ValueError(f"GridContactRig.pressure = {self.pressure!r}: 'hertz' or 'uniform'")
        if int(self.n_grid) < 3:
            raise ValueError("GridContactRig.n_grid must be >= 3")
        object.__setattr__(self, "n_grid", int(self.n_grid))
        if int(self.substeps) < 1:
            raise ValueError("GridContactRig.substeps must be >= 1")
        object.__setattr__(self, "substeps", int(self.substeps))
        for name in ("delta", "mu_s", "mu_k", "v_s", "sigma0"):
            v = float(getattr(self, name))
            if not (math.isfinite(v) and v > 0.0):
                raise ValueError(f"GridContactRig.{name} = {v!r}: must be finite and > 0")
            object.__setattr__(self, name, v)
        for name in ("sigma1", "sigma2", "beta_a"):
            v = float(getattr(self, name))
            if not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f"GridContactRig.{name} = {v!r}: must be finite and >= 0")
            object.__setattr__(self, name, v)
        if not 0.0 < float(self.gamma) < 1.0:
            raise ValueError("GridContactRig.gamma must be in (0, 1)")
        if self.mu_s < self.mu_k:
            raise ValueError("GridContactRig: mu_s must be >= mu_k")

    # -- presets ------------------------------------------------------------------------------

    @classmethod
    def stribeck(cls, **kw) -> GridContactRig:
        """Plant (i): Stribeck friction (mu_s 0.55, mu_k 0.45), Hertzian pressure, no
        viscous shear."""
        kw.setdefault("name", "grid-stribeck")
        return cls(**kw)

    @classmethod
    def viscous(cls, **kw) -> GridContactRig:
        """Plant (ii): plant (i) plus a viscous shear of 2e7 N s/m^3 uniform over the patch."""
        kw.setdefault("name", "grid-viscous")
        kw.setdefault("beta_a", 2.0e7)
        return cls(**kw)

    # -- geometry -----------------------------------------------------------------------------

    def rho(self, f_n):
        """Contact radius delta f_n**gamma [m]."""
        return self.delta * np.asarray(f_n, dtype=float) ** self.gamma

    def cells(self) -> tuple[np.ndarray, np.ndarray, float]:
        """Cell centres in unit-disc coordinates (C, 2), their load weights w_i (sum 1,
        Hertzian or uniform) and the cell area in units of rho^2."""
        n = self.n_grid
        h = 2.0 / n
        x = -1.0 + h * (np.arange(n) + 0.5)
        X, Y = np.meshgrid(x, x, indexing="ij")
        r2 = X * X + Y * Y
        inside = r2 < 1.0
        u = np.stack([X[inside], Y[inside]], axis=1)
        w = np.sqrt(1.0 - r2[inside]) if self.pressure == "hertz" else np.ones(int(inside.sum()))
        w = w / w.sum()
        return u, w, h * h

    def torsion_factor(self) -> float:
        """sum w_i |u_i| of the grid: tau_max = mu f_n rho times this (3 pi / 16 for the
        continuous Hertzian disc, 2/3 for the uniform one)."""
        u, w, _ = self.cells()
        return float(np.sum(w * np.hypot(u[:, 0], u[:, 1])))

    def truth(self) -> RigTruth:
        f = np.geomspace(0.25, 40.0, 9)
        tmax = self.mu_k * f * self.rho(f) * self.torsion_factor()
        viscous = self.beta_a > 0.0 or self.sigma2 > 0.0
        notes = (f"{self.n_grid}x{self.n_grid} grid of LuGre cells, Stribeck speed "
                 f"{self.v_s:g} m/s, sigma0 {self.sigma0:g} 1/m, sigma1 {self.sigma1:g} s/m, "
                 f"sigma2 {self.sigma2:g} s/m; tau_max from the grid at mu_k")
        return RigTruth(
            name=self.name, mu_static=self.mu_s, mu_kinetic=self.mu_k, mu=self.mu_k,
            beta_a=self.beta_a if self.beta_a > 0.0 else None, viscous=viscous,
            delta=self.delta, gamma=float(self.gamma), pressure="Hertzian (k = 2)" if self.pressure == "hertz" else "uniform (k = inf)",
            tau_max_points=tuple(zip(f.tolist(), tmax.tolist())), notes=notes)

    def settings(self) -> dict:
        return dataclasses.asdict(self)

    # -- simulation ---------------------------------------------------------------------------

    def run(self, plans: Sequence[ManeuverPlan], *, substeps: int | None = None,
            batch: int = _BATCH) -> list[RigRun]:
        """Integrate the plant along the plans (true wrench, no sensor); one
        :class:`~lugrip.rigs._run.RigRun` per plan, in the plans' order. ``substeps``
        overrides the rig's internal steps per sample; ``batch`` maneuvers (sorted by length)
        are integrated together."""
        plans = list(plans)
        if not plans:
            return []
        dts = {round(float(p.t[1] - p.t[0]), 12) for p in plans if len(p.t) > 1}
        if len(dts) > 1:
            raise ValueError("GridContactRig.run: all plans must share one sample period")
        S = int(self.substeps if substeps is None else substeps)
        order = sorted(range(len(plans)), key=lambda i: len(plans[i]))
        out: list[RigRun | None] = [None] * len(plans)
        batch = max(1, int(batch))
        for b in range(0, len(order), batch):
            idx = order[b:b + batch]
            for i, res in zip(idx, self._run_batch([plans[i] for i in idx], S)):
                out[i] = res
        return out  # type: ignore[return-value]

    def _run_batch(self, plans: list[ManeuverPlan], S: int) -> list[RigRun]:
        u, w, area = self.cells()
        ux, uy = u[:, 0][None, :], u[:, 1][None, :]
        wx, wy = w * u[:, 0], w * u[:, 1]  # load-weighted cell positions (unit disc)
        w_r2 = float(np.sum(u * u))  # sum |u_i|^2 (viscous moment)
        n_cells = u.shape[0]
        M = len(plans)
        L = max(len(p) for p in plans)
        dt = float(plans[0].t[1] - plans[0].t[0]) if L > 1 else 1.0
        h = dt / S
        # per-sample inputs, padded past each plan's end with rest at the last force
        fn_s = np.empty((M, L))
        w_s = np.zeros((M, L))
        for m, p in enumerate(plans):
            n = len(p)
            fn_s[m, :n] = p.f_n
            fn_s[m, n:] = fn_s[m, n - 1]
            w_s[m, :n] = -p.omega_pad
        # omega at the midpoints of every internal step (0 past each plan's end)
        t_mid = (np.arange((L - 1) * S) + 0.5) * h
        w_mid = np.zeros((M, len(t_mid)))
        for m, p in enumerate(plans):
            live = t_mid <= p.t[-1]
            w_mid[m, live] = -p.omega_pad_at(t_mid[live])
        cx = np.array([p.cor[0] for p in plans])[:, None]
        cy = np.array([p.cor[1] for p in plans])[:, None]
        rho_s = self.rho(fn_s)
        zx = np.zeros((M, n_cells))
        zy = np.zeros_like(zx)
        dmu = self.mu_s - self.mu_k
        inv_vs2 = 1.0 / self.v_s ** 2
        res = {k: np.zeros((M, L)) for k in ("fx", "fy", "tau", "tau_cor", "cap", "slide")}
        speed, s, x, tmp = (np.empty((M, n_cells)) for _ in range(4))

        def geometry(rho):
            """Cell offsets from the CoR, their distance and the unit direction in which the
            slider moves there for omega > 0."""
            dx, dy = rho * ux - cx, rho * uy - cy
            dn = np.hypot(dx, dy)
            safe = np.where(dn > 0.0, dn, 1.0)
            return dx, dy, dn, -dy / safe, dx / safe

        def stribeck(omega, dn):
            """|v| and s(|v|) of every cell into the buffers speed and s."""
            np.multiply(np.abs(omega), dn, out=speed)
            np.multiply(speed, speed, out=s)
            np.multiply(s, -inv_vs2, out=s)
            np.exp(s, out=s)
            np.multiply(s, dmu, out=s)
            np.add(s, self.mu_k, out=s)

        def sample(k, geo):
            fn, omega = fn_s[:, k], w_s[:, k][:, None]
            rho = rho_s[:, k]
            _, _, dn, ex, ey = geo
            stribeck(omega, dn)
            # bristle force per unit cell load: sigma0 z + sigma1 dz/dt + sigma2 v
            vx, vy = omega * dn * ex, omega * dn * ey
            cell_x = self.sigma0 * zx
            cell_y = self.sigma0 * zy
            if self.sigma1 > 0.0:
                a = self.sigma0 * speed / s
                cell_x += self.sigma1 * (vx - a * zx)
                cell_y += self.sigma1 * (vy - a * zy)
            if self.sigma2 > 0.0:
                cell_x += self.sigma2 * vx
                cell_y += self.sigma2 * vy
            fx = fn * (cell_x @ w)
            fy = fn * (cell_y @ w)
            tau = fn * rho * (cell_y @ wx - cell_x @ wy)
            if self.beta_a > 0.0:
                # uniform shear beta_A A v summed over the cells (the grid is symmetric, so
                # sum u_i = 0): force beta_A A n omega (c_y, -c_x), moment beta_A A omega
                # rho^2 sum |u_i|^2 about the centre
                visc = self.beta_a * area * rho * rho * w_s[:, k]
                fx = fx + visc * n_cells * cy[:, 0]
                fy = fy - visc * n_cells * cx[:, 0]
                tau = tau + visc * rho * rho * w_r2
            res["fx"][:, k] = fx
            res["fy"][:, k] = fy
            res["tau"][:, k] = tau
            res["tau_cor"][:, k] = tau - (cx[:, 0] * fy - cy[:, 0] * fx)
            res["cap"][:, k] = self.mu_s * fn * (dn @ w)
            # a cell slides when it moves and its bristle has reached its sliding deflection
            along = np.sign(omega) * (zx * ex + zy * ey)
            sliding = (speed > 0.0) & (self.sigma0 * along >= _STEADY * s)
            res["slide"][:, k] = sliding @ w

        sample(0, geometry(rho_s[:, 0][:, None]))
        rate = self.sigma0 * h
        for k in range(L - 1):
            # geometry held over the sample interval (radius at the mean force)
            geo = geometry(self.rho(0.5 * (fn_s[:, k] + fn_s[:, k + 1]))[:, None])
            dn, ex, ey = geo[2], geo[3], geo[4]
            for j in range(S):
                omega = w_mid[:, k * S + j][:, None]
                stribeck(omega, dn)
                # exact bristle relaxation over h toward its sliding deflection s/sigma0 along v
                np.divide(speed, s, out=x)
                x *= -rate
                np.expm1(x, out=x)  # -(1 - decay)
                np.multiply(s, x, out=tmp)
                tmp *= -np.sign(omega) / self.sigma0  # (1 - decay) * sliding deflection
                x += 1.0  # decay
                zx *= x
                zx += tmp * ex
                zy *= x
                zy += tmp * ey
            sample(k + 1, geo)

        runs = []
        for m, p in enumerate(plans):
            n = len(p)
            moving = p.commanded_phase() == 1
            runs.append(RigRun(
                f_n=fn_s[m, :n].copy(), f_x=res["fx"][m, :n].copy(),
                f_y=res["fy"][m, :n].copy(), tau=res["tau"][m, :n].copy(),
                load_ratio=np.abs(res["tau_cor"][m, :n]) / res["cap"][m, :n],
                sliding=moving & (res["slide"][m, :n] >= _SLIDING_LOAD),
                rho=rho_s[m, :n].copy(), sliding_load=res["slide"][m, :n].copy()))
        return runs

    def simulate(self, design: RubbingDesign | None = None, n: int = 12, seed: int = 0, *,
                 plans: Sequence[ManeuverPlan] | None = None) -> RubbingData:
        """Rub the plant with ``n`` maneuvers of ``design`` (default :class:`RubbingDesign`)
        drawn with ``seed`` (or with the given ``plans``) and read it through the sensor."""
        design = RubbingDesign() if design is None else design
        t0 = time.perf_counter()
        if plans is None:
            plans = plan_maneuvers(design, n, seed, radius=lambda f: float(self.rho(f)))
        plans = list(plans)
        runs = self.run(plans)
        data = assemble(plans, runs, design, self.truth(), source=self.name)
        meta = dict(data.meta)
        meta.update(plant=self.settings(), seed=seed, n_maneuvers=len(plans),
                    seconds=time.perf_counter() - t0)
        return dataclasses.replace(data, meta=meta)


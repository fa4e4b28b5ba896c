"""lugrip's own grasp simulator (the C++ ``GraspPlant``: the patch and the lumped plant) as
:class:`lugrip.sim.plant.Plant` objects, registered as "patch" and "lumped".

The plant is lugrip's model (include/lugrip/grasp_plant.hpp): a rigid planar object between two
soft fingertips, the distributed-contact patch or the lumped slider, a first-order actuator
behind the 50 Hz zero-order hold, fingertip sensors at 500 Hz. Its sample ``i`` is the state at
``t = i T`` (sample 0 the initial state, as the C++ closed loop reads it); ``step(commands)``
sets ``commands[j]`` at the actuator input and advances one sample, so the command the runner
computes from sample i drives the plant from sample i to i + 1, as in
:class:`lugrip.sim.run_closed_loop`. The first ``step`` after ``reset`` returns sample 0 without
advancing (the actuator starts at ``actuator.f_init``).

Both plants also offer ``closed_loop``: the whole run, plant, sensors, observers, controller,
baselines and faults, in one C++ call (:func:`lugrip.sim.run_closed_loop`), which the runner
uses for them; stepping them from Python gives the same run up to the C++ loop's own log
conventions (tests/python/test_cplant.py: the lumped slip is its path length, the drop rule the
plant's).

``extra`` columns: ``c_tilde_true_i`` (the true normalised CoR of finger i's relative motion,
as the C++ loop logs it), ``supported`` and ``dropped`` (the plant's own flags: the object
rests on its support; a drop criterion of ``config.drop`` was met, latched) and ``energy`` (the plant's mechanical and bristle energy [J]).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import _core
from ._closed_loop import ClosedLoopRun, run_closed_loop
from .plant import PlantClock, PlantSamples

__all__ = ["CPlant", "LumpedPlant", "PatchPlant"]

_FINGER = ("f_n", "f_x", "f_y", "tau", "true_f_n", "true_f_x", "true_f_y", "true_tau",
           "slip_x", "slip_y", "slip_angle", "slip_vx", "slip_vy", "omega", "c_tilde")
_STATE = ("t", "f_n", "gripper_y", "x", "y", "theta", "max_slip", "ext_fx", "ext_fy",
          "ext_tau", "supported", "dropped")


class CPlant:
    """lugrip's C++ grasp plant of model ``model`` ("patch" or "lumped") as a Plant."""

    #: the run's ``slip`` column is the slip path length (the lumped plant does not translate)
    path_slip = False

    def __init__(self, model: str = "patch") -> None:
        if model not in ("patch", "lumped"):
            raise ValueError(f"model {model!r}: expected 'patch' or 'lumped'")
        self.name = model
        self._plant: Any = None
        self._fresh = False
        self._status: dict[str, Any] = {"status": "ok", "detail": "", "time": None,
                                        "contact_time": None}

    def _config(self, config):
        return config if config.model == self.name else config.replace(model=self.name)

    # --- the Plant interface ----------------------------------------------------------------
    def reset(self, scene, seed: int | None = None, *, config=None) -> PlantClock:
        cfg = config if config is not None else scene.plant_config(self.name, seed)
        if seed is not None and config is not None:
            cfg = cfg.replace(seed=int(seed))
        cfg = self._config(cfg)
        self._plant = _core.GraspPlant(cfg.to_core())
        self._cfg = cfg
        self._T = 1.0 / float(cfg.sensor.rate)
        self._i = 0
        self._fresh = True
        self._status = {"status": "ok", "detail": "", "time": None, "contact_time": None}
        return PlantClock(sample_period=self._T,
                          command_ratio=round(float(cfg.sensor.rate) / cfg.actuator.command_rate))

    def step(self, commands) -> PlantSamples:
        cmd = np.ascontiguousarray(commands, dtype=np.float64).reshape(-1)
        if self._plant is None:
            raise RuntimeError(f"{self.name} plant: step before reset")
        parts = []
        if self._fresh:  # sample 0: the initial state, read without advancing
            self._fresh = False
            parts.append(self._current())
            cmd = cmd[1:]
        if cmd.size:
            parts.append(self._plant.run(cmd))
        rows = {k: np.concatenate([np.atleast_1d(p[k]) for p in parts]) for k in parts[0]}
        return self._samples(rows)

    def scene_status(self) -> dict[str, Any]:
        """Always "ok": the object starts between the fingers, which touch it from t = 0."""
        return dict(self._status)

    def closed_loop(self, config, controller_settings=None, observer_settings=None,
                    mode_schedule=None, duration: float = 10.0, **options) -> ClosedLoopRun:
        """The whole closed loop on this plant in one C++ call
        (:func:`lugrip.sim.run_closed_loop` with the config's model set to this plant's)."""
        return run_closed_loop(self._config(config), controller_settings, observer_settings,
                               mode_schedule, duration, **options)

    # --- helpers ----------------------------------------------------------------------------
    def _current(self) -> dict[str, np.ndarray]:
        """The columns of ``GraspPlant.run`` for the present sample (without advancing)."""
        p = self._plant
        row: dict[str, Any] = {}
        for k in (0, 1):
            s = p.sensor_sample(k)
            for name in _FINGER:
                row[f"{name}_{k}"] = getattr(s, name)
        st = p.state
        for name in _STATE:
            row[name] = getattr(st, name)
        row["f_act"] = st.f_n
        row["energy"] = p.energy
        return {k: np.array([v], dtype=bool if k in ("supported", "dropped") else float)
                for k, v in row.items()}

    def _samples(self, r: dict[str, np.ndarray]) -> PlantSamples:
        n = r["t"].shape[0]
        t = (self._i + np.arange(n)) * self._T
        self._i += n

        def fingers(*names):
            return np.stack([np.stack([r[f"{x}_{k}"] for x in names], -1) for k in (0, 1)], 1)

        true = fingers("true_f_n", "true_f_x", "true_f_y", "true_tau")
        contact = true[:, :, 0] > self._cfg.drop.contact_force_min
        if self._status["contact_time"] is None and contact.all(axis=1).any():
            self._status["contact_time"] = float(t[np.argmax(contact.all(axis=1))])
        # the object point at the grasp point: finger 0's pad centre (sensor x_0 = X, y_0 = Y)
        slip = np.stack([r["slip_x_0"], r["slip_y_0"]], 1)
        extra = {"c_tilde_true_0": r["c_tilde_0"], "c_tilde_true_1": r["c_tilde_1"],
                 "supported": r["supported"].astype(np.int64),
                 "dropped": r["dropped"].astype(np.int64), "energy": r["energy"]}
        if self.path_slip:  # no translation: its slip is the path length, as logged in C++
            extra["slip"] = r["max_slip"]
        return PlantSamples(
            t=t,
            wrench=fingers("f_n", "f_x", "f_y", "tau"),
            wrench_true=true,
            grip_force=r["f_act"],
            contact=contact,
            slip=slip,
            rotation=r["slip_angle_0"],
            theta=r["theta"],
            cog=np.stack([r["x"], r["y"]], 1),
            omega=fingers("omega")[:, :, 0],
            v_slip=np.hypot(fingers("slip_vx")[:, :, 0], fingers("slip_vy")[:, :, 0]),
            external=np.stack([r["ext_fx"], r["ext_fy"], r["ext_tau"]], 1),
            gripper_y=r["gripper_y"],
            extra=extra,
        ).check()


class PatchPlant(CPlant):
    """lugrip's distributed-contact (pressure patch) grasp plant."""

    def __init__(self) -> None:
        super().__init__("patch")


class LumpedPlant(CPlant):
    """lugrip's lumped LuGre/limit-surface slider plant (no translational slip)."""

    path_slip = True

    def __init__(self) -> None:
        super().__init__("lumped")

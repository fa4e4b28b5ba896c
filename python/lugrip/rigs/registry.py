"""Rubbing plants by name, for the ``lugrip simulate-rubbing`` command and scripts."""

from __future__ import annotations

__all__ = ["PLANTS", "make_rig"]

#: Plant names accepted by :func:`make_rig`, with one line on each.
PLANTS: dict[str, str] = {
    "grid-stribeck": "distributed 31x31 grid of LuGre cells, Hertzian pressure, Stribeck "
                     "friction mu_s 0.55 / mu_k 0.45, no viscous shear (independent physics)",
    "grid-viscous": "the same grid plus a viscous shear of 2e7 N s/m^3 uniform over the patch "
                    "(independent physics)",
    "lumped": "lugrip's lumped LuGre/limit-surface model with the prescribed omega "
              "(consistency only)",
    "patch": "the grasp simulator's pressure patch (lugrip.sim.PatchContact) with prescribed "
             "kinematics",
    "mujoco": "MuJoCo pad on a compliant mount rubbing a fixed slider (lugrip.rigs.mujoco_rig, "
              "needs mujoco)",
    "drake": "Drake compliant-hydroelastic pad on a compliant mount rubbing a rigid slab: the "
             "patch's pressure field and limit surface from the engine (lugrip.sim.drake.rig, "
             "needs drake)",
}

#: the engine rigs: plant name -> (module relative to lugrip, class, pip package, the
#: package's import name)
_ENGINE_RIGS: dict[str, tuple[str, str, str, str]] = {
    "mujoco": (".rigs.mujoco_rig", "MujocoRubbingRig", "mujoco", "mujoco"),
    "drake": (".sim.drake.rig", "DrakeRubbingRig", "drake", "pydrake"),
}


def make_rig(name: str, *, params=None):
    """The rig called ``name`` (one of :data:`PLANTS`). ``params`` (ContactParams, preset
    name or dict) sets the contact of the ``lumped`` and ``patch`` plants (default: the
    aluminium_can preset); the other plants carry their own physics and reject it."""
    key = str(name).strip().lower()
    if key not in PLANTS:
        raise ValueError(f"unknown plant {name!r}; known: {', '.join(PLANTS)}")
    if params is not None and key not in ("lumped", "patch"):
        raise ValueError(f"plant {key!r} has its own physics; contact parameters apply only "
                         "to 'lumped' and 'patch'")
    if key in ("grid-stribeck", "grid-viscous"):
        from .grid import GridContactRig

        return GridContactRig.stribeck() if key == "grid-stribeck" else GridContactRig.viscous()
    if key in ("lumped", "patch"):
        from .model_rigs import LumpedRig, PatchRig

        cls = LumpedRig if key == "lumped" else PatchRig
        return cls() if params is None else cls(params=params)
    import importlib

    relative, attr, package, import_name = _ENGINE_RIGS[key]
    module = __name__.split(".", 1)[0] + relative
    try:
        engine_rig = importlib.import_module(module)
    except ModuleNotFoundError as err:
        if err.name == module:
            raise ImportError(f"the {key!r} plant is not available in this installation "
                              f"(module {module} is missing)") from None
        if (err.name or "").split(".")[0] == import_name:
            raise ImportError(f"the {key!r} plant needs the {package} package: "
                              f"pip install {package}") from None
        raise
    cls = getattr(engine_rig, attr, None)
    if cls is None:
        raise ImportError(f"{module} defines no {attr} class")
    return cls()

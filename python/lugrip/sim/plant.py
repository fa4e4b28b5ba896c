"""The Plant interface: what a grasp simulator gives lugrip's closed loop, and the registry of
plant kinds.

A plant simulates the gripper, its two fingertip force/torque sensors, the grasped object and the
robot's moves and disturbances. It knows nothing of lugrip's observers, controller, baselines,
faults or judging: the closed-loop runner (:mod:`lugrip.sim.runner`) owns those for every
plant. A plant kind is one module with a class that satisfies :class:`Plant` and one call of
:func:`register_plant` (a line in the built-in registrations at the end of this module, which
import the plant's module only when it is used). Every ``--plant`` choice, scenario check and
campaign asks this registry; nothing else names a plant kind.

Registered kinds: "patch" and "lumped" (lugrip's own C++ grasp simulator,
:mod:`lugrip.sim.cplant`), "mujoco" (:class:`lugrip.sim.mujoco.plant.MujocoPlant`, the reference
implementation of an engine) and "drake" (:class:`lugrip.sim.drake.plant.DrakePlant`). The
runner is :func:`lugrip.sim.runner.run_plant_loop`.

The cycle
---------
::

    plant = make_plant("mujoco")                 # a registered kind, its options as keywords
    clock = plant.reset(scene, seed, config=cfg)  # -> PlantClock (sample period, command ratio)
    out = plant.step(np.full(1, f_init))          # sample 0
    out = plant.step(np.full(clock.command_ratio, f_cmd))  # the next command period, ...

``reset(scene, seed=None, *, config=None)``
    ``scene`` is the parsed scenario, a :class:`lugrip.sim.scenarios.Scenario` (already
    ``scene.for_plant(name)``): the plant reads its own block from it, ``scene.block(name)``
    (a dict: the scenario file's top-level key of the plant's name, e.g. ``mujoco:`` -- which
    ``scene.scene_spec()`` parses for MuJoCo -- or ``drake:``; any registered name is accepted
    as a key), and may read ``scene.duration`` and ``scene.name``. ``config`` is the
    :class:`lugrip.sim.PlantConfig` of the run (object mass/inertia/CoG [kg, kg m^2, m];
    contact parameters; actuator lag, rate limit, range and ``f_init``; sensor rate, noise and
    bias; gripper moves; disturbances; drop limits; seed). When None it is
    ``scene.plant_config(name, seed)``; a caller passes its own when it changed it (a campaign's
    drawn object). ``seed`` (None: ``config.seed``) seeds the sensor noise. Returns the
    :class:`PlantClock`. Reset may be called again to start a new run on the same object.

``step(commands)``
    ``commands``: a 1-D float array, one entry per sensor sample to simulate: the grip-force
    command [N] at the actuator's input during that sample (the plant applies its actuator lag,
    rate limit and range to it). The runner calls it with one sample after reset (sample 0),
    then with ``command_ratio`` samples at a time (the command period, the last sample being
    the next command tick); any length >= 1 must work. Returns the :class:`PlantSamples` of
    those samples.

``estimator(config)`` (optional)
    The contact parameters lugrip's observers and controller use on this plant when the
    scenario names none for it (an engine whose contact is not lugrip's model states what
    identification on it gives); without it, the plant block's contact.

``closed_loop(config, controller_settings, observer_settings, mode_schedule, duration, **options)`` (optional)
    A plant whose physics and lugrip's controller can run together in compiled code offers
    the whole loop in one call with :func:`lugrip.sim.run_closed_loop`'s arguments (the
    keyword options the runner takes: ``kind``, ``constant_force``, ``cone_*``, ``estimator``,
    ``faults``, ``stuck_samples``, ``healthy_finger_fallback``); the runner then hands the run
    to it instead of stepping the plant (the C++ plants; same schedule, faults and baselines
    as the runner's, tests/python/test_cplant.py compares the two).

``scene_status()``
    A dict {status, detail, time, contact_time}: ``status`` is "ok" or a short code naming a
    scene fault (the object not between the fingers, a finger closing on nothing, a contact
    lost after the grasp; :data:`SCENE_STATUS`), ``time`` [s] when it was found, ``contact_time``
    [s] when both fingers first touched the object (None: not yet). Scene faults never raise.

Frames and signs (all arrays float64 unless said, n = samples of the call, finger 0 and 1)
------------------------------------------------------------------------------------------
* fingertip sensor frame: origin on the fingertip axis at its face, z along the fingertip axis
  from the face into the finger (the direction of the normal force the object exerts on the
  fingertip), x and y in the fingertip plane, right-handed (docs/sliding_log.md).
* ``wrench`` (n, 2, 4): what each sensor reads, (f_n, f_x, f_y, tau) = the wrench the object
  exerts on the fingertip in its sensor frame [N, N, N, N m], tau about the sensor z axis,
  averaged over the sample period, with the sensor's bias and noise (``config.sensor``).
  ``wrench_true`` (n, 2, 4): the same without bias and noise.
* the hand frame: the plane the object moves in (the finger plane), X horizontal and Y up when
  the hand is not rolled; Z is the grasp axis, from finger 0 to finger 1. The world plane:
  horizontal, vertical. Angles are positive about Z (right-hand rule).
"""

from __future__ import annotations

import dataclasses
import importlib
from collections.abc import Callable, Mapping, Sequence
from typing import Any, Protocol, runtime_checkable

import numpy as np

__all__ = [
    "SCENE_STATUS",
    "Plant",
    "PlantClock",
    "PlantKind",
    "PlantSamples",
    "builds_scene",
    "make_plant",
    "plant_class",
    "plant_description",
    "plant_kind",
    "plant_names",
    "plant_renders",
    "register_plant",
    "registered",
]

#: Scene status codes a plant reports (``scene_status()["status"]``), with their meaning.
SCENE_STATUS: dict[str, str] = {
    "ok": "both fingers touched the object and kept contact from the lift start on",
    "object_not_reached": "a finger never touched the object: it is not between the fingers",
    "closed_on_nothing": "a finger reached its closing stop without touching anything",
    "lost_contact": "a finger lost contact with the object after the grasp was established",
}


@dataclasses.dataclass(frozen=True)
class PlantClock:
    """The timing a plant runs at, returned by ``reset``."""

    sample_period: float  #: sensor sample period [s] (the observers' and controller's dt)
    command_ratio: int  #: sensor samples per grip-force command (the command period)


@dataclasses.dataclass
class PlantSamples:
    """The fingertip samples and the ground truth of ``step``'s n sensor samples.

    Measured (what lugrip's observers and controller may use):

    * ``t`` (n,): sample times from the start of the run [s] (sample i at i * sample_period).
    * ``wrench`` (n, 2, 4): each fingertip sensor's reading (f_n, f_x, f_y, tau) [N, N, N, N m],
      the object's wrench on the fingertip in the sensor frame (module docstring), averaged
      over the sample, with bias and noise.

    Ground truth (for logs, metrics and judging only):

    * ``wrench_true`` (n, 2, 4): ``wrench`` without bias and noise.
    * ``grip_force`` (n,): the force the gripper's actuator actually applies at the end of the
      sample (after its lag, rate limit and range) [N].
    * ``contact`` (n, 2) bool: fingertip i touches the object (at the end of the sample).
    * ``slip`` (n, 2): displacement of the object's grasp point relative to the fingertips
      since reset, in the hand frame (X, Y) [m].
    * ``rotation`` (n,): rotation of the object relative to the fingertips since reset [rad]
      (positive about the grasp axis from finger 0 to finger 1).
    * ``theta`` (n,): the object's angle in the world plane [rad] (0 at rest).
    * ``cog`` (n, 2): the object's centre of gravity relative to the fingertips' midpoint (the
      grasp point at rest), world plane axes (horizontal, vertical) [m]; with ``theta``, the
      object's pose relative to the hand.
    * ``omega`` (n, 2): the object's spin relative to fingertip i about the sensor z axis
      [rad/s] (0 without contact).
    * ``v_slip`` (n, 2): the object's in-plane slip speed relative to fingertip i at the sensor
      origin [m/s] (0 without contact).
    * ``external`` (n, 3): the disturbance applied to the object: world force (horizontal,
      vertical) [N] and torque about its CoG [N m].
    * ``gripper_y`` (n,): the grasp point's height [m] (the hand's lift).
    * ``extra``: plant-specific columns, each (n,), logged with the run under their own names
      (MuJoCo: ``pad_deflection_0``, ``pad_twist_1``, ``roll``, ...). A column named as one the
      runner derives replaces it: ``slip`` (a plant whose slip is a path length),
      ``supported`` and ``dropped`` (a plant with its own support and drop rule, latched).
    """

    t: np.ndarray
    wrench: np.ndarray
    wrench_true: np.ndarray
    grip_force: np.ndarray
    contact: np.ndarray
    slip: np.ndarray
    rotation: np.ndarray
    theta: np.ndarray
    cog: np.ndarray
    omega: np.ndarray
    v_slip: np.ndarray
    external: np.ndarray
    gripper_y: np.ndarray
    extra: dict[str, np.ndarray] = dataclasses.field(default_factory=dict)

    def __len__(self) -> int:
        return int(self.t.shape[0])

    def check(self) -> PlantSamples:
        """Raise ValueError when an array's shape does not match n samples (a plant's bug)."""
        n = len(self)
        shapes = {
            "wrench": (n, 2, 4), "wrench_true": (n, 2, 4), "grip_force": (n,), "contact": (n, 2),
            "slip": (n, 2), "rotation": (n,), "theta": (n,), "cog": (n, 2), "omega": (n, 2),
            "v_slip": (n, 2), "external": (n, 3), "gripper_y": (n,),
        }
        for name, shape in shapes.items():
            got = np.shape(getattr(self, name))
            if got != shape:
                raise ValueError(f"PlantSamples.{name}: shape {got}, expected {shape}")
        for name, col in self.extra.items():
            if np.shape(col) != (n,):
                raise ValueError(f"PlantSamples.extra[{name!r}]: shape {np.shape(col)}, expected ({n},)")
        return self


@runtime_checkable
class Plant(Protocol):
    """A grasp simulator lugrip's closed loop runs on (see the module docstring)."""

    #: the registered name of the plant kind ("mujoco", ...)
    name: str

    def reset(self, scene: Any, seed: int | None = None, *, config: Any = None) -> PlantClock:
        """Start a run of ``scene`` (a :class:`lugrip.sim.scenarios.Scenario`) with the run's
        :class:`lugrip.sim.PlantConfig` ``config`` (None: ``scene.plant_config(name, seed)``)."""
        ...

    def step(self, commands: np.ndarray) -> PlantSamples:
        """Simulate ``len(commands)`` sensor samples, ``commands[j]`` the grip-force command
        [N] at the actuator input during sample j."""
        ...

    def scene_status(self) -> dict[str, Any]:
        """{status, detail, time, contact_time} (module docstring)."""
        ...


# --- the registry ----------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class PlantKind:
    """What the registry knows of a plant kind without building one (:func:`plant_kind`)."""

    #: a callable returning a :class:`Plant`, or a "module:attribute" string naming one
    factory: Callable[..., Plant] | str
    #: one line of description
    description: str = ""
    #: the factory takes ``frame_callback=f(model, data, t)`` (MuJoCo's offscreen frames)
    frames: bool = False
    #: the plant builds a scene of its own from the scenario (its block, e.g. ``mujoco:``): it
    #: can fail to grasp (the scene status and the ``scene_ok`` criterion), its runs are
    #: reported per engine (``lugrip simulate``'s ``<name>.md``)
    scene: bool = True
    #: the :class:`lugrip.sim.PlantConfig` model of the plant block the plant reads ("patch":
    #: an engine reads the patch plant's object, contact, actuator, sensors and moves)
    config_model: str = "patch"
    #: campaign parameters of this kind only: parameter name -> the key path in the scenario
    #: it sets (e.g. ``pad_k_slide`` -> ("mujoco", "pad", "k_slide"))
    parameters: Mapping[str, tuple[str, ...]] = dataclasses.field(default_factory=dict)


#: name -> PlantKind
_REGISTRY: dict[str, PlantKind] = {}
#: the kinds registered by this module (not replaceable)
_BUILTIN: frozenset[str] = frozenset()


def register_plant(name: str, factory: Callable[..., Plant] | str, description: str = "", *,
                   frames: bool = False, scene: bool = True, config_model: str = "patch",
                   parameters: Mapping[str, Sequence[str]] | None = None) -> None:
    """Make plant kind ``name`` available to :func:`make_plant` and ``--plant``.

    ``factory`` is a callable returning a :class:`Plant` (called with :func:`make_plant`'s
    keyword options), or a ``"module:attribute"`` string naming one, imported on first use (so
    an engine's package is imported only when its plant is used). Registering a name again
    replaces it, except lugrip's built-in kinds. ``frames``, ``scene``, ``config_model``, ``parameters``: see
    :class:`PlantKind`."""
    key = str(name).strip().lower()
    if not key or not key.replace("_", "").replace("-", "").isalnum():
        raise ValueError(f"plant name {name!r}: expected letters, digits, '-' or '_'")
    if key in _BUILTIN:
        raise ValueError(f"plant name {key!r} is one of lugrip's built-in plants")
    if not (callable(factory) or (isinstance(factory, str) and ":" in factory)):
        raise TypeError("factory: expected a callable or a 'module:attribute' string")
    if config_model not in ("patch", "lumped"):
        raise ValueError(f"config_model {config_model!r}: expected 'patch' or 'lumped'")
    params = {str(k): tuple(str(x) for x in v) for k, v in (parameters or {}).items()}
    if any(not v for v in params.values()):
        raise ValueError("parameters: every parameter needs a non-empty key path")
    _REGISTRY[key] = PlantKind(factory, str(description), bool(frames), bool(scene),
                               config_model, params)


def plant_kind(name: str) -> PlantKind:
    """The registered :class:`PlantKind` of ``name`` (ValueError when unknown)."""
    key = str(name).strip().lower()
    if key not in _REGISTRY:
        raise ValueError(f"unknown plant {name!r}; known: {', '.join(plant_names())}")
    return _REGISTRY[key]


def plant_renders(name: str) -> bool:
    """Plant kind ``name`` renders MuJoCo frames (``register_plant(..., frames=True)``)."""
    return registered(name) and plant_kind(name).frames


def builds_scene(name: str) -> bool:
    """Plant kind ``name`` builds a scene of its own (``register_plant(..., scene=True)``)."""
    return registered(name) and plant_kind(name).scene


def plant_names() -> tuple[str, ...]:
    """Every plant kind a scenario may run on, in registration order."""
    return tuple(_REGISTRY)


def plant_description(name: str) -> str:
    """The one-line description of plant kind ``name``."""
    return plant_kind(name).description


def plant_class(name: str) -> Callable[..., Plant]:
    """The factory of plant kind ``name`` (its module imported; ImportError naming the package
    when the engine is not installed), without building a plant."""
    key = str(name).strip().lower()
    if key not in _REGISTRY:
        raise ValueError(f"unknown plant {name!r}; registered: {', '.join(_REGISTRY) or 'none'}")
    factory = _REGISTRY[key].factory
    if isinstance(factory, str):
        module, _, attr = factory.partition(":")
        try:
            factory = getattr(importlib.import_module(module), attr)
        except ModuleNotFoundError as err:
            raise ImportError(f"the {key!r} plant needs the package {err.name!r}, which is not "
                              "installed") from err
    return factory


def make_plant(name: str, **options: Any) -> Plant:
    """A new plant of the registered kind ``name``, built with ``options`` (the kind's own
    keywords, e.g. MuJoCo's ``frame_callback``)."""
    factory = plant_class(name)
    plant = factory(**options)
    if not isinstance(plant, Plant):
        raise TypeError(f"plant {name!r}: {factory!r} returned {type(plant).__name__}, which "
                        "lacks reset/step/scene_status")
    return plant


def registered(name: str) -> bool:
    """``name`` is a registered plant kind."""
    return str(name).strip().lower() in _REGISTRY


# --- the built-in plants ---------------------------------------------------------------------

register_plant(
    "patch",
    "lugrip.sim.cplant:PatchPlant",
    "lugrip's distributed-contact (pressure patch) grasp plant, in C++",
    scene=False,
)
register_plant(
    "lumped",
    "lugrip.sim.cplant:LumpedPlant",
    "lugrip's lumped LuGre/limit-surface slider plant, in C++ (no translational slip)",
    scene=False,
    config_model="lumped",
)
register_plant(
    "mujoco",
    "lugrip.sim.mujoco.plant:MujocoPlant",
    "MuJoCo gripper with compliant pads and condim-4 contacts (an independent engine)",
    frames=True,
    parameters={"pad_k_slide": ("mujoco", "pad", "k_slide"),
                "pad_k_twist": ("mujoco", "pad", "k_twist")},
)
register_plant(
    "drake",
    "lugrip.sim.drake.plant:DrakePlant",
    "Drake gripper with compliant-hydroelastic pads: the patch's pressure field and limit "
    "surface from the engine (an independent engine; pip install 'lugrip[drake]')",
)
_BUILTIN = frozenset(_REGISTRY)

"""A compliant-hydroelastic fingertip pad for Drake models, and its force/torque sensor.

The pad is a sphere of compliant-hydroelastic material (Drake's pressure-field contact): where
it overlaps a rigid surface, Drake builds the contact patch, a polygon mesh carrying the pad's
pressure field, and integrates the friction of every polygon over it. The normal force, the
patch radius, the tangential force and the torsional moment therefore all come from the
engine; nothing of lugrip's limit surface or radius law is put into it.

For a sphere of radius R pressed a depth d into a flat face, the pressure field
p = E (depth / R) gives the force f_n = pi E d^2 on a patch of radius a = sqrt(2 R d), a
paraboloid pressure over it, so a = (4 R^2 f_n / (pi E))^(1/4) (:meth:`DrakePad.patch_radius`,
the continuum value) and the torsional capacity in pure spin mu (8/15) f_n a. Drake meshes the
sphere with tetrahedra of about ``resolution_hint``; the patch it integrates is that of the
mesh, so the engine's own capacity is measured on the engine (:func:`lugrip.sim.drake.rig
.measure_capacity`), not taken from this formula.

The pad hangs from its finger on a planar joint (two slides in the pad plane, a twist about the
pad axis) with springs (a linear bushing) and the joint's viscous damping (implicit in Drake's
discrete solver): it deflects before the contact slides, and the springs of the two pads share
the load between the fingers.

Pad (sensor) frame: origin on the pad axis at the pad face, z along the pad axis from the face
into the finger (the direction of the normal force the object exerts on the pad), x and y in the
pad plane, right-handed (docs/sliding_log.md). The pad body's frame is this frame at rest.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

__all__ = ["DrakePad", "PadWrench", "add_pad", "rigid_properties"]


@dataclasses.dataclass(frozen=True)
class DrakePad:
    """Geometry, material, mount and friction of one pad (SI units)."""

    radius: float = 0.012  #: sphere radius R [m]
    #: hydroelastic modulus E [Pa]: the continuum patch radius is 1.8 mm at 1 N
    modulus: float = 1.75e7
    #: Drake's mesh resolution hint [m]. Drake refines the sphere in levels: 3 mm (and 2.5 mm)
    #: put 8-45 polygons in the patch (1-30 N), 2 mm 25-125 at 3-8 times the cost per step; the
    #: capacity then departs up to +-7 % from a power law of f_n (2 mm: 1 %), measured on the
    #: engine (:func:`lugrip.sim.drake.rig.measure_capacity`)
    resolution_hint: float = 0.003
    #: Hunt-Crossley dissipation [s/m] of the pad material (the normal mode damped)
    dissipation: float = 10.0
    mass: float = 0.035  #: pad body (with the sensor flange) [kg]
    k_slide: float = 4000.0  #: in-plane mount stiffness [N/m]
    k_twist: float = 2.0  #: twist mount stiffness about the pad axis [N m/rad]
    d_slide: float = 20.0  #: in-plane mount damping [N s/m]
    d_twist: float = 0.05  #: twist mount damping [N m s/rad]
    mu: float = 0.7  #: Coulomb friction of the pad with the surface it touches [-]

    def __post_init__(self):
        for f in dataclasses.fields(self):
            v = float(getattr(self, f.name))
            if not math.isfinite(v) or v < 0.0 or (v == 0.0 and f.name not in (
                    "dissipation", "d_slide", "d_twist")):
                raise ValueError(f"DrakePad.{f.name} = {v!r}: must be finite and > 0")
        if self.resolution_hint > self.radius:
            raise ValueError("DrakePad.resolution_hint must be <= the radius")

    def patch_radius(self, f_n):
        """The continuum patch radius a = (4 R^2 f_n / (pi E))^(1/4) [m] (Drake's mesh gives
        its own, close to it)."""
        f = np.maximum(np.asarray(f_n, dtype=float), 0.0)
        out = (4.0 * self.radius**2 * f / (math.pi * self.modulus)) ** 0.25
        return float(out) if np.ndim(out) == 0 else out

    def depth(self, f_n) -> float:
        """The continuum penetration d = sqrt(f_n / (pi E)) at normal force f_n [m]."""
        return math.sqrt(max(float(f_n), 0.0) / (math.pi * self.modulus))

    def replace(self, **changes) -> DrakePad:
        return dataclasses.replace(self, **changes)


def _material(mu: float, dissipation: float | None):
    from pydrake.geometry import AddContactMaterial, ProximityProperties
    from pydrake.multibody.plant import CoulombFriction

    props = ProximityProperties()
    AddContactMaterial(dissipation=dissipation, friction=CoulombFriction(mu, mu), properties=props)
    return props


def rigid_properties(mu: float, resolution_hint: float = 0.002):
    """Proximity properties of a rigid-hydroelastic object surface with friction mu (Drake
    combines the two materials' coefficients as 2 mu1 mu2 / (mu1 + mu2): the pad and the object
    carry the same mu, so the contact has it)."""
    from pydrake.geometry import AddRigidHydroelasticProperties

    props = _material(mu, None)
    AddRigidHydroelasticProperties(resolution_hint, props)
    return props


def add_pad(plant, parent, X_parent_pad, name: str, pad: DrakePad):
    """Add pad ``name`` to ``plant``, hanging from frame ``parent`` (a body frame) with its rest
    pose ``X_parent_pad`` (a RigidTransform of the pad frame in ``parent``). Returns
    (pad body, its planar joint, its geometry id)."""
    from pydrake.geometry import AddCompliantHydroelasticProperties, Sphere
    from pydrake.math import RigidTransform
    from pydrake.multibody.tree import (
        FixedOffsetFrame,
        LinearBushingRollPitchYaw,
        PlanarJoint,
        SpatialInertia,
    )

    inertia = SpatialInertia.SolidSphereWithMass(pad.mass, pad.radius)
    # the sphere's centre at z = R in the pad frame: its inertia about the pad origin
    inertia = inertia.Shift([0.0, 0.0, -pad.radius])
    body = plant.AddRigidBody(name, parent.body().model_instance(), inertia)
    mount = plant.AddFrame(FixedOffsetFrame(f"{name}_mount", parent, X_parent_pad))
    joint = plant.AddJoint(PlanarJoint(
        f"{name}_mount", mount, body.body_frame(),
        damping=np.array([pad.d_slide, pad.d_slide, pad.d_twist])))
    plant.AddForceElement(LinearBushingRollPitchYaw(
        mount, body.body_frame(),
        torque_stiffness_constants=np.array([0.0, 0.0, pad.k_twist]),
        torque_damping_constants=np.zeros(3),
        force_stiffness_constants=np.array([pad.k_slide, pad.k_slide, 0.0]),
        force_damping_constants=np.zeros(3)))
    props = _material(pad.mu, pad.dissipation)
    AddCompliantHydroelasticProperties(pad.resolution_hint, pad.modulus, props)
    gid = plant.RegisterCollisionGeometry(
        body, RigidTransform([0.0, 0.0, pad.radius]), Sphere(pad.radius), name, props)
    return body, joint, gid


class PadWrench:
    """Reads, from Drake's contact results, the wrench the touching bodies exert on a pad in its
    pad frame, (f_n, f_x, f_y, tau) with tau about the pad z axis through the pad origin, and
    the patch's size (the polygons' count and area)."""

    def __init__(self, plant, scene_graph, body, geometry_id):
        self.plant = plant
        self.body = body
        self.geometry_id = geometry_id
        self._inspector = scene_graph.model_inspector()

    def read(self, context, results=None) -> tuple[np.ndarray, int, float]:
        """(wrench (4,), polygons, patch area [m^2]) at ``context`` (the plant's); ``results``:
        the plant's ContactResults when evaluated already."""
        plant = self.plant
        if results is None:
            results = plant.get_contact_results_output_port().Eval(context)
        X_WP = self.body.EvalPoseInWorld(context)
        p_WO = X_WP.translation()
        f_W = np.zeros(3)
        t_W = np.zeros(3)  # about the pad origin O
        faces, area = 0, 0.0
        for i in range(results.num_hydroelastic_contacts()):
            info = results.hydroelastic_contact_info(i)
            surf = info.contact_surface()
            if self.geometry_id == surf.id_M():
                sign = 1.0  # F_Ac_W acts on the body of geometry M
            elif self.geometry_id == surf.id_N():
                sign = -1.0
            else:
                continue
            F = info.F_Ac_W()
            f = sign * F.translational()
            f_W += f
            t_W += sign * F.rotational() + np.cross(np.asarray(surf.centroid()) - p_WO, f)
            faces += surf.num_faces()
            area += surf.total_area()
        R = X_WP.rotation().matrix()
        f_P = R.T @ f_W
        t_P = R.T @ t_W
        return np.array([f_P[2], f_P[0], f_P[1], t_P[2]]), faces, area

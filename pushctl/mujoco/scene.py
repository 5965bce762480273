"""The MuJoCo model of the pushing scene, built with ``mujoco.MjSpec`` from the project's specs.

The same inputs as :func:`pushctl.make_world`: the arm's URDF (the very file Pinocchio reads,
imported by MuJoCo's own URDF parser, so the arm's kinematics and inertias are MuJoCo's),
the pusher plate of :class:`~pushctl.config.PusherConfig` welded to the end effector with
the placement :func:`pushctl.arm.pusher.placement_ee_to_pusher` gives, and the object of an
:class:`~pushctl.objects.ObjectSpec` as a free rigid body: a box for a rectangular prism,
otherwise the convex mesh of its footprint extruded up to its (possibly sloped) top.
MuJoCo computes the object's mass properties from that geometry with the spec's mass; the
tests compare them with the spec's (I_z, centre-of-mass height).

Prongs are small spheres (radius :data:`PRONG_RADIUS`) whose front points are the prong
points of the pusher frame, so a sphere touches the pushed face exactly where our point
prong does. Only three kinds of contact exist, as explicit pairs (every geom has
contype = conaffinity = 0): object–floor with μ_g, prong–object with μ_c. The arm has no
collision geometry, as in our world.

Body frame of the object: origin on the table under the centre of mass, axes the object's
local frame (x = e_n), so its free joint's (x, y, yaw) is the planar pose (x, y, θ).
"""

from __future__ import annotations

import importlib.resources
import math
from dataclasses import dataclass

import mujoco
import numpy as np

from pushctl.arm import ArmModel
from pushctl.arm.kinova_urdf import URDF_FILENAME
from pushctl.arm.pusher import placement_ee_to_pusher
from pushctl.errors import ConfigError
from pushctl.objects import ObjectSpec

SUPPORTED_ARMS = ("kinova-gen2-7dof",)
"""Arms the MuJoCo scene can be built for: the project's own URDF (the others come from
example-robot-data with mesh files MuJoCo would have to resolve)."""

PRONG_RADIUS = 0.003
"""Radius [m] of a prong's sphere: small against the 88 mm face, large enough for a
well-conditioned sphere–box contact."""

OBJECT_BODY, PUSHER_BODY, FLOOR_GEOM, OBJECT_GEOM = "object", "pusher", "floor", "object"


def prong_geom_name(i: int) -> str:
    return f"prong_{i}"


def prong_site_name(i: int) -> str:
    return f"prong_point_{i}"


@dataclass(frozen=True)
class MujocoSettings:
    """Solver and contact parameters of the MuJoCo scene (chosen by measurement, see
    docs/mujoco.md and studies/mujoco_validation.py).

    ``substeps``: MuJoCo steps per control step (timestep = dt / substeps). ``cone``:
    ``elliptic`` or ``pyramidal``. ``solref_*`` (time constant [s], damping ratio) and
    ``solimp_*`` (d0, dwidth, width [m], midpoint, power) of the prong and floor contacts;
    ``impratio``: friction-to-normal impedance ratio (elliptic cones only);
    ``solref_friction_floor``: the floor friction's own solref (None: see
    :meth:`floor_friction_solref`). ``integrator``:
    ``implicitfast`` (joint damping, hence the PD's K_v, is integrated implicitly).
    """

    substeps: int = 1
    cone: str = "elliptic"
    impratio: float = 3.0
    solref_prong: tuple[float, float] = (0.02, 1.0)
    solref_floor: tuple[float, float] = (0.02, 2.0)
    solref_friction_floor: tuple[float, float] | None = None
    solimp_prong: tuple[float, float, float, float, float] = (0.9, 0.95, 0.001, 0.5, 2.0)
    solimp_floor: tuple[float, float, float, float, float] = (0.9, 0.95, 0.001, 0.5, 2.0)
    integrator: str = "implicitfast"

    def floor_friction_solref(self, timestep: float) -> tuple[float, float]:
        """The floor friction's (time constant [s], damping ratio): by default
        max(0.02 s, 4 timesteps). Measured (docs/mujoco.md): at h = 0.01 s, 0.04 s (the
        normal's) keeps the slide within 3 % and the spin-down within 7 %, and 0.02 s stops
        them 7 % and 62 % short; at h = 1 ms, 0.04 s lets a 20 ms spin-down run 72 % long
        (the soft friction's creep outlasts it) and 0.02 s brings it within 5 %."""
        if self.solref_friction_floor is not None:
            return self.solref_friction_floor
        return (max(0.02, 4.0 * timestep), 1.0)

    def __post_init__(self) -> None:
        if not (isinstance(self.substeps, int) and self.substeps >= 1):
            raise ConfigError(f"mujoco substeps must be an integer >= 1, got {self.substeps!r}")
        if self.cone not in ("elliptic", "pyramidal"):
            raise ConfigError(f"mujoco cone must be elliptic or pyramidal, got {self.cone!r}")
        if self.integrator not in ("implicitfast", "implicit", "euler"):
            raise ConfigError(
                f"mujoco integrator must be implicitfast, implicit or euler, got "
                f"{self.integrator!r}"
            )
        if not (math.isfinite(self.impratio) and self.impratio >= 1.0):
            raise ConfigError(f"mujoco impratio must be >= 1, got {self.impratio!r}")


_CONES = {"elliptic": mujoco.mjtCone.mjCONE_ELLIPTIC, "pyramidal": mujoco.mjtCone.mjCONE_PYRAMIDAL}
_INTEGRATORS = {
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
    "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
    "euler": mujoco.mjtIntegrator.mjINT_EULER,
}


def _urdf_spec(arm: ArmModel) -> mujoco.MjSpec:
    """The arm's URDF through MuJoCo's parser, keeping the fixed end-effector link as a body."""
    if arm.name not in SUPPORTED_ARMS:
        raise ConfigError(
            f"the mujoco engine supports the arm {', '.join(SUPPORTED_ARMS)}, got {arm.name!r}"
        )
    text = (importlib.resources.files("pushctl.arm") / "data" / URDF_FILENAME).read_text("utf-8")
    head = text.index(">", text.index("<robot")) + 1
    compiler = (
        '<mujoco><compiler fusestatic="false" discardvisual="true" balanceinertia="false"/>'
        "</mujoco>"
    )
    return mujoco.MjSpec.from_string(text[:head] + compiler + text[head:])


def _add_pusher(spec: mujoco.MjSpec, arm: ArmModel) -> None:
    """The plate (its inertia as the pusher's) and the prong spheres on the end effector."""
    ee = spec.body(arm.spec.ee_frame)
    if ee is None:
        raise ConfigError(f"MuJoCo's import of {arm.name!r} has no body {arm.spec.ee_frame!r}")
    pusher = arm.pusher
    placement = placement_ee_to_pusher(arm.spec.push_axis_ee, arm.spec.tool_axis_ee, pusher)
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(placement.rotation).ravel())
    body = ee.add_body(name=PUSHER_BODY, pos=placement.translation, quat=quat)
    m, t, w, h = pusher.mass, pusher.thickness, pusher.width, pusher.height
    body.explicitinertial = True
    body.mass = m
    body.ipos = (-0.5 * t, 0.0, 0.0)
    body.inertia = (m / 12.0) * np.array([w * w + h * h, t * t + h * h, t * t + w * w])
    # Where each prong really is on the plate: the nominal spacing plus any mounting error
    # (``prong_errors``, a plant unknown), as our engine's prong frames (attach_pusher).
    for i, (along, across) in enumerate(pusher.prong_points().tolist()):
        body.add_site(name=prong_site_name(i), pos=(along, across, 0.0))
        body.add_geom(
            name=prong_geom_name(i),
            type=mujoco.mjtGeom.mjGEOM_SPHERE,
            size=(PRONG_RADIUS, 0, 0),
            pos=(along - PRONG_RADIUS, across, 0.0),
            contype=0,
            conaffinity=0,
            mass=0.0,
        )
    body.add_site(name=PUSHER_BODY, pos=(0.0, 0.0, 0.0))


def _is_box(obj: ObjectSpec) -> bool:
    """A rectangular prism with axis-aligned sides in the object frame (the cube)."""
    v = obj.footprint
    flat = not np.any(obj.slope)
    return bool(flat and len(v) == 4 and np.allclose(np.abs(v), np.abs(v[0]), atol=1e-12))


def _add_object(spec: mujoco.MjSpec, obj: ObjectSpec) -> None:
    """The object as a free body; its mass properties follow from geometry and mass."""
    body = spec.worldbody.add_body(name=OBJECT_BODY)
    body.add_freejoint(name=OBJECT_BODY)
    if _is_box(obj):
        half = np.abs(obj.footprint[0])
        height = obj.height_at_origin
        body.add_geom(
            name=OBJECT_GEOM,
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=(half[0], half[1], 0.5 * height),
            pos=(0.0, 0.0, 0.5 * height),
            mass=obj.mass,
            contype=0,
            conaffinity=0,
        )
        return
    tops = obj.height_at(obj.footprint)
    points = [(x, y, 0.0) for x, y in obj.footprint.tolist()]
    points += [
        (x, y, z)
        for (x, y), z in zip(obj.footprint.tolist(), tops.tolist(), strict=True)
        if z > 1e-9
    ]
    mesh = spec.add_mesh(name=OBJECT_GEOM)
    mesh.uservert = np.asarray(points, dtype=float).ravel()
    body.add_geom(
        name=OBJECT_GEOM,
        type=mujoco.mjtGeom.mjGEOM_MESH,
        meshname=OBJECT_GEOM,
        mass=obj.mass,
        contype=0,
        conaffinity=0,
    )


def _condim(mu: float) -> int:
    """Contact dimension: 3 (normal and sliding friction), or 1 (frictionless) for μ = 0:
    MuJoCo keeps a friction row with a minimum μ of 1e-5 otherwise."""
    return 1 if mu == 0.0 else 3


def build_model(
    obj: ObjectSpec,
    arm: ArmModel | None,
    *,
    dt: float,
    mu_ground: float,
    mu_contact: float,
    gravity: float,
    settings: MujocoSettings,
) -> mujoco.MjModel:
    """Compile the scene: floor, object, and (unless ``arm`` is None) the arm with its pusher.

    ``arm``: the Pinocchio arm whose name, pusher, armature and damping are used (its
    dynamics are not: MuJoCo derives them from the URDF). Joint limits are left out, as in
    our world (keeping the arm inside them is the controller's job).
    """
    spec = _urdf_spec(arm) if arm is not None else mujoco.MjSpec()
    spec.option.timestep = dt / settings.substeps
    spec.option.integrator = _INTEGRATORS[settings.integrator]
    spec.option.cone = _CONES[settings.cone]
    spec.option.impratio = settings.impratio
    spec.option.gravity = (0.0, 0.0, -gravity)
    spec.worldbody.add_geom(
        name=FLOOR_GEOM,
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=(0, 0, 1),
        contype=0,
        conaffinity=0,
    )
    _add_object(spec, obj)
    spec.add_pair(
        geomname1=FLOOR_GEOM,
        geomname2=OBJECT_GEOM,
        condim=_condim(mu_ground),
        friction=(mu_ground, mu_ground, 0.0, 0.0, 0.0),
        solref=settings.solref_floor,
        solimp=settings.solimp_floor,
        solreffriction=settings.floor_friction_solref(dt / settings.substeps),
    )
    if arm is not None:
        names = list(arm.model.names)[1:]  # Pinocchio's joints, in velocity order
        for name, armature, damping in zip(names, arm.armature, arm.damping, strict=True):
            joint = spec.joint(name)
            joint.armature = float(armature)
            joint.damping = (float(damping), 0.0, 0.0)  # linear term; no polynomial
            joint.limited = mujoco.mjtLimited.mjLIMITED_FALSE
        _add_pusher(spec, arm)
        for i in range(arm.pusher.n_prongs):
            spec.add_pair(
                geomname1=prong_geom_name(i),
                geomname2=OBJECT_GEOM,
                condim=_condim(mu_contact),
                friction=(mu_contact, mu_contact, 0.0, 0.0, 0.0),
                solref=settings.solref_prong,
                solimp=settings.solimp_prong,
            )
    return spec.compile()

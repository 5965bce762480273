"""``make_world``: the one call that puts an arm, a pusher and an object on the table."""

from __future__ import annotations

from pushctl.arm import ArmConfig, load_arm
from pushctl.config import GRAVITY, PusherConfig
from pushctl.contact.ground_field import FrictionField
from pushctl.contact.world import World, WorldConfig
from pushctl.objects import ObjectSpec, resolve_object, with_masses


def make_world(
    object: str | ObjectSpec = "cube",  # noqa: A002 - the public keyword of the documented API
    arm: str | None = "kinova-gen2-7dof",
    mu_ground: float = 0.3,
    mu_contact: float = 0.4,
    dt: float = 0.01,
    *,
    object_mass: float | None = None,
    pusher: PusherConfig | None = None,
    armature=None,
    damping=None,
    substeps: int = 1,
    gravity: float = GRAVITY,
    friction_field: FrictionField | None = None,
) -> World:
    """Build a world. Every argument is validated; bad ones raise a ``ConfigError``.

    object: a preset name (``cube``, ``wedge``), the path of a TOML object file, or an
        ObjectSpec (used as is; ``object_mass`` still overrides its mass).
    arm: ``kinova-gen2-7dof`` (default), ``kinova-j2s6s200``, ``panda``, or None for an
        object-only world (no pusher; ``step`` then ignores its torque argument).
    mu_ground, mu_contact: Coulomb coefficients of object–table and prong–object friction.
    dt [s]: the step; ``substeps`` divides it internally.
    object_mass [kg]: overrides the preset's mass (inertia and support loads follow).
    pusher: the pusher plate; by default Table II's, with the object's pusher mass
        (30 g for the cube, 40 g for the wedge).
    armature [kg·m²], damping [N·m·s/rad]: per joint; None uses the arm's defaults.
    gravity [m/s²]: its magnitude; 0 turns it off for arm and ground loads alike.
    friction_field: μ(p)/μ_g over the table, a
        :class:`~pushctl.contact.ground_field.FrictionField`; None: μ_g everywhere.
    """
    config = WorldConfig(
        dt=dt, mu_ground=mu_ground, mu_contact=mu_contact, substeps=substeps, gravity=gravity
    )
    if isinstance(object, ObjectSpec):
        spec = object if object_mass is None else with_masses(object, mass=object_mass)
    else:
        spec = resolve_object(object, mass=object_mass)
    if arm is None:
        return World(spec, None, config, friction_field)
    if pusher is None:
        pusher = PusherConfig(mass=spec.pusher_mass)
    arm_config = ArmConfig(
        name=arm,
        armature=None if armature is None else tuple(armature),
        damping=None if damping is None else tuple(damping),
        pusher=pusher,
    )
    arm_model = load_arm(arm_config)
    arm_model.set_gravity(gravity)
    return World(spec, arm_model, config, friction_field)


__all__ = ["make_world"]

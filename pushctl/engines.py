"""``make_world``: the one call that puts an arm, a pusher and an object on the table, in
either physics engine: our box-friction MLCP world (:mod:`pushctl.contact`) or MuJoCo
(:mod:`pushctl.mujoco`, loaded only when asked for). Both engines sit below this module;
neither imports the other."""

from __future__ import annotations

from typing import TYPE_CHECKING

from pushctl.arm import ArmConfig, ArmModel, load_arm
from pushctl.config import GRAVITY, PusherConfig
from pushctl.contact.ground_field import FrictionField
from pushctl.contact.world import World
from pushctl.contact.world_config import MAX_SLIP_ITERATIONS, WorldConfig
from pushctl.errors import ConfigError
from pushctl.objects import ObjectSpec, resolve_object, with_masses

if TYPE_CHECKING:
    from pushctl.mujoco import MujocoWorld

ENGINES = ("ours", "mujoco")
"""Physics engines of :func:`make_world`: our box-friction MLCP world, or MuJoCo."""


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
    engine: str = "ours",
    slip_iterations: int = MAX_SLIP_ITERATIONS,
    friction_model: str = "slip_box",
    facets: int = 8,
) -> World | MujocoWorld:
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
    engine: ``ours`` (default: the box-friction MLCP world, a :class:`World`) or ``mujoco``
        (the same scene in MuJoCo, a :class:`pushctl.mujoco.MujocoWorld`, same interface;
        ``substeps`` are then MuJoCo steps per ``dt``; see docs/mujoco.md).
    slip_iterations: re-solves of a step for its ground friction directions (our engine;
        see :class:`WorldConfig`). The default, 6, is what ``results/`` was made with.
    friction_model, facets: the ground friction model of our engine (``slip_box``, the
        default and what ``results/`` was made with; ``polygon`` with ``facets`` sides;
        ``axis_box``; see :class:`WorldConfig`). MuJoCo accepts only the default.
    """
    if engine not in ENGINES:
        raise ConfigError(f"unknown engine {engine!r}; choose one of {', '.join(ENGINES)}")
    config = WorldConfig(
        dt=dt,
        mu_ground=mu_ground,
        mu_contact=mu_contact,
        substeps=substeps,
        gravity=gravity,
        slip_iterations=slip_iterations,
        friction_model=friction_model,
        facets=facets,
    )
    if isinstance(object, ObjectSpec):
        spec = object if object_mass is None else with_masses(object, mass=object_mass)
    else:
        spec = resolve_object(object, mass=object_mass)
    if arm is None:
        return _build(engine, spec, None, config, friction_field)
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
    return _build(engine, spec, arm_model, config, friction_field)


def _build(
    engine: str,
    spec: ObjectSpec,
    arm: ArmModel | None,
    config: WorldConfig,
    friction_field: FrictionField | None,
) -> World | MujocoWorld:
    """The world of ``engine`` with ``config``'s parameters (MuJoCo: its substeps as
    MuJoCo steps per dt, its other settings the measured defaults; its ground friction is
    uniform, so a ``friction_field`` is refused there)."""
    if engine == "mujoco":
        if config.friction_model != "slip_box":
            raise ConfigError(
                f"friction_model {config.friction_model!r} is not available on the mujoco "
                "engine; accepted there: slip_box (MuJoCo's own friction)"
            )
        if friction_field is not None:
            raise ConfigError(
                "a ground friction field is not available on the mujoco engine; "
                "accepted there: uniform mu_ground (friction_field=None)"
            )
        # imported here: MuJoCo is loaded only when asked for
        from pushctl.mujoco import MujocoSettings, MujocoWorld, MujocoWorldConfig

        settings = MujocoSettings(config.substeps)
        mj_config = MujocoWorldConfig(
            config.dt, config.mu_ground, config.mu_contact, config.gravity, settings
        )
        return MujocoWorld(spec, arm, mj_config)
    return World(spec, arm, config, friction_field)


__all__ = ["ENGINES", "make_world"]

"""What an :class:`~pushctl.episode.runner.Episode` builds before its world: the nominal
plan the controller follows, the plant's object and pusher (the scenario's true parameters
and plant unknowns), and the prong forces that plant needs to follow the plan."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from pushctl.arm import ArmConfig, ArmModel, load_arm
from pushctl.config import PusherConfig
from pushctl.contact.ground_field import FrictionField
from pushctl.episode.scenario import Scenario
from pushctl.episode.unknowns import PlantUnknowns, friction_limits, with_unknown_loads
from pushctl.objects import ObjectSpec, resolve_object
from pushctl.planning import ForcePlan, ForceSettings, Plan, make_plan
from pushctl.planning.forces import distribute_forces


def nominal_plan(scenario: Scenario) -> Plan:
    """The scenario's plan, made with its nominal parameters (the controller's belief)."""
    nominal = scenario.nominal
    obj = resolve_object(
        scenario.object, mass=nominal.object_mass, pusher_mass=scenario.pusher_mass(nominal)
    )
    pusher = scenario.pusher_config(obj.pusher_mass)
    return make_plan(
        obj,
        scenario.goal.as_array(),
        start=None if scenario.start is None else scenario.start.as_array(),
        profile=scenario.profile,
        duration=scenario.duration,
        dt=scenario.dt,
        forces=ForceSettings(mu_contact=nominal.mu_contact, mu_ground=nominal.mu_ground),
        arm=load_arm(ArmConfig(name=scenario.arm, pusher=pusher)),
        gravity=scenario.gravity,
    )


def plant_object(scenario: Scenario, unknowns: PlantUnknowns) -> ObjectSpec:
    """The pushed object as the plant has it: true masses and the unknowns' support loads."""
    plant = scenario.true_parameters
    obj = resolve_object(
        scenario.object, mass=plant.object_mass, pusher_mass=scenario.pusher_mass(plant)
    )
    return with_unknown_loads(obj, unknowns)


def true_pusher(scenario: Scenario, mass: float, unknowns: PlantUnknowns) -> PusherConfig:
    """The plate of ``mass`` [kg] as mounted: with the unknowns' mounting error, if any."""
    pusher = scenario.pusher_config(mass)
    if not unknowns.has_mounting_error:
        return pusher
    return replace(
        pusher,
        mount_yaw=unknowns.mount_yaw,
        prong_errors=unknowns.prong_errors_for(pusher.n_prongs),
    )


def plant_friction_limits(
    obj: ObjectSpec, scenario: Scenario, field: FrictionField | None, plan: Plan
) -> np.ndarray | None:
    """Each support point's sliding friction at every sample of the plan (N, S) [N] under
    the plant's friction ``field`` (None: uniform μ_g, and None is returned)."""
    if field is None:
        return None
    mu_ground = scenario.true_parameters.mu_ground
    return friction_limits(obj, mu_ground, field, plan.trajectory.pose, scenario.gravity)


def needed_forces(
    scenario: Scenario,
    plan: Plan,
    obj: ObjectSpec,
    pusher: PusherConfig,
    limits: np.ndarray | None,
    shift: float,
) -> ForcePlan:
    """The prong forces the plant (``obj``, ``pusher`` as mounted, the support points'
    friction ``limits``) needs to follow ``plan``, with the plate ``shift`` [m] across the
    face from the plan's plate offset (docs/design.md §7's F_des)."""
    plant = scenario.true_parameters
    return distribute_forces(
        plan.trajectory,
        obj,
        pusher.prong_points()[:, 1],
        ForceSettings(mu_contact=plant.mu_contact, mu_ground=plant.mu_ground),
        scenario.gravity,
        offset=plan.forces.offset + shift,
        friction_limits=limits,
    )


def believed_arm(world_arm: ArmModel, scenario: Scenario, pusher: PusherConfig) -> ArmModel:
    """The controller's model of the arm: ``world_arm`` itself, or with ``pusher`` mounted
    other than the controller believes, a copy with the nominal pusher (same mass)."""
    if pusher == pusher.nominal:
        return world_arm
    nominal = load_arm(ArmConfig(name=scenario.arm, pusher=pusher.nominal))
    nominal.set_gravity(scenario.gravity)
    return nominal

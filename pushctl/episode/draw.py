"""Scenarios drawn from a seed: a goal from the target ranges, the plant's parameters from a
plant's ranges, redrawn until the planner accepts the goal (docs/design.md §7)."""

from __future__ import annotations

from dataclasses import replace

from pushctl.arm import ArmConfig, load_arm
from pushctl.config import GRAVITY, PusherConfig
from pushctl.episode.ranges import Randomisation, load_ranges
from pushctl.episode.scenario import STREAMS, PhysicalParameters, Scenario, stream_rng
from pushctl.episode.unknowns import NO_UNKNOWNS, unknowns_rng
from pushctl.errors import PlanError
from pushctl.objects import resolve_object
from pushctl.planning import ForceSettings, Plan, make_plan
from pushctl.planning.workspace import default_start

MAX_DRAWS = 100
"""Goals drawn for one scenario before giving up (the evaluation ranges are all feasible
for the nominal parameters in the planner's sweeps; this only guards custom ranges)."""


def draw_scenario(
    seed: int,
    stream: str,
    object_name: str,
    profile: str,
    **options,
) -> tuple[Scenario, int]:
    """The scenario of ``seed`` in ``stream`` and how many goals were redrawn (the options
    and the draw as in :func:`draw_planned_scenario`)."""
    scenario, redrawn, _ = draw_planned_scenario(seed, stream, object_name, profile, **options)
    return scenario, redrawn


def draw_planned_scenario(
    seed: int,
    stream: str,
    object_name: str,
    profile: str,
    *,
    plant: str | None = None,
    ranges: Randomisation | None = None,
    nominal: PhysicalParameters | None = None,
    arm: str = "kinova-gen2-7dof",
    duration: float = 20.0,
    dt: float = 0.01,
    gravity: float = GRAVITY,
    pusher: PusherConfig | None = None,
) -> tuple[Scenario, int, Plan]:
    """The scenario of ``seed`` in ``stream``, how many goals were redrawn, and its plan
    (made with the nominal parameters, as :class:`~pushctl.episode.runner.Episode` makes it).

    Each attempt draws, in this order, a goal (4 uniforms) and a plant (4 uniforms), so the
    goals of one seed are the same whether or not, and from whichever ranges, the plant is
    randomised (and the sim and proxy plants of one seed use the same uniforms). ``plant`` None:
    the world gets the ``nominal`` parameters; ``"sim"`` or ``"proxy"``: the drawn ones, and
    plant unknowns drawn from that plant's ranges with their own generator
    (:func:`~pushctl.episode.unknowns.unknowns_rng`), so the goals and parameters above are
    the same with or without them.
    A goal the planner (with the nominal parameters) cannot execute is redrawn; PlanError
    after :data:`MAX_DRAWS` attempts. ``pusher``: the scenario's plate and prongs (None: the
    paper's); its mass stands for the object's Table II pusher mass where ``nominal`` leaves
    it None (the plant's pusher mass is drawn as a multiple of it).
    """
    ranges = ranges if ranges is not None else load_ranges()
    nominal = nominal if nominal is not None else PhysicalParameters()
    plant_ranges = ranges.plant(plant) if plant is not None else None
    rng = stream_rng(seed, stream)
    if nominal.pusher_mass is None and pusher is not None:
        nominal = replace(nominal, pusher_mass=pusher.mass)
    obj = resolve_object(object_name, mass=nominal.object_mass, pusher_mass=nominal.pusher_mass)
    plate = replace(pusher or PusherConfig(), mass=obj.pusher_mass)
    arm_model = load_arm(ArmConfig(name=arm, pusher=plate))
    start = default_start(obj, arm_model.ready_pusher_position)
    settings = ForceSettings(mu_contact=nominal.mu_contact, mu_ground=nominal.mu_ground)
    unknowns = NO_UNKNOWNS
    if plant is not None:
        unknowns = ranges.unknowns(plant).draw(unknowns_rng(seed, STREAMS[stream]))
    reason = ""
    for attempt in range(MAX_DRAWS):
        goal = ranges.targets.draw(rng, start)
        # Always four draws (uniforms, whatever the range), randomised or not.
        drawn = (plant_ranges or ranges.sim).draw(rng, obj.mass, obj.pusher_mass)
        plan = make_plan(
            obj,
            goal.as_array(),
            start=start.as_array(),
            profile=profile,
            duration=duration,
            dt=dt,
            forces=settings,
            arm=arm_model,
            gravity=gravity,
        )
        if plan.feasible:
            scenario = Scenario(
                object=object_name,
                profile=profile,
                goal=goal,
                start=start,
                true_parameters=drawn if plant_ranges is not None else nominal,
                nominal=nominal,
                seed=seed,
                duration=duration,
                dt=dt,
                arm=arm,
                gravity=gravity,
                unknowns=unknowns,
                pusher=pusher,
            )
            return scenario, attempt, plan
        reason = plan.problems[0]
    raise PlanError(
        f"no feasible goal in {MAX_DRAWS} draws of seed {seed} ({object_name}, {profile}); "
        f"the last: {reason}"
    )

"""``pushctl simulate`` and ``pushctl tune-pd``: scenario from options, tables for the
terminal. The commands are in
:mod:`pushctl.cli.simulate` and :mod:`pushctl.cli.tune_pd`."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path

from rich.table import Table

from pushctl.config import PusherConfig
from pushctl.control.gains import PDGains, gains_toml
from pushctl.episode.draw import draw_scenario
from pushctl.episode.metrics import METRIC_UNITS, EpisodeMetrics
from pushctl.episode.ranges import PLANTS
from pushctl.episode.scenario import PhysicalParameters, Scenario
from pushctl.episode.trace import Trace
from pushctl.episode.unknowns import PlantUnknowns
from pushctl.errors import ConfigError
from pushctl.evaluation.tune_pd import BOUNDS, GRID, Candidate
from pushctl.files.provenance import provenance_line
from pushctl.objects import resolve_object
from pushctl.planning import Plan
from pushctl.planning.profiles import PROFILE_NAMES
from pushctl.types import PlanarPose


def check_controller(name: str) -> None:
    """ConfigError (one line, naming those accepted) unless ``name`` is registered."""
    from pushctl.controllers import controller_entry

    controller_entry(name)


def push(
    scenario: Scenario,
    controller: str,
    gains: PDGains,
    policy: Path | None = None,
    plant: str = "sim",
) -> tuple[Trace, Plan]:
    """Run ``scenario`` with the registered ``controller`` on ``plant``; the trace and the
    plan, through the evaluation's driver (:func:`~pushctl.controllers.drive.push_scenario`).
    A controller that pushes with a policy (``rl``) takes the one at ``policy`` (default:
    the shipped one) and the settings it was trained with; the others today's defaults (the
    feedback law its own residual settings and ``pushctl/defaults/feedback_gains.toml``)."""
    from pushctl.controllers import PushSetup, controller_entry
    from pushctl.controllers.drive import push_scenario

    entry = controller_entry(controller)
    check_plant(plant)
    # torch loads only for a controller that pushes with a policy
    policies: tuple = ()
    if entry.needs_policy:
        from pushctl.evaluation.evaluate import DEFAULT_POLICY, load_evaluation_policy

        trained = load_evaluation_policy(policy if policy is not None else DEFAULT_POLICY)
        config, policies = trained.env, ((trained.actor, trained.seed),)
    else:
        from pushctl.task.env_config import EnvConfig

        config = EnvConfig()
    own = {} if entry.load_gains is None else {controller: entry.load_gains()}
    # the evaluation stream, as simulate's scenarios (a given scenario draws nothing)
    setup = PushSetup(replace(config, plant=plant, stream="evaluation"), gains, policies, own)
    return push_scenario(controller, scenario, setup)


def check_pusher(pusher: PusherConfig | None, controller: str) -> None:
    """ConfigError for a controller that pushes with the paper's pusher only (``rl``) with
    another: a policy is trained for one pusher (its observation has a row per prong)."""
    if pusher is not None and pusher != PusherConfig():
        from pushctl.evaluation.trials import check_pusher as check_all

        check_all((controller,))


def check_plant(name: str) -> None:
    if name not in PLANTS:
        raise ConfigError(f"unknown plant {name!r}; accepted: {', '.join(PLANTS)}")


def check_profile(name: str) -> None:
    if name not in PROFILE_NAMES:
        raise ConfigError(f"unknown profile {name!r}; accepted: {', '.join(PROFILE_NAMES)}")


def simulate_scenario(
    object_name: str,
    profile: str,
    goal: tuple[float, float, float] | None,
    seed: int | None,
    randomize: bool,
    overrides: Mapping[str, float | None],
    duration: float,
    arm: str,
    plant: str = "sim",
    pusher: PusherConfig | None = None,
) -> tuple[Scenario, int]:
    """The scenario ``pushctl simulate`` runs and the goals redrawn to find it.

    The goal is ``goal`` if given, else drawn from ``seed`` (evaluation stream). With
    ``randomize`` the plant is drawn from ``plant``'s ranges of ``seed`` (mujoco: sim's).
    ``overrides`` (mu_ground, mu_contact, object_mass; None = keep) then set plant values by hand.
    ``pusher``: the scenario's plate and prongs (None: the paper's).
    """
    check_profile(profile)
    if seed is not None and seed < 0:
        raise ConfigError(f"--scenario must be an integer >= 0, got {seed}")
    if goal is None and seed is None:
        raise ConfigError(
            "give a goal (--goal x,y,theta_deg) or a scenario to draw one (--scenario N)"
        )
    if randomize and seed is None:
        raise ConfigError(
            "--randomize draws the plant's parameters from --scenario; give --scenario N"
        )
    redrawn = 0
    if seed is not None:
        scenario, redrawn = draw_scenario(
            seed,
            "evaluation",
            object_name,
            profile,
            plant=plant if randomize else None,
            duration=duration,
            arm=arm,
            pusher=pusher,
        )
        if goal is not None:
            scenario = replace(scenario, goal=PlanarPose.from_array(goal))
    else:
        resolve_object(object_name)  # a bad name fails here, before any planning
        assert goal is not None
        scenario = Scenario(
            object=object_name,
            profile=profile,
            goal=PlanarPose.from_array(goal),
            duration=duration,
            arm=arm,
            pusher=pusher,
        )
    given = {key: value for key, value in overrides.items() if value is not None}
    if given:
        scenario = scenario.with_true_parameters(replace(scenario.true_parameters, **given))
    return scenario, redrawn


def _plant_text(plant: PhysicalParameters, object_name: str) -> str:
    obj = resolve_object(object_name, mass=plant.object_mass, pusher_mass=plant.pusher_mass)
    return (
        f"μ_g {plant.mu_ground:.3f}, μ_c {plant.mu_contact:.3f}, object {obj.mass:.3f} kg, "
        f"pusher {obj.pusher_mass:.3f} kg"
    )


def scenario_table(scenario: Scenario, start: PlanarPose, redrawn: int) -> Table:
    """The set-up of one simulated episode."""
    table = Table(
        title=f"episode: {scenario.object}, {scenario.profile} profile", show_header=False
    )
    goal = scenario.goal
    table.add_row(
        "start → goal",
        f"({start.x:.3f}, {start.y:.3f}) m, {math.degrees(start.theta):.1f} deg → "
        f"({goal.x:.3f}, {goal.y:.3f}) m, {math.degrees(goal.theta):.1f} deg",
    )
    if scenario.seed is not None:
        table.add_row("seed", f"{scenario.seed} (evaluation stream; {redrawn} goals redrawn)")
    table.add_row("plant", _plant_text(scenario.true_parameters, scenario.object))
    table.add_row("planned with", _plant_text(scenario.nominal, scenario.object))
    if not scenario.unknowns.is_none:
        table.add_row("unknowns", _unknowns_text(scenario.unknowns))
    table.add_row("push", f"{scenario.duration:g} s in steps of {scenario.dt:g} s")
    return table


def _unknowns_text(unknowns: PlantUnknowns) -> str:
    """The drawn plant unknowns in mm, deg and percent (docs/design.md §9)."""
    along, across, turn = unknowns.placement
    prongs = ", ".join(f"({1e3 * a:+.2f}, {1e3 * b:+.2f})" for a, b in unknowns.prong_errors[:2])
    pressure_n, pressure_t = unknowns.pressure_offset
    return (
        f"placement {1e3 * along:+.2f} / {1e3 * across:+.2f} mm, {math.degrees(turn):+.2f} deg; "
        f"mounting yaw {math.degrees(unknowns.mount_yaw):+.2f} deg, prongs {prongs} mm; "
        f"centre of pressure {100 * pressure_n:+.1f} / {100 * pressure_t:+.1f} % of the "
        f"half-extents; ground friction ±{100 * unknowns.ground_variation:.0f} % over "
        f"{1e3 * unknowns.ground_length:.0f} mm (field seed {unknowns.ground_seed})"
    )


_LABELS = {
    "translation_error_pct": "translation error",
    "angle_error_pct": "angle error",
    "force_error": "force error vs the plant's needs (mean over steps and prongs)",
    "force_error_plan": "force error vs the nominal plan",
    "torque_error": "torque error",
    "contact_loss_fraction": "contact-loss time fraction",
    "slip_fraction": "prong-slip time fraction",
    "max_penetration": "max penetration",
    "final_position_error": "final position error",
    "final_angle_error": "final angle error",
    "angle_error_deg": "mean angle error",
}


def metrics_table(metrics: EpisodeMetrics, title: str = "metrics (push phase)") -> Table:
    """docs/design.md §7's metrics and the extra diagnostics, with units."""
    table = Table(title=title)
    table.add_column("metric")
    table.add_column("value", justify="right")
    table.add_column("unit")
    for name, value in metrics.as_dict().items():
        unit = METRIC_UNITS[name]
        if unit == "m":
            value, unit = 1e3 * value, "mm"
        elif unit == "rad":
            value, unit = math.degrees(value), "deg"
        text = "n/a (Δθ = 0)" if math.isnan(value) else f"{value:.4g}"
        table.add_row(_LABELS.get(name, name), text, unit)
    return table


def tuning_record(
    best: Candidate,
    candidates: list[Candidate],
    seed: int,
    per_case: int,
    objects: tuple[str, ...],
    profiles: tuple[str, ...],
    duration: float,
    redrawn: int,
    command: str,
) -> str:
    """The gains file ``pushctl tune-pd`` writes: provenance, ``[pd]``, and ``[search]``
    recording the tuning set, the procedure and every candidate (K_p, K_v, K_x, objective)."""
    search: dict[str, object] = {
        "procedure": "grid then coordinate refinement (pushctl.evaluation.tune_pd)",
        "objective": "mean over the tuning set of translation error % + angle error %",
        "stream": "tuning",
        "seed": seed,
        "per_case": per_case,
        "objects": list(objects),
        "profiles": list(profiles),
        "plant": "sim ranges (pushctl/defaults/randomisation.toml)",
        "duration": duration,
        "goals_redrawn": redrawn,
        "candidates_evaluated": len(candidates),
        "best_objective": best.objective,
        "best_translation_error_pct": best.translation_error_pct,
        "best_angle_error_pct": best.angle_error_pct,
        "grid_kp": list(GRID["kp"]),
        "grid_kv": list(GRID["kv"]),
        "grid_kx": list(GRID["kx"]),
        "bounds_kp": list(BOUNDS["kp"]),
        "bounds_kv": list(BOUNDS["kv"]),
        "bounds_kx": list(BOUNDS["kx"]),
        "candidates_kp_kv_kx_objective": [
            [c.gains.kp, c.gains.kv, c.gains.kx_linear, c.objective] for c in candidates
        ],
    }
    header = provenance_line(command).removeprefix("# ")
    header += "\nPD gains of the baseline (docs/design.md §5). Regenerate with the command above."
    return gains_toml(best.gains, header, search)

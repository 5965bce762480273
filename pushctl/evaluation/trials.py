"""The evaluation's trials (docs/design.md §7): which scenarios run, and one paired trial (the
CSV columns, ``TRIAL_COLUMNS`` and ``STEP_COLUMNS``, are in :mod:`pushctl.evaluation.columns`).

Trial i of every object × profile cell of an evaluation with seed S pushes the scenario of
seed ``S * SEEDS_PER_EVALUATION + i`` in the *evaluation* stream (training and tuning draw
from their own streams, so no trial was ever trained or tuned on). Trials must number at
most :data:`SEEDS_PER_EVALUATION`, so two evaluation seeds never share a scenario; seed 0's
trial i is ``pushctl simulate --seed i``'s scenario. The draw
(:func:`~pushctl.episode.draw.draw_planned_scenario`) redraws goals the planner finds
infeasible and counts them. The ``sim`` and ``proxy`` plants of one trial use the same seed:
the same goal, their parameters from the same uniforms scaled to each plant's ranges.

Paired: the controllers (PD-only, feedback, RL-assisted, any registered one) push the same
scenario with the same plan (and, on the proxy, the same camera noise), one after the other,
through :func:`~pushctl.controllers.drive.push_controllers`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pushctl.config import PusherConfig
from pushctl.controllers import (
    Controller,
    controller_entry,
    controller_names,
    entries,
    paper_controllers,
)
from pushctl.controllers.drive import push_controllers, reset
from pushctl.episode.draw import draw_planned_scenario
from pushctl.episode.landed import landed_force_error
from pushctl.episode.metrics import compute_metrics
from pushctl.episode.ranges import DEFAULT_PLANTS, PLANTS
from pushctl.episode.trace import Trace
from pushctl.errors import ConfigError
from pushctl.objects import OBJECT_NAMES, resolve_object
from pushctl.planning import PROFILE_NAMES
from pushctl.task.env import PushEnv

SEEDS_PER_EVALUATION = 100_000
"""Scenario seeds reserved for one evaluation seed: S × this + trial."""

STREAMS_EVALUATED = ("evaluation", "tuning")
"""The random streams an evaluation may draw from (never ``training``'s)."""


@dataclass(frozen=True)
class TrialSpec:
    """Which trials run: distinct names from :data:`OBJECT_NAMES`, :data:`PROFILE_NAMES`,
    :data:`PLANTS` and the registered controllers (default: the paper's three; the outputs
    keep the order given), ``trials`` per object × profile (1 … :data:`SEEDS_PER_EVALUATION`)
    and the evaluation ``seed`` >= 0.
    An object may also be a TOML object file (``experiments/objects/hexagon.toml``).
    ``pusher``: the plate and prongs of every trial (a pusher file's; None: the paper's),
    for controllers that push with any pusher only (a policy was trained for the paper's).
    ``stream``: where the scenarios are drawn: ``evaluation`` (the held-out targets), or
    ``tuning`` for looking around (other pushers and shapes, gains) without touching them.
    ConfigError (one line) for anything else."""

    objects: tuple[str, ...] = OBJECT_NAMES
    profiles: tuple[str, ...] = PROFILE_NAMES
    plants: tuple[str, ...] = DEFAULT_PLANTS
    controllers: tuple[str, ...] = field(default_factory=paper_controllers)
    trials: int = 50
    seed: int = 0
    pusher: PusherConfig | None = None
    stream: str = "evaluation"

    def __post_init__(self) -> None:
        if self.stream not in STREAMS_EVALUATED:
            raise ConfigError(
                f"unknown --stream {self.stream!r}; accepted: {', '.join(STREAMS_EVALUATED)}"
            )
        for name in self.objects:
            if name not in OBJECT_NAMES and name.lower().endswith(".toml"):
                resolve_object(name)  # a bad file fails here, naming itself
        files = tuple(name for name in self.objects if name.lower().endswith(".toml"))
        for option, chosen, accepted in (
            ("object", self.objects, OBJECT_NAMES + files),
            ("profile", self.profiles, PROFILE_NAMES),
            ("plant", self.plants, PLANTS),
            ("controller", self.controllers, controller_names()),
        ):
            bad = [name for name in chosen if name not in accepted]
            if bad or not chosen:
                raise ConfigError(
                    f"unknown {option} {bad[0] if bad else '(none)'!r}; "
                    f"accepted: {', '.join(accepted)}"
                )
            if len(set(chosen)) < len(chosen):
                raise ConfigError(f"each {option} may be named once, got {', '.join(chosen)}")
        if not _is_int(self.trials) or not 1 <= self.trials <= SEEDS_PER_EVALUATION:
            raise ConfigError(
                f"--trials must be an integer in 1 … {SEEDS_PER_EVALUATION}, got {self.trials!r}"
            )
        if not _is_int(self.seed) or self.seed < 0:
            raise ConfigError(f"--seed must be an integer >= 0, got {self.seed!r}")
        if self.pusher is not None and self.pusher != PusherConfig():
            check_pusher(self.controllers)

    def scenario_seed(self, trial: int) -> int:
        """The evaluation-stream seed of trial ``trial`` (the same in every cell and plant)."""
        return self.seed * SEEDS_PER_EVALUATION + trial

    def jobs(self) -> list[Job]:
        """One job per object, profile, plant and trial (nested in that order): the
        controllers of one trial on one plant."""
        return [
            Job(obj, profile, plant, trial, self.scenario_seed(trial))
            for obj in self.objects
            for profile in self.profiles
            for plant in self.plants
            for trial in range(self.trials)
        ]

    @property
    def n_episodes(self) -> int:
        return (
            len(self.objects)
            * len(self.profiles)
            * len(self.plants)
            * self.trials
            * len(self.controllers)
        )


@dataclass(frozen=True)
class Job:
    """One trial on one plant."""

    object: str
    profile: str
    plant: str
    trial: int
    seed: int


@dataclass(frozen=True)
class TrialResult:
    """What one job leaves: a ``trials.csv`` row per controller (keys ``TRIAL_COLUMNS``
    then the metrics), and per controller the per-step quantities (N+1, 8) in the order of
    ``STEP_COLUMNS``; ``t`` (N+1,) [s]; ``redrawn`` goals before this one."""

    job: Job
    rows: tuple[dict[str, Any], ...]
    steps: dict[str, np.ndarray]
    t: np.ndarray
    redrawn: int


def run_trial(
    env: PushEnv,
    controllers: Mapping[str, Controller],
    job: Job,
    pusher: PusherConfig | None = None,
) -> TrialResult:
    """Run ``controllers`` (built from the registry) on ``job``'s scenario, paired.

    ``env``: a :class:`PushEnv` on the evaluation stream with ``job.plant``'s ranges (it
    draws and plans; a policy pushes in it); every controller pushes from its reset
    (:func:`~pushctl.controllers.drive.push_controllers`). The reset draws the scenario
    whichever controllers run, so each one's rows are the same with and without the
    others. A controller with several runs (one per policy) adds a row per run, and its
    per-step quantities are their mean. ``pusher``: the trial's plate and prongs (None: the
    paper's); the scenario of ``job.seed`` is then drawn here as the environment would draw
    it, with that pusher.
    """
    options: dict[str, Any] = {
        "object": job.object, "profile": job.profile, "scenario_seed": job.seed
    }  # fmt: skip
    redrawn = None
    if pusher is not None:
        config = env.config
        scenario, redrawn, _ = draw_planned_scenario(
            job.seed, config.stream, job.object, job.profile,
            plant=config.plant, duration=config.duration, dt=config.dt, pusher=pusher,
        )  # fmt: skip
        options = {"scenario": scenario}
    start = reset(env, options)
    runs = push_controllers(controllers, start)
    redrawn = start.redrawn if redrawn is None else redrawn
    rows, steps = [], {}
    for name in (name for name in controller_names() if name in runs):
        for run in runs[name]:
            rows.append(_row(env, job, name, redrawn, run.gate_share, run.trace, run.policy_seed))
        quantities = [step_quantities(run.trace) for run in runs[name]]
        steps[name] = quantities[0] if len(quantities) == 1 else np.mean(quantities, axis=0)
    t = next(iter(runs.values()))[0].trace.t
    return TrialResult(job, tuple(rows), steps, np.asarray(t, dtype=float), redrawn)


def check_pusher(controllers: tuple[str, ...]) -> None:
    """ConfigError for a pusher other than the paper's with a controller that pushes with
    the paper's only (a policy's observation has a row per prong)."""
    bound = [entry.name for entry in entries(controllers) if not entry.any_pusher]
    if bound:
        free = [entry.name for entry in entries() if entry.any_pusher]
        raise ConfigError(
            f"--pusher runs with --controller {' or '.join(free)}: the "
            f"{controller_entry(bound[0]).label} controller's policy was trained for the "
            "paper's two-prong pusher"
        )


def _row(
    env: PushEnv,
    job: Job,
    controller: str,
    redrawn: int,
    gate_share: float,
    trace: Trace,
    policy_seed: int | None = None,
) -> dict[str, Any]:
    """One ``trials.csv`` row: the job, the policy's training seed (``rl`` rows; empty
    elsewhere), the draw (goal relative to the start, world frame [m, m, rad]; the plant's
    parameters [1, 1, kg, kg]; its unknowns, ``UNKNOWN_COLUMNS``), the gate's share, where
    the prongs landed and the force error against the plant's needs there [m, N]
    (:func:`~pushctl.episode.landed.landed_force_error`), and the metrics."""
    scenario = env.scenario
    start = scenario.start
    assert start is not None  # the draw always sets the default start
    plant = scenario.true_parameters
    assert env.episode is not None
    landed_offset, force_error_landed = landed_force_error(env.episode, trace)
    return {
        "object": job.object,
        "profile": job.profile,
        "plant": job.plant,
        "controller": controller,
        "trial": job.trial,
        "seed": job.seed,
        "policy_seed": policy_seed,
        "redrawn": redrawn,
        "goal_dx": scenario.goal.x - start.x,
        "goal_dy": scenario.goal.y - start.y,
        "goal_dtheta": scenario.goal.theta - start.theta,
        "mu_ground": plant.mu_ground,
        "mu_contact": plant.mu_contact,
        "object_mass": plant.object_mass,
        "pusher_mass": plant.pusher_mass,
        **scenario.unknowns.as_dict(n_prongs=2),
        "gate_open_fraction": gate_share,
        "landed_offset": landed_offset,
        "force_error_landed": force_error_landed,
        **compute_metrics(trace).as_dict(),
    }


def step_quantities(trace: Trace) -> np.ndarray:
    """The per-step quantities of ``STEP_COLUMNS``, (N+1, 8), rows t = 0 … T.

    Distances [mm] and angles [deg] are from the *planned* start pose (row 0 of the desired
    pose); angles are multiplied by sign(Δθ of the plan), so pushes turning either way
    average. The object pose is the camera's where the trace has one (the proxy), as in
    the metrics. Force error [N]: mean over prongs of ‖F_des,i − λ_i‖; torque error [N·m]:
    |τ_des − τ|.
    """
    seen = trace.object_pose if trace.measured_pose is None else trace.measured_pose
    pose = np.asarray(seen, dtype=float)
    desired = np.asarray(trace.desired_pose, dtype=float)
    start = desired[0]
    sign = -1.0 if trace.delta_theta < 0.0 else 1.0
    forces = np.asarray(trace.contact_forces, dtype=float)
    forces_des = np.asarray(trace.desired_forces, dtype=float)
    columns = (
        1e3 * np.linalg.norm(desired[:, :2] - start[:2], axis=1),
        1e3 * np.linalg.norm(pose[:, :2] - start[:2], axis=1),
        np.degrees(sign * (desired[:, 2] - start[2])) + 0.0,  # + 0.0: no "-0" in the CSV
        np.degrees(sign * (pose[:, 2] - start[2])) + 0.0,
        1e3 * np.linalg.norm(pose[:, :2] - desired[:, :2], axis=1),
        np.degrees(np.abs(pose[:, 2] - desired[:, 2])),
        np.linalg.norm(forces_des - forces, axis=2).mean(axis=1),
        np.abs(np.asarray(trace.desired_torque) - np.asarray(trace.contact_torque)),
    )
    return np.column_stack(columns)


def _is_int(value: object) -> bool:
    return isinstance(value, (int, np.integer)) and not isinstance(value, bool)

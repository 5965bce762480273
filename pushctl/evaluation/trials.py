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

Paired: PD-only, feedback and RL-assisted push the same scenario with the same plan (and, on
the proxy, the same camera noise), one after the other.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from pushctl.config import PusherConfig
from pushctl.control.feedback import FeedbackGains
from pushctl.episode.draw import draw_planned_scenario
from pushctl.episode.landed import landed_force_error
from pushctl.episode.metrics import compute_metrics
from pushctl.episode.ranges import DEFAULT_PLANTS, PLANTS
from pushctl.episode.trace import Trace
from pushctl.errors import ConfigError
from pushctl.evaluation.controllers import CONTROLLERS, FeedbackActor
from pushctl.objects import OBJECT_NAMES, resolve_object
from pushctl.planning import PROFILE_NAMES
from pushctl.rl.networks import ActorPolicy
from pushctl.rl.policy import finish_with_policy, pd_only_episode
from pushctl.task.env import PushEnv

SEEDS_PER_EVALUATION = 100_000
"""Scenario seeds reserved for one evaluation seed: S × this + trial."""

STREAMS_EVALUATED = ("evaluation", "tuning")
"""The random streams an evaluation may draw from (never ``training``'s)."""


@dataclass(frozen=True)
class TrialSpec:
    """Which trials run: distinct names from :data:`OBJECT_NAMES`, :data:`PROFILE_NAMES`,
    :data:`PLANTS` and :data:`CONTROLLERS` (the outputs keep the order given), ``trials``
    per object × profile (1 … :data:`SEEDS_PER_EVALUATION`) and the evaluation ``seed`` >= 0.
    An object may also be a TOML object file (``experiments/objects/hexagon.toml``).
    ``pusher``: the plate and prongs of every trial (a pusher file's; None: the paper's),
    for PD-only and feedback only: a policy was trained for the paper's pusher.
    ``stream``: where the scenarios are drawn: ``evaluation`` (the held-out targets), or
    ``tuning`` for looking around (other pushers and shapes, gains) without touching them.
    ConfigError (one line) for anything else."""

    objects: tuple[str, ...] = OBJECT_NAMES
    profiles: tuple[str, ...] = PROFILE_NAMES
    plants: tuple[str, ...] = DEFAULT_PLANTS
    controllers: tuple[str, ...] = CONTROLLERS
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
            ("controller", self.controllers, CONTROLLERS),
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
        if self.pusher is not None and "rl" in self.controllers and self.pusher != PusherConfig():
            raise ConfigError(
                "--pusher runs with --controller pd or feedback: the policy was trained for "
                "the paper's two-prong pusher"
            )

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
    actor: ActorPolicy | None,
    job: Job,
    controllers: tuple[str, ...],
    feedback: tuple[PushEnv, FeedbackGains] | None = None,
    policy_seed: int | None = None,
    policies: tuple[tuple[ActorPolicy, int | None], ...] | None = None,
    pusher: PusherConfig | None = None,
) -> TrialResult:
    """Run ``controllers`` (a subset of :data:`CONTROLLERS`) on ``job``'s scenario.

    ``env``: a :class:`PushEnv` on the evaluation stream with ``job.plant``'s ranges (it
    draws, plans and, for RL, pushes); ``actor``: the residual policy (None only without
    ``rl``); ``feedback``: the environment the feedback law pushes in (the same stream and
    plant, its own residual settings) and its gains (None only without ``feedback``);
    ``policy_seed``: the policy's training seed, for the ``rl`` row; ``policies``: several
    (actor, training seed) pairs instead of ``actor`` and ``policy_seed``, each pushing the
    same scenario (from a copy of the environment as the reset left it) and adding its own
    ``rl`` row; ``rl``'s per-step quantities are then their mean. The reset draws the
    scenario even when only PD runs, so PD-only's rows are the same with and without the
    others. ``pusher``: the trial's plate and prongs (None: the paper's); the scenario of
    ``job.seed`` is then drawn here as the environment would draw it, with that pusher.
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
    traces: dict[str, tuple[Trace, float]] = {}
    _, info = env.reset(options=options)
    assert env.episode is not None
    # Every controller starts from the end of the same approach: PD-only pushes from a copy
    # of the episode as the reset left it (9 % of a trial's CPU time saved; the same trace
    # as a fresh Episode's run(), tested).
    pd_episode = pd_only_episode(env) if "pd" in controllers else None
    rl_runs: list[tuple[int | None, tuple[Trace, float]]] = []
    runs = (policies or ((actor, policy_seed),)) if "rl" in controllers else ()
    # The feedback law takes the reset over (PushEnv.reset_from) where its environment
    # builds episodes as the policy's does; else it resets to the same scenario itself.
    hand_over = feedback is not None and feedback[0].episodes_differ(env) is None
    # Each further policy, and the feedback law, push from a copy of the environment as the
    # reset left it: the same episode, approach and generators as a second reset with the
    # same options (tested to the byte), without drawing, planning and approaching again.
    start = copy.deepcopy(env) if len(runs) > 1 or (runs and hand_over) else env
    if "rl" in controllers:
        for k, (one, seed) in enumerate(runs):
            if one is None:
                raise ConfigError("RL-assisted trials need a policy")
            pushing = env if start is env or k == 0 else copy.deepcopy(start)
            rl_runs.append((seed, _push_with(pushing, one)))
        traces["rl"] = rl_runs[0][1]
    if "feedback" in controllers:
        if feedback is None:
            raise ConfigError("feedback trials need the feedback law's gains")
        feedback_env, gains = feedback
        if hand_over:
            feedback_env.reset_from(start, int(info["goals_redrawn"]))
        else:
            feedback_env.reset(options=options)  # the same scenario: the options fix the draw
        traces["feedback"] = _push_with(feedback_env, FeedbackActor(feedback_env, gains))
    if pd_episode is not None:
        traces["pd"] = (pd_episode.finish(), 0.0)
    redrawn = int(info["goals_redrawn"]) if redrawn is None else redrawn
    rows, steps = [], {}
    for controller in CONTROLLERS:
        if controller == "rl" and rl_runs:
            for seed, (trace, gate_share) in rl_runs:
                rows.append(_row(env, job, "rl", redrawn, gate_share, trace, seed))
            steps["rl"] = np.mean([step_quantities(run[0]) for _, run in rl_runs], axis=0)
        elif controller in traces:
            trace, gate_share = traces[controller]
            rows.append(_row(env, job, controller, redrawn, gate_share, trace))
            steps[controller] = step_quantities(trace)
    t = next(iter(traces.values()))[0].t
    return TrialResult(job, tuple(rows), steps, np.asarray(t, dtype=float), redrawn)


def _push_with(env: PushEnv, actor: Callable[[np.ndarray], np.ndarray]) -> tuple[Trace, float]:
    """The push of the episode ``env`` was just reset to, with the deterministic ``actor``
    (a policy or the feedback law), and the share of its steps the gate was open."""
    assert env.episode is not None
    opened = finish_with_policy(env, actor)
    return env.episode.trace(), opened / max(env.episode.n_steps, 1)


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

"""One training episode: the residual policy (or warm-up noise) on a drawn scenario, its
transitions, and its errors beside PD-only on the same scenario.

Everything random in episode e of a run with seed s (the scenario and the exploration noise)
comes from ``SeedSequence(s, spawn_key=(e,))``, so an episode is a pure function of (s, e,
the actor's weights): it can run in another process, and a resumed run redraws exactly what
a killed run would have drawn.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from pushctl.control.feedback import FeedbackGains
from pushctl.control.gains import PDGains
from pushctl.episode.metrics import compute_metrics, force_component_errors
from pushctl.episode.trace import Trace
from pushctl.errors import ConfigError, StateError
from pushctl.rl.networks import ActorPolicy
from pushctl.rl.noise import OrnsteinUhlenbeckNoise
from pushctl.rl.policy import pd_only_episode
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.feedback_actor import FeedbackActor
from pushctl.task.vector_env import PushVectorEnv

CURVE_METRICS = (
    "force_n_error",
    "force_t_error",
    "torque_error",
    "force_error",
    "translation_error_pct",
    "angle_error_pct",
    "slip_fraction",
    "contact_loss_fraction",
)
"""Per-episode errors recorded for the training curves (Fig. 5): mean |ΔF_n|, |ΔF_t| [N]
per prong and step, mean |Δτ_z| [N·m], then docs/design.md §7's force error [N], translation and
angle error [%], and the shares of steps with a slipping prong and with a prong out of
contact (docs/design.md §6 asks for them: where PD-only never slips, the residual has little to
fix)."""


@dataclass(frozen=True)
class Behaviour:
    """How episode e acts: while ``warmup``, OU noise (θ, σ, dt) alone, or the law of
    ``demonstrator`` (the feedback controller's gains; None: no demonstrator) without noise;
    else the actor of ``actor_state`` (None only in warm-up) plus the noise."""

    warmup: bool
    actor_state: dict[str, Any] | None
    ou_theta: float
    ou_sigma: float
    ou_dt: float
    demonstrator: FeedbackGains | None = None
    privileged: bool = False
    """Record each decision's privileged rows (``priv``, ``next_priv``) for an asymmetric
    critic (:meth:`~pushctl.task.env.PushEnv.privileged_state`)."""


@dataclass(frozen=True)
class EpisodeRecord:
    """What episode ``episode`` left: its scenario's description, transitions (T rows:
    ``obs`` (T, d), ``action`` (T, 3) the policy's action as the environment applied it (0
    where the gate dropped it, also under a base law that acts at every step), ``reward``
    (T,), ``next_obs`` (T, d), ``done`` (T,)), its RL errors and, where PD-only was pushed
    too (``collect_episodes``' ``pd_only``), PD-only's (keys :data:`CURVE_METRICS`), and the
    seconds its RL push took (with its reset)."""

    episode: int
    scenario: dict[str, Any]
    transitions: dict[str, np.ndarray]
    rl: dict[str, float]
    pd: dict[str, float] | None
    gate_open_fraction: float
    episode_return: float
    seconds: float


def episode_rngs(seed: int, episode: int) -> tuple[int, np.random.Generator]:
    """The environment's reset seed and the exploration generator of ``episode``."""
    reset_seq, explore_seq = np.random.SeedSequence(seed, spawn_key=(episode,)).spawn(2)
    return int(reset_seq.generate_state(1)[0]), np.random.default_rng(explore_seq)


def collect_episode(
    env_config: EnvConfig,
    gains: PDGains,
    seed: int,
    episode: int,
    behaviour: Behaviour,
    env: PushEnv | None = None,
) -> EpisodeRecord:
    """Run episode ``episode`` of the run with ``seed`` (see the module docstring); its
    record's ``pd`` is None (PD-only beside it: :func:`collect_episodes`' ``pd_only``).
    ``env``: one to reuse (its config must be ``env_config``). The same record as that
    episode's in any :func:`collect_episodes` batch."""
    vector = PushVectorEnv.of([env if env is not None else PushEnv(env_config, gains)])
    return collect_episodes(vector, seed, [episode], behaviour)[0]


def collect_episodes(
    vector: PushVectorEnv,
    seed: int,
    episodes: Sequence[int],
    behaviour: Behaviour,
    pd_only: Sequence[int] = (),
) -> list[EpisodeRecord]:
    """Run the ``episodes`` of the run with ``seed`` together in ``vector`` (one
    sub-environment each: ``vector.num_envs == len(episodes)``), one batched actor forward
    per step for all of them; their records, in order, each the same bit for bit as when
    the episode runs alone (:meth:`ActorPolicy.batch`, one noise generator per episode).

    The records of the episodes in ``pd_only`` also hold PD-only's errors on their scenario
    (the training curves' comparison, Fig. 5): a copy of the episode as its reset left it,
    pushed by the PD alone after the RL episode, bit for bit :func:`pd_only_metrics`
    without its second reset (draw, plan, plant force plan, approach: about half a
    PD-only push's time)."""
    started = time.perf_counter()
    if vector.num_envs != len(episodes):
        raise ConfigError(
            f"{len(episodes)} episodes need as many environments, got {vector.num_envs}"
        )
    draws = [episode_rngs(seed, e) for e in episodes]
    obs, _ = vector.reset(seed=[reset_seed for reset_seed, _ in draws])
    pd_pushes = {
        i: pd_only_episode(env) for i, env in enumerate(vector.envs) if episodes[i] in pd_only
    }
    act = _acting(behaviour, [rng for _, rng in draws], vector.envs)
    lengths = {env.episode.n_steps for env in vector.envs if env.episode is not None}
    if len(lengths) != 1:  # a round's pushes share EnvConfig.duration and dt
        raise StateError(f"episodes of one batch must be equally long, got {sorted(lengths)}")
    decisions = -(-lengths.pop() // vector.config.action_repeat)  # step() holds an action
    rows = _allocate(decisions, *obs.shape)
    if behaviour.privileged:
        width = len(vector.envs[0].privileged_state())
        rows["priv"] = np.zeros((decisions, len(episodes), width), dtype=np.float32)
        rows["next_priv"] = np.zeros_like(rows["priv"])
    gate_open = np.zeros(len(episodes))
    for n in range(decisions):
        action = act(obs)
        if behaviour.privileged:
            rows["priv"][n] = [env.privileged_state() for env in vector.envs]
        next_obs, reward, terminated, _, info = vector.step(action)
        if behaviour.privileged:
            rows["next_priv"][n] = [env.privileged_state() for env in vector.envs]
        active = info["residual_active"]
        rows["obs"][n] = obs
        rows["action"][n] = info["action_applied"]  # zeros where the gate dropped it
        rows["reward"][n] = reward
        rows["next_obs"][n] = next_obs
        rows["done"][n] = terminated
        gate_open += active
        obs = next_obs
    assert all(env.episode is not None and env.episode.done for env in vector.envs)
    seconds = (time.perf_counter() - started) / len(episodes)
    pd_metrics = {i: _curve_metrics(push.finish()) for i, push in pd_pushes.items()}
    records = []
    for i, (episode, env) in enumerate(zip(episodes, vector.envs, strict=True)):
        assert env.episode is not None
        transitions = {key: np.ascontiguousarray(value[:, i]) for key, value in rows.items()}
        records.append(
            EpisodeRecord(
                episode=episode,
                scenario=_describe(env),
                transitions=transitions,
                rl=_curve_metrics(env.episode.trace()),
                pd=pd_metrics.get(i),
                gate_open_fraction=float(gate_open[i]) / max(decisions, 1),
                episode_return=float(transitions["reward"].sum()),
                seconds=seconds,
            )
        )
    return records


def curve_row(record: EpisodeRecord) -> dict[str, Any]:
    """``record`` as a row of a run's ``curve.csv``: its episode and scenario, the RL and
    PD-only errors (``rl_*``, ``pd_*``; NaN where PD-only was not pushed), the gate's open
    share and the return."""
    row: dict[str, Any] = {"episode": record.episode, **record.scenario}
    row.update({f"rl_{name}": record.rl[name] for name in CURVE_METRICS})
    pd_metrics = record.pd or {}
    row.update({f"pd_{name}": pd_metrics.get(name, math.nan) for name in CURVE_METRICS})
    row["gate_open_fraction"] = record.gate_open_fraction
    row["episode_return"] = record.episode_return
    return row


def pd_only_metrics(env: PushEnv, seed: int, episode: int) -> dict[str, float]:
    """PD-only on the scenario and plan episode ``episode`` of the run with ``seed`` draws
    (``env`` draws, plans and approaches it: the same draw as :func:`collect_episode`'s,
    on the same plant, :func:`~pushctl.rl.policy.pd_only_episode`), as
    :data:`CURVE_METRICS`. A training run has the collector push it from the RL episode's
    reset (:func:`collect_episodes`' ``pd_only``); this is that push on its own."""
    reset_seed, _ = episode_rngs(seed, episode)
    env.reset(seed=reset_seed)
    return _curve_metrics(pd_only_episode(env).finish())


def _acting(behaviour: Behaviour, rngs: list[np.random.Generator], envs: list[PushEnv]):
    """obs (B, d) → actions (B, 3) in [−1, 1]: in warm-up the OU noise alone or the
    demonstrator's law (on each of ``envs``' pushes, just reset), else actor + noise; row
    i's noise from ``rngs[i]`` (its episode's), so a row does not depend on the others.

    Warm-up explores with the (temporally correlated) noise rather than uniform draws: a
    uniform action every 10 ms is a velocity step every step, whose force spikes are 100
    times the baseline's errors and teach the critic about a regime the actor never visits.
    """
    b = behaviour
    noises = [OrnsteinUhlenbeckNoise(3, b.ou_theta, b.ou_sigma, b.ou_dt, rng) for rng in rngs]
    if b.warmup or b.actor_state is None:
        if b.demonstrator is None:
            return lambda obs: np.stack([noise.explore(None) for noise in noises])
        # The law alone, no noise: the actor is cloned from these actions, and the noise,
        # held for action_repeat steps, is a function of time that an actor seeing the phase
        # and the forces would learn by heart from a few episodes.
        laws = [FeedbackActor(env, b.demonstrator) for env in envs]
        return lambda obs: np.stack(
            [np.clip(law(row), -1.0, 1.0) for law, row in zip(laws, obs, strict=True)]
        )
    policy = ActorPolicy.from_state(tensors(b.actor_state))

    def act(obs: np.ndarray) -> np.ndarray:
        if policy is None:
            return np.stack([noise.explore(None) for noise in noises])
        actions = policy.batch(obs)
        for row, noise in zip(actions, noises, strict=True):
            noise.explore(row)  # in place
        return actions

    return act


def portable(state: Any) -> Any:
    """Tensors → numpy arrays (nested dicts), so an actor state crosses to the collector
    process by plain pickling."""
    if isinstance(state, torch.Tensor):
        return state.numpy()
    if isinstance(state, dict):
        return {key: portable(value) for key, value in state.items()}
    return state


def tensors(state: Any) -> Any:
    """The inverse of :func:`portable`."""
    if isinstance(state, np.ndarray):
        return torch.from_numpy(state)
    if isinstance(state, dict):
        return {key: tensors(value) for key, value in state.items()}
    return state


def _allocate(steps: int, envs: int, obs_dim: int) -> dict[str, np.ndarray]:
    """Transitions of ``envs`` episodes, step-major: (steps, envs, …)."""
    return {
        "obs": np.zeros((steps, envs, obs_dim), dtype=np.float32),
        "action": np.zeros((steps, envs, 3), dtype=np.float32),
        "reward": np.zeros((steps, envs), dtype=np.float32),
        "next_obs": np.zeros((steps, envs, obs_dim), dtype=np.float32),
        "done": np.zeros((steps, envs), dtype=np.float32),
    }


def _curve_metrics(trace: Trace) -> dict[str, float]:
    metrics = compute_metrics(trace)
    normal, tangential = force_component_errors(trace)
    return {
        "force_n_error": normal,
        "force_t_error": tangential,
        "torque_error": metrics.torque_error,
        "force_error": metrics.force_error,
        "translation_error_pct": metrics.translation_error_pct,
        "angle_error_pct": metrics.angle_error_pct,
        "slip_fraction": metrics.slip_fraction,
        "contact_loss_fraction": metrics.contact_loss_fraction,
    }


def _describe(env: PushEnv) -> dict[str, Any]:
    scenario = env.scenario
    plant = scenario.true_parameters
    return {
        "object": scenario.object,
        "profile": scenario.profile,
        "scenario_seed": scenario.seed,
        "goal_x": scenario.goal.x,
        "goal_y": scenario.goal.y,
        "goal_theta_deg": float(np.degrees(scenario.goal.theta)),
        "mu_ground": plant.mu_ground,
        "mu_contact": plant.mu_contact,
        "object_mass": plant.object_mass,
        "pusher_mass": plant.pusher_mass,
    }

"""A standard learner through the same environment: stable-baselines3's SAC (Haarnoja et al.
2018) on the push environment of a preset, for comparing learners (``pushctl train --algo
sb3-sac``).

What it shares with the DDPG run of the same preset: the environment (``[env]``, every
reset from the run's seed), the budget (``[train] episodes`` × decisions per episode), the
networks' widths, γ, τ, batch and buffer sizes, the warm-up (the DDPG learner's own: whole
episodes of the ``demonstrator``'s law or of the OU noise alone, collected by
:func:`~pushctl.rl.collect.collect_episodes` into SAC's replay buffer before SAC acts; not
SB3's uniform random actions) and the updates per decision (``gradient_steps`` updates
every ``train_freq`` steps of the vector env, each ``episodes_per_round`` decisions:
:func:`sac_schedule`); the observation is divided by the same scales and the reward
multiplied by the same ``reward_scale``. The rest is SB3's SAC as it comes (a learned
entropy coefficient, one learning rate of 3e-4). It steps ``episodes_per_round``
environments in SB3's ``DummyVecEnv`` in the learner's process.

The critic's parts: SAC always has two critics and takes the smaller target (what
``twin_critics`` switches on in DDPG); its stochastic policy stands in for TD3's target
smoothing (``target_noise``, ``target_noise_clip`` do not apply) and it updates the actor at
every update (``actor_delay`` must be 1). ``n_step``, ``critic_layer_norm``,
``critic_warmup_updates``, ``privileged_critic`` and ``policy_average`` are not supported: a
preset that sets them is refused (:data:`UNSUPPORTED`). SAC's actor loss is its own, so
``prior_weight``, ``action_penalty``, ``critic_burn_in``, ``imitation_updates``, the actor's
learning rate and the OU noise after the warm-up do not apply (the log says so).

The trained actor is written as a pushctl policy (``policy.pt``: SAC's deterministic action
tanh(μ(s)) is the same ReLU MLP with a tanh output as the DDPG actor, so its weights copy
over exactly) and selected like DDPG's with the ``paired`` rule on the preset's validation
set: kept only if it beats the law beyond the CI, else the file holds the law. The SB3
model itself is ``sb3_sac.zip``; a run cannot be resumed.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import torch

from pushctl.control.feedback import load_feedback_gains
from pushctl.control.gains import PDGains, load_gains
from pushctl.errors import ConfigError
from pushctl.files.provenance import write_csv
from pushctl.rl.collect import Behaviour, collect_episodes
from pushctl.rl.config import DDPGConfig
from pushctl.rl.networks import Actor, ActorPolicy, configure_torch
from pushctl.rl.policy import write_policy
from pushctl.rl.presets import Preset
from pushctl.rl.validate import Validator, validation_metrics
from pushctl.task.env import PushEnv
from pushctl.task.spaces import observation_entries, scales
from pushctl.task.vector_env import PushVectorEnv

MODEL = "sb3_sac.zip"
"""The SB3 model in the run directory."""

UNSUPPORTED = {
    "n_step": 1,
    "critic_layer_norm": False,
    "critic_warmup_updates": 0,
    "privileged_critic": False,
    "actor_delay": 1,
    "policy_average": 0.0,
}
"""The ``[ddpg]`` settings SAC here cannot honour, with the only value it accepts."""

NOT_APPLIED = ("prior_weight", "action_penalty", "critic_burn_in", "imitation_updates")
"""``[ddpg]`` settings of DDPG's actor that SAC's own actor loss has no place for."""


def sac_schedule(updates_per_step: float, n_envs: int) -> tuple[int, int]:
    """SB3's ``(train_freq, gradient_steps)`` for ``updates_per_step`` updates per decision
    on ``n_envs`` environments: SB3 counts ``train_freq`` in steps of the vector env, each
    ``n_envs`` decisions, so ``gradient_steps / (train_freq · n_envs)`` is the rate asked for
    (exactly, as a fraction of denominator ≤ 1000: 0.3 on 2 environments is 3 updates every
    5 vector steps)."""
    ratio = Fraction(updates_per_step * n_envs).limit_denominator(1000)
    return ratio.denominator, ratio.numerator


def check_supported(ddpg: DDPGConfig) -> None:
    """ConfigError naming the settings of ``ddpg`` SAC here cannot honour."""
    asked = [f"{k} = {getattr(ddpg, k)!r}" for k, v in UNSUPPORTED.items() if getattr(ddpg, k) != v]
    if asked:
        raise ConfigError(
            f"sb3-sac does not support [ddpg] {', '.join(asked)} (SAC has two critics and its "
            "own target; no n-step returns, critic layer norm, critic warm-up, privileged "
            "critic, actor delay or averaged actor)"
        )


def sac_actor_state(model: Any, obs_scale: np.ndarray) -> dict[str, Any]:
    """SAC's deterministic actor as an :class:`~pushctl.rl.networks.ActorPolicy` state:
    the latent MLP's linear layers then μ, in the Actor's ``net`` order."""
    sb3_actor = model.policy.actor
    linears = [m for m in sb3_actor.latent_pi if isinstance(m, torch.nn.Linear)]
    linears.append(sb3_actor.mu)
    hidden = [layer.out_features for layer in linears[:-1]]
    actor = Actor(linears[0].in_features, linears[-1].out_features, hidden)
    targets = [m for m in actor.net if isinstance(m, torch.nn.Linear)]
    with torch.no_grad():
        for target, source in zip(targets, linears, strict=True):
            target.weight.copy_(source.weight)
            target.bias.copy_(source.bias)
    return ActorPolicy(actor, obs_scale).state()


def train_sac(
    preset: Preset,
    seed: int,
    out: Path,
    made_by: str,
    episodes: int | None = None,
    gains: PDGains | None = None,
    log: Callable[[str], None] = print,
) -> dict[str, Any]:
    """Train SAC on ``preset``'s environment for ``episodes`` (default the preset's) with
    ``seed``; write ``sb3_sac.zip``, ``policy_last.pt``, ``policy.pt`` and ``validation.csv``
    to ``out`` (which must not hold a run). Returns the validation rows' last."""
    from stable_baselines3 import SAC
    from stable_baselines3.common.vec_env import DummyVecEnv

    if out.exists() and any(out.iterdir()):
        raise ConfigError(f"{out} already holds a run; sb3-sac runs cannot be resumed")
    train, config, ddpg = preset.train, preset.env, preset.ddpg
    check_supported(ddpg)
    gains = gains if gains is not None else load_gains()
    entries = observation_entries(
        2, reference_offset=config.offset_observed, context=config.observe_context
    )
    obs_scale = scales(entries)
    n_envs = max(1, train.episodes_per_round)
    decisions = -(-round(config.duration / config.dt) // config.action_repeat)
    episodes = episodes or train.episodes
    total = episodes * decisions
    train_freq, gradient_steps = sac_schedule(ddpg.updates_per_step, n_envs)
    configure_torch(ddpg.torch_threads)

    def make(rank: int) -> Callable[[], Any]:
        return lambda: _scaled(PushEnv(config, gains), obs_scale, ddpg.reward_scale)

    vector = DummyVecEnv([make(rank) for rank in range(n_envs)])
    vector.seed(seed)
    model = SAC(
        "MlpPolicy",
        vector,
        gamma=ddpg.gamma,
        tau=ddpg.tau,
        batch_size=ddpg.batch_size,
        buffer_size=min(ddpg.buffer_size, total),
        learning_starts=0,  # the warm-up's transitions are in the buffer already
        train_freq=(train_freq, "step"),
        gradient_steps=gradient_steps,
        policy_kwargs={"net_arch": list(ddpg.hidden)},
        seed=seed,
        device="cpu",
        verbose=0,
    )
    ignored = [f"{k} = {getattr(ddpg, k)}" for k in NOT_APPLIED if getattr(ddpg, k)]
    if ignored:
        log(f"sb3-sac: SAC's actor loss has no place for {', '.join(ignored)}")
    warm = _warm_up(model, preset, gains, seed, obs_scale, decisions)
    log(f"sb3-sac: {total:,} decisions ({warm:,} of warm-up) on {n_envs} environments")
    model.learn(total_timesteps=max(total - warm, 0))
    out.mkdir(parents=True, exist_ok=True)
    model.save(out / MODEL)
    last = sac_actor_state(model, obs_scale)
    write_policy(out / "policy_last.pt", last, config, made_by)
    return _select(preset, gains, last, out, made_by, episodes)


def _warm_up(
    model: Any, preset: Preset, gains: PDGains, seed: int, obs_scale: np.ndarray, decisions: int
) -> int:
    """Fill ``model``'s replay buffer with the DDPG learner's warm-up: the episodes whose
    first decision falls before ``warmup_steps`` (rounded up to whole rounds of the vector
    env's size), acted by the ``demonstrator``'s law or by the OU noise alone, each from
    :func:`~pushctl.rl.collect.episode_rngs` of ``seed``. Returns the decisions stored."""
    ddpg, n_envs = preset.ddpg, model.n_envs
    episodes = -(-ddpg.warmup_steps // decisions)
    episodes = -(-episodes // n_envs) * n_envs
    demonstrator = load_feedback_gains() if ddpg.demonstrator == "feedback" else None
    behaviour = Behaviour(
        warmup=True,
        actor_state=None,
        ou_theta=ddpg.ou_theta,
        ou_sigma=ddpg.ou_sigma,
        ou_dt=ddpg.ou_dt,
        demonstrator=demonstrator,
    )
    vector = PushVectorEnv(n_envs, preset.env, gains)
    scale = np.asarray(obs_scale, dtype=np.float32)
    for first in range(0, episodes, n_envs):
        records = collect_episodes(vector, seed, range(first, first + n_envs), behaviour)
        rows = {
            k: np.stack([r.transitions[k] for r in records], axis=1) for k in records[0].transitions
        }
        for n in range(len(rows["reward"])):
            model.replay_buffer.add(
                rows["obs"][n] / scale,
                rows["next_obs"][n] / scale,
                rows["action"][n],
                ddpg.reward_scale * rows["reward"][n],
                rows["done"][n],
                [{} for _ in range(n_envs)],
            )
    return episodes * decisions


def _select(
    preset: Preset, gains: PDGains, last: dict[str, Any], out: Path, made_by: str, episodes: int
) -> dict[str, Any]:
    """Score the trained actor against the law (the ``paired`` rule) on the preset's
    validation set; ``policy.pt`` is the actor if it passes, else the law. The trained
    actor's row is labelled with the run's ``episodes``."""
    train, config = preset.train, preset.env
    per_cell = max(2, train.validation_per_cell)
    validator = Validator(config, gains, per_cell, rule="paired")
    zero = ActorPolicy.zero_residual(last)
    rows = []
    for episode, state in ((0, zero), (episodes, last)):
        metrics = validation_metrics(validator.env, state, validator.options)
        score = validator.score_metrics(metrics)
        paired = validator.paired(episode, metrics, state)
        kept = episode > 0 and score.beats_pd and paired.beats_law
        rows.append({"episode": episode, **_score_row(score), "kept": kept, **paired.as_row()})
    kept = rows[-1]["kept"]
    chosen = last if kept else zero
    note = "" if kept else "; shipped: episode 0's zero residual (no actor beat it)"
    write_policy(out / "policy.pt", chosen, config, made_by + note)
    write_csv(out / "validation.csv", pd.DataFrame(rows), made_by)
    return rows[-1]


def _score_row(score: Any) -> dict[str, float]:
    return {
        "force_error": score.force_error,
        "pd_force_error": score.pd_force_error,
        "translation_error_pct": score.translation_error_pct,
        "pd_translation_error_pct": score.pd_translation_error_pct,
        "angle_error_pct": score.angle_error_pct,
        "pd_angle_error_pct": score.pd_angle_error_pct,
        "score": score.score if math.isfinite(score.score) else math.nan,
    }


def _scaled(env: PushEnv, obs_scale: np.ndarray, reward_scale: float) -> Any:
    """``env`` as SB3 takes it: the observation over ``obs_scale``, the reward ×
    ``reward_scale`` (the DDPG critic's scaling), everything else as it is."""
    import gymnasium

    scale = np.asarray(obs_scale, dtype=np.float32)
    space = gymnasium.spaces.Box(-np.inf, np.inf, env.observation_space.shape, np.float32)
    scaled = gymnasium.wrappers.TransformObservation(
        env, lambda obs: (obs / scale).astype(np.float32), space
    )
    return gymnasium.wrappers.TransformReward(scaled, lambda r: reward_scale * float(r))

"""A standard learner through the same environment: stable-baselines3's SAC (Haarnoja et al.
2018) on the push environment of a preset, for comparing learners (``pushctl train --algo
sb3-sac``).

What it shares with the DDPG run of the same preset: the environment (``[env]``, every
reset from the run's seed), the budget (``[train] episodes`` × decisions per episode), the
networks' widths, γ, τ, batch and buffer sizes, the warm-up length (SB3's
``learning_starts``: uniform random actions, SB3's rule, where DDPG explores with OU noise)
and the updates per decision (as ``train_freq`` decisions and ``gradient_steps`` updates);
the observation is divided by the same scales and the reward multiplied by the same
``reward_scale``. The rest is SB3's SAC as it comes (a learned entropy coefficient, one
learning rate of 3e-4). It steps ``episodes_per_round`` environments in SB3's ``DummyVecEnv``
in the learner's process.

The trained actor is written as a pushctl policy (``policy.pt``: SAC's deterministic action
tanh(μ(s)) is the same ReLU MLP with a tanh output as the DDPG actor, so its weights copy
over exactly) and selected like DDPG's with the ``paired`` rule on the preset's validation
set: kept only if it beats the law beyond the CI, else the file holds the law. The SB3
model itself is ``sb3_sac.zip``; a run cannot be resumed.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import torch

from pushctl.control.gains import PDGains, load_gains
from pushctl.errors import ConfigError
from pushctl.files.provenance import write_csv
from pushctl.rl.networks import Actor, ActorPolicy, configure_torch
from pushctl.rl.policy import write_policy
from pushctl.rl.presets import Preset
from pushctl.rl.validate import Validator, validation_metrics
from pushctl.task.env import PushEnv
from pushctl.task.spaces import observation_entries, scales

MODEL = "sb3_sac.zip"
"""The SB3 model in the run directory."""


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
    gains = gains if gains is not None else load_gains()
    entries = observation_entries(
        2, reference_offset=config.offset_observed, context=config.observe_context
    )
    obs_scale = scales(entries)
    n_envs = max(1, train.episodes_per_round)
    decisions = -(-round(config.duration / config.dt) // config.action_repeat)
    total = (episodes or train.episodes) * decisions
    repeat = max(1, round(1.0 / ddpg.updates_per_step)) if ddpg.updates_per_step < 1 else 1
    gradient_steps = max(1, round(ddpg.updates_per_step * repeat))
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
        learning_starts=ddpg.warmup_steps,
        train_freq=(repeat, "step"),
        gradient_steps=gradient_steps,
        policy_kwargs={"net_arch": list(ddpg.hidden)},
        seed=seed,
        device="cpu",
        verbose=0,
    )
    log(f"sb3-sac: {total:,} decisions on {n_envs} environments, seed {seed}")
    model.learn(total_timesteps=total)
    out.mkdir(parents=True, exist_ok=True)
    model.save(out / MODEL)
    last = sac_actor_state(model, obs_scale)
    write_policy(out / "policy_last.pt", last, config, made_by)
    return _select(preset, gains, last, out, made_by)


def _select(
    preset: Preset, gains: PDGains, last: dict[str, Any], out: Path, made_by: str
) -> dict[str, Any]:
    """Score the trained actor against the law (the ``paired`` rule) on the preset's
    validation set; ``policy.pt`` is the actor if it passes, else the law."""
    train, config = preset.train, preset.env
    per_cell = max(2, train.validation_per_cell)
    validator = Validator(config, gains, per_cell, rule="paired")
    zero = ActorPolicy.zero_residual(last)
    rows = []
    for episode, state in ((0, zero), (train.episodes, last)):
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

"""The critic's side of :class:`~pushctl.rl.ddpg.DDPGAgent`'s update, with the parts
:class:`~pushctl.rl.config.DDPGConfig` switches on: twin critics with target policy
smoothing (TD3, Fujimoto et al. 2018), n-step targets, the asymmetric critic's privileged
input (Pinto et al. 2017), LayerNorm (in :class:`~pushctl.rl.networks.Critic`) and the critic
warm-up on the base law's transitions before any actor update.

With every part off the agent takes its own plain DDPG step, bit for bit as before these
parts existed; each part draws its random numbers (the smoothing noise) from the agent's
torch generator, which its checkpoint holds, so a resumed run stays bit-identical.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch
from torch import nn

from pushctl.errors import ConfigError
from pushctl.rl.config import DDPGConfig
from pushctl.rl.networks import Critic, initialise
from pushctl.task.spaces import PRIVILEGED_SCALES

DDPGAgent = Any
"""A :class:`pushctl.rl.ddpg.DDPGAgent` (not imported: it imports this module)."""


def privileged_scale(config: DDPGConfig, priv_scale: np.ndarray | None) -> np.ndarray:
    """The divisors (p,) of the privileged rows the critic sees: none (0,) unless
    ``privileged_critic``; then ``priv_scale`` or the environment's
    :data:`~pushctl.task.spaces.PRIVILEGED_SCALES`."""
    if not config.privileged_critic:
        return np.zeros(0)
    scale = np.asarray(PRIVILEGED_SCALES if priv_scale is None else priv_scale, dtype=float)
    if scale.ndim != 1 or not (np.isfinite(scale).all() and (scale > 0.0).all()):
        raise ConfigError(f"priv_scale must be finite positive numbers, got {scale!r:.80}")
    return scale


@dataclass
class TwinCritic:
    """TD3's second critic, its target and its optimiser."""

    critic: Critic
    target: Critic
    optim: torch.optim.Adam

    @classmethod
    def build(
        cls, config: DDPGConfig, critic_in: int, act_dim: int, generator: torch.Generator
    ) -> TwinCritic | None:
        """The second critic (``twin_critics``; None otherwise), initialised from
        ``generator`` after the agent's own networks, so those draw as without it."""
        if not config.twin_critics:
            return None
        critic = Critic(critic_in, act_dim, config.hidden, config.critic_layer_norm)
        initialise(critic, generator)
        target = Critic(critic_in, act_dim, config.hidden, config.critic_layer_norm)
        target.load_state_dict(critic.state_dict())
        optim = torch.optim.Adam(critic.parameters(), lr=config.critic_lr, fused=True)
        return cls(critic, target.requires_grad_(False), optim)


def critic_input(
    agent: DDPGAgent, obs: torch.Tensor, batch: dict[str, torch.Tensor], key: str
) -> torch.Tensor:
    """What the critic sees: the scaled observations ``obs`` (B, d), and with a privileged
    critic the batch's ``key`` rows (``priv`` or ``next_priv``) over their scale."""
    if not agent.priv_dim:
        return obs
    scale = torch.as_tensor(agent.priv_scale, dtype=torch.float32)
    return torch.cat((obs, batch[key] / scale), dim=-1)


def critic_step(
    agent: DDPGAgent, batch: dict[str, torch.Tensor], obs: torch.Tensor, next_obs: torch.Tensor
) -> tuple[torch.Tensor, torch.Tensor]:
    """One gradient step of the critic (and its twin) to
    ``reward_scale·r + γ^n (1 − done) Q'(s', ã)``, Q' the smaller of the two target critics
    with twins, ã the target actor's action plus clipped Gaussian noise with twins (target
    policy smoothing), r the n-step reward the buffer holds (:func:`n_step_rows`). Returns
    the first critic's Q of the batch (B,) and its loss."""
    cfg, twin = agent.config, agent.twin
    seen = critic_input(agent, obs, batch, "priv")
    seen_next = critic_input(agent, next_obs, batch, "next_priv")
    with torch.no_grad():
        next_action = agent.actor_target(next_obs)
        if twin is not None and cfg.target_noise > 0.0:
            noise = torch.randn(next_action.shape, generator=agent._torch_gen)
            noise = (noise * cfg.target_noise).clamp(-cfg.target_noise_clip, cfg.target_noise_clip)
            next_action = (next_action + noise).clamp(-1.0, 1.0)
        next_q = agent.critic_target(seen_next, next_action)
        if twin is not None:
            next_q = torch.minimum(next_q, twin.target(seen_next, next_action))
        discount = cfg.gamma**cfg.n_step
        target = cfg.reward_scale * batch["reward"] + discount * (1.0 - batch["done"]) * next_q
    pairs = [(agent.critic, agent.critic_optim)]
    if twin is not None:
        pairs.append((twin.critic, twin.optim))
    results = []
    for critic, optim in pairs:
        q = critic(seen, batch["action"])
        loss = nn.functional.mse_loss(q, target)
        optim.zero_grad(set_to_none=True)
        loss.backward()
        if cfg.critic_grad_clip > 0.0:
            nn.utils.clip_grad_norm_(critic.parameters(), cfg.critic_grad_clip)
        optim.step()
        results.append((q, loss))
    return results[0]


def n_step_rows(rows: dict[str, np.ndarray], n: int, gamma: float) -> dict[str, np.ndarray]:
    """One episode's transitions (T rows, in order: :class:`~pushctl.rl.collect.EpisodeRecord`)
    as n-step transitions: row t's reward becomes Σ_k γ^k r_{t+k} over the next ``n``
    decisions or up to a terminal, its ``next_obs``/``next_priv`` and ``done`` those of the
    window's last row. ``n`` = 1 returns ``rows`` itself."""
    if n == 1:
        return rows
    reward = rows["reward"].astype(np.float64)
    done = rows["done"]
    steps = len(reward)
    total = np.zeros(steps)
    last = np.arange(steps)
    alive = np.ones(steps, dtype=bool)
    for k in range(n):
        ahead = np.arange(steps) + k
        valid = alive & (ahead < steps)
        total[valid] += gamma**k * reward[ahead[valid]]
        last[valid] = ahead[valid]
        alive = valid & (done[np.minimum(ahead, steps - 1)] == 0.0)
    out = dict(rows)
    out["reward"] = total.astype(np.float32)
    for key in ("next_obs", "done", "next_priv"):
        if key in rows:
            out[key] = np.ascontiguousarray(rows[key][last])
    return out


def critic_warmup_due(agent: DDPGAgent) -> bool:
    """Whether :func:`warm_critic` should run now: asked for, the warm-up over, not run."""
    cfg = agent.config
    return (
        cfg.critic_warmup_updates > 0
        and not agent._critic_warmed
        and agent.env_steps >= cfg.warmup_steps
        and len(agent.replay) >= cfg.batch_size
    )


def warm_critic(agent: DDPGAgent) -> None:
    """``critic_warmup_updates`` critic-only updates on the buffer as the warm-up left it
    (the base law's transitions with the OU noise), once: the actor and its target stay, and
    the updates do not count in :attr:`~pushctl.rl.ddpg.DDPGAgent.n_updates` (the burn-in
    comes after them)."""
    agent._critic_only = agent.config.critic_warmup_updates
    while agent._critic_only > 0:
        agent.update()
    agent._critic_warmed = True


def save_extras(agent: DDPGAgent, state: dict[str, Any]) -> None:
    """Add the twin critic and the warm-up's state to a checkpoint ``state`` (nothing when
    the parts are off, so a plain agent's checkpoint is as before)."""
    if agent.twin is not None:
        twin = agent.twin
        state["twin_critic"] = {k: v.clone() for k, v in twin.critic.state_dict().items()}
        state["twin_target"] = {k: v.clone() for k, v in twin.target.state_dict().items()}
        state["twin_optim"] = copy.deepcopy(twin.optim.state_dict())
    if agent.config.critic_warmup_updates > 0:
        state["critic_warmed"] = agent._critic_warmed


def load_extras(agent: DDPGAgent, state: dict[str, Any]) -> None:
    """The inverse of :func:`save_extras`."""
    if agent.twin is not None:
        agent.twin.critic.load_state_dict(state["twin_critic"])
        agent.twin.target.load_state_dict(state["twin_target"])
        agent.twin.optim.load_state_dict(state["twin_optim"])
    agent._critic_warmed = bool(state.get("critic_warmed", False))
    agent._critic_only = 0

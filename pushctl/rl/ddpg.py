"""DDPG (Lillicrap et al., 2016): the agent that acts, stores transitions, updates and resumes.

Determinism: every random draw comes from ``seed`` via ``np.random.SeedSequence(seed)``,
spawned into numpy generators (replay sampling, OU noise) and the seed
of one ``torch.Generator`` (weight initialisation). The global numpy, torch and ``random``
RNGs are never used, and :meth:`DDPGAgent.state_dict` holds every generator's state, so a
resumed run continues bit-identically (on the same machine and torch thread count).
"""

from __future__ import annotations

import copy
import numbers
from collections.abc import Iterable
from fractions import Fraction
from typing import Any

import numpy as np
import torch
from torch import nn

from pushctl.errors import ConfigError, StateError
from pushctl.rl import critic_side
from pushctl.rl.config import DDPGConfig
from pushctl.rl.networks import (  # configure_torch, soft_update: imported from here too
    Actor,
    ActorPolicy,
    Critic,
    configure_torch,  # noqa: F401
    initialise,
    soft_update,  # noqa: F401
)
from pushctl.rl.noise import OrnsteinUhlenbeckNoise
from pushctl.rl.replay import ReplayBuffer

_NETWORKS = ("actor", "critic", "actor_target", "critic_target")


class DDPGAgent:
    """DDPG with a replay buffer, OU exploration noise and Polyak-averaged target networks.

    Observations are raw (obs_dim,) or (B, obs_dim) vectors; they are stored raw and divided
    by ``obs_scale`` (obs_dim,) [obs units] before entering any network. Actions are
    normalised to [-1, 1], float64, (act_dim,) or (B, act_dim).

    Training loop, one environment step at a time (or B rows of a vectorised env)::

        action = agent.act(obs, explore=True)
        agent.observe(obs, action, reward, next_obs, done)   # done: true terminal only
        for _ in range(agent.updates_due(1)):
            agent.update()

    Call :meth:`reset_noise` at the start of each episode.
    """

    def __init__(
        self,
        obs_dim: int,
        act_dim: int,
        config: DDPGConfig,
        seed: int,
        obs_scale: np.ndarray | None = None,
        priv_scale: np.ndarray | None = None,
    ) -> None:
        for name, value, least in (
            ("obs_dim", obs_dim, 1),
            ("act_dim", act_dim, 1),
            ("seed", seed, 0),
        ):
            if not isinstance(value, numbers.Integral) or isinstance(value, bool) or value < least:
                raise ConfigError(f"ddpg {name} must be an integer >= {least}, got {value!r}")
        self.obs_dim, self.act_dim, self.config = int(obs_dim), int(act_dim), config
        # four children as before the uniform warm-up's generator went, so the others keep
        # their streams (the second is unused)
        replay_seq, _, noise_seq, torch_seq = np.random.SeedSequence(int(seed)).spawn(4)
        self._replay_rng = np.random.default_rng(replay_seq)
        self._noise_rng = np.random.default_rng(noise_seq)
        self._torch_gen = torch.Generator().manual_seed(int(torch_seq.generate_state(1)[0]))
        self.priv_scale = critic_side.privileged_scale(config, priv_scale)
        self.priv_dim = len(self.priv_scale)
        critic_in = self.obs_dim + self.priv_dim
        norm = config.critic_layer_norm
        self.actor = Actor(self.obs_dim, self.act_dim, config.hidden)
        self.critic = Critic(critic_in, self.act_dim, config.hidden, norm)
        initialise(self.actor, self._torch_gen, config.actor_final_init)
        initialise(self.critic, self._torch_gen)
        self.actor_target = copy.deepcopy(self.actor).requires_grad_(False)
        self.critic_target = copy.deepcopy(self.critic).requires_grad_(False)
        self.actor_optim = torch.optim.Adam(self.actor.parameters(), lr=config.actor_lr, fused=True)
        self.critic_optim = torch.optim.Adam(
            self.critic.parameters(), lr=config.critic_lr, fused=True
        )
        self.twin = critic_side.TwinCritic.build(config, critic_in, self.act_dim, self._torch_gen)
        self.replay = ReplayBuffer(config.buffer_size, self.obs_dim, self.act_dim, self.priv_dim)
        self._noise = self._new_noise((self.act_dim,))
        ratio = Fraction(config.updates_per_step).limit_denominator(1_000_000)
        self._credit_per_step, self._credit_per_update = ratio.numerator, ratio.denominator
        self._env_steps = 0
        self._updates = 0
        self._credit = 0
        self._imitated = False
        self._critic_only = 0  # updates left of a critic warm-up (critic_side.warm_critic)
        self._critic_warmed = False
        self.prior: Actor | None = None
        """The actor as imitation left it (frozen), once :meth:`imitate` ran; without
        imitation and with a ``prior_weight``, the actor as it starts (a residual that
        stays near zero: near the base law it is added to). Set with :meth:`_set_prior`."""
        self._prior_is_zero = False
        self.actor_average: Actor | None = (
            copy.deepcopy(self.actor).requires_grad_(False) if config.policy_average else None
        )
        """The averaged actor (``policy_average`` > 0): what :meth:`shipped_state` holds."""
        self._set_policy(obs_scale)
        if config.prior_weight > 0.0 and config.imitation_updates == 0:
            self._set_prior(self.actor)

    @property
    def env_steps(self) -> int:
        """Environment steps observed so far (rows passed to :meth:`observe`)."""
        return self._env_steps

    @property
    def n_updates(self) -> int:
        """Gradient updates done so far."""
        return self._updates

    @property
    def obs_scale(self) -> np.ndarray:
        """Divisor of observations before the networks, (obs_dim,) [obs units] (a copy)."""
        return self._policy.obs_scale.astype(np.float64)

    def act(self, obs: np.ndarray, explore: bool) -> np.ndarray:
        """Action for obs (obs_dim,) → (act_dim,), or (B, obs_dim) → (B, act_dim), in [-1, 1].

        ``explore=False``: the actor's output. ``explore=True``: the behaviour of training
        (:meth:`OrnsteinUhlenbeckNoise.explore`): the OU noise alone while :attr:`env_steps`
        < ``warmup_steps``, afterwards actor + OU noise, clipped to [-1, 1]. A batch keeps
        one OU process per row: the noise has shape (B, act_dim), and a new batch shape
        starts a fresh process at 0. (:mod:`pushctl.rl.train` draws each episode's noise
        from that episode's own generator, :mod:`pushctl.rl.collect`, with the same rule.)
        """
        if not explore:
            return self._policy(obs)
        if self._env_steps < self.config.warmup_steps:  # the noise alone (obs still checked)
            action, shape = None, self._policy.scaled(obs).shape[:-1] + (self.act_dim,)
        else:
            action = self._policy(obs)
            shape = action.shape
        if self._noise.shape != shape:
            self._noise = self._new_noise(shape)
        return self._noise.explore(action)

    def policy_action(self, obs: np.ndarray) -> np.ndarray:
        """The deterministic actor's action (no noise, no warm-up), for evaluation."""
        return self._policy(obs)

    def reset_noise(self, rows: Iterable[int] | None = None) -> None:
        """Restart the OU noise at 0 (episode start); ``rows`` only those batch rows."""
        self._noise.reset(None if rows is None else np.fromiter(rows, dtype=np.intp))

    def observe(self, obs, action, reward, next_obs, done, priv=None, next_priv=None) -> None:
        """Store one transition (obs (obs_dim,), ...) or B of them (obs (B, obs_dim), ...).

        ``done`` is True only at a true terminal state (no bootstrap from next_obs); store a
        time-limit truncation with done=False and its real next_obs. Advances
        :attr:`env_steps` by the number of rows.
        """
        if np.ndim(obs) == 1:
            self.replay.add(obs, action, reward, next_obs, done)
            self._env_steps += 1
        else:
            self.replay.add_batch(obs, action, reward, next_obs, done, priv, next_priv)
            self._env_steps += int(np.shape(obs)[0])

    def updates_due(self, n_new_steps: int) -> int:
        """Gradient updates to run after ``n_new_steps`` new env steps were observed.

        Credits ``updates_per_step`` (as an exact fraction p/q) per new step past warm-up and
        returns the whole updates accumulated, keeping the remainder: 0.1 gives one update
        every 10 steps, 2.0 two per step. Nothing is credited during warm-up or while the
        buffer holds fewer than ``batch_size`` transitions.
        """
        eligible = min(int(n_new_steps), self._env_steps - self.config.warmup_steps)
        if eligible <= 0 or len(self.replay) < self.config.batch_size:
            return 0
        self._credit += eligible * self._credit_per_step
        due, self._credit = divmod(self._credit, self._credit_per_update)
        return due

    @property
    def imitation_due(self) -> bool:
        """Whether :meth:`imitate` should run now: the config asks for it, the warm-up is
        over and it has not run."""
        cfg = self.config
        return (
            cfg.imitation_updates > 0
            and not self._imitated
            and self._env_steps >= cfg.warmup_steps
            and len(self.replay) >= cfg.batch_size
        )

    def imitate(self) -> float:
        """Fit the actor to the actions in the buffer (the warm-up's demonstrations):
        ``imitation_updates`` Adam steps (learning rate 1e-3, its own optimiser) on the mean
        squared error between ``actor(obs)`` and the stored action, batches of
        ``batch_size``; then the target actor copies it. Runs once; returns the last loss."""
        cfg = self.config
        optim = torch.optim.Adam(self.actor.parameters(), lr=1e-3)
        loss = torch.zeros(())
        for _ in range(cfg.imitation_updates):
            batch = self.replay.sample(cfg.batch_size, self._replay_rng)
            obs = torch.from_numpy(batch["obs"]) / self._scale_t
            loss = nn.functional.mse_loss(self.actor(obs), torch.from_numpy(batch["action"]))
            optim.zero_grad(set_to_none=True)
            loss.backward()
            optim.step()
        soft_update(self.actor_target, self.actor, 1.0)
        if self.actor_average is not None:
            soft_update(self.actor_average, self.actor, 1.0)
        self._set_prior(self.actor)
        self._imitated = True
        return float(loss.item())

    def update(self) -> dict[str, float]:
        """One gradient step of critic and actor on a sampled batch, then the target updates.

        Critic: MSE to ``reward_scale·r + gamma·(1 − done)·Q'(s', mu'(s'))``, or with the
        config's critic parts the target of :func:`~pushctl.rl.critic_side.critic_step`
        (twins, smoothing, n-step, privileged rows; the actor every ``actor_delay``-th
        update, following the first critic). Actor: maximise
        Q(s, mu(s)) − action_penalty·‖z(s)‖², z the actor's output before its tanh, from the
        ``critic_burn_in``-th update on (before it the actor stays as it is): with the
        critic's weights frozen for its backward pass, and without the prior's forward pass
        where the prior acts 0 (:meth:`_set_prior`): the same bits as without either, in less
        time. Targets: :func:`soft_update`
        with ``tau``. Returns the critic loss, actor loss and mean Q of the batch.
        """
        cfg = self.config
        if len(self.replay) < cfg.batch_size:
            raise StateError(
                f"update needs {cfg.batch_size} transitions in the buffer, has {len(self.replay)}"
            )
        batch = self.replay.sample(cfg.batch_size, self._replay_rng)
        t = {name: torch.from_numpy(value) for name, value in batch.items()}
        obs, next_obs = t["obs"] / self._scale_t, t["next_obs"] / self._scale_t
        # plain DDPG's step when the parts are off: the same operations as before them
        q, critic_loss = critic_side.critic_step(self, t, obs, next_obs)
        actor_due = self._updates % cfg.actor_delay == 0 and self._critic_only <= 0
        critic_obs = critic_side.critic_input(self, obs, t, "priv")

        if self._updates >= cfg.critic_burn_in and actor_due:
            # The critic is a fixed function of the action here: without its weights'
            # gradients (which the next critic step would discard) the backward pass skips
            # their products; the actor's gradient is the same to the bit.
            self.critic.requires_grad_(False)
            try:
                actor_loss = self._actor_loss(obs, critic_obs)
                self.actor_optim.zero_grad(set_to_none=True)
                actor_loss.backward()
            finally:
                self.critic.requires_grad_(True)
            self.actor_optim.step()
            if self.actor_average is not None:
                soft_update(self.actor_average, self.actor, cfg.policy_average)
        else:
            with torch.no_grad():
                actor_loss = -self.critic(critic_obs, self.actor(obs)).mean()

        # TD3 moves every target only with its delayed actor step (Fujimoto et al. 2018,
        # Algorithm 1); with no delay, every update moves them
        targets_due = cfg.actor_delay == 1 or actor_due
        if targets_due:
            soft_update(self.critic_target, self.critic, cfg.tau)
            if self.twin is not None:
                soft_update(self.twin.target, self.twin.critic, cfg.tau)
        if self._critic_only <= 0 and targets_due:  # it stays while only the critic learns
            soft_update(self.actor_target, self.actor, cfg.tau)
        if self._critic_only > 0:  # a critic warm-up's update: not counted
            self._critic_only -= 1
        else:
            self._updates += 1
        return {
            "critic_loss": critic_loss.item(),
            "actor_loss": actor_loss.item(),
            "q_mean": float(q.detach().mean()),
        }

    def _actor_loss(self, obs: torch.Tensor, critic_obs: torch.Tensor) -> torch.Tensor:
        """The actor's loss on a batch of scaled observations (see :meth:`update`);
        ``critic_obs``: what the critic sees of them (with the privileged rows, if any)."""
        cfg = self.config
        pre_tanh = self.actor.net(obs)
        if cfg.prior_weight > 0.0 and self.prior is not None:
            action = torch.tanh(pre_tanh)
            q_pi = self.critic(critic_obs, action)
            with torch.no_grad():
                q_size = q_pi.abs().mean().clamp_min(1e-6)
            if self._prior_is_zero:  # action − 0 is the action, bit for bit
                distance = action.square().sum(dim=1).mean()
            else:
                with torch.no_grad():
                    prior_action = self.prior(obs)
                distance = (action - prior_action).square().sum(dim=1).mean()
            actor_loss = -q_pi.mean() / q_size + cfg.prior_weight * distance
        else:
            actor_loss = -self.critic(critic_obs, torch.tanh(pre_tanh)).mean()
        if cfg.action_penalty > 0.0:
            penalty = pre_tanh.square().sum(dim=1).mean()
            actor_loss = actor_loss + cfg.action_penalty * penalty
        return actor_loss

    def _set_prior(self, actor: Actor) -> None:
        """A frozen copy of ``actor`` becomes :attr:`prior`. One whose output layer is all
        zeros acts 0 everywhere (tanh(0) = 0: the paper preset's, ``actor_final_init``
        0), which the actor loss then uses without the prior's forward pass."""
        self.prior = copy.deepcopy(actor).requires_grad_(False)
        last = self.prior.net[-1]
        assert isinstance(last, nn.Linear)
        self._prior_is_zero = not (bool(last.weight.any()) or bool(last.bias.any()))

    def actor_state(self) -> dict[str, Any]:
        """The actor alone with its obs_scale, for :meth:`ActorPolicy.from_state` (a snapshot)."""
        return self._policy.state()

    def shipped_state(self) -> dict[str, Any]:
        """What validation scores and a run ships, as :meth:`actor_state`: the averaged actor
        with ``policy_average`` > 0, else the actor itself."""
        if self.actor_average is None:
            return self.actor_state()
        return ActorPolicy(self.actor_average, self._policy.obs_scale).state()

    def state_dict(self) -> dict[str, Any]:
        """A snapshot of everything a bit-identical resume needs, as tensors and plain values.

        Holds the four networks, both Adam states, the replay buffer (filled rows), the three
        numpy generator states, the torch generator state, the OU state, the counters,
        obs_scale, the config and the dims. Loadable by ``torch.load`` with
        ``weights_only=True``.
        """
        state: dict[str, Any] = {
            name: {k: v.clone() for k, v in getattr(self, name).state_dict().items()}
            for name in _NETWORKS
        }
        state.update(
            obs_dim=self.obs_dim,
            act_dim=self.act_dim,
            config=self.config.to_dict(),
            actor_optim=copy.deepcopy(self.actor_optim.state_dict()),
            critic_optim=copy.deepcopy(self.critic_optim.state_dict()),
            replay=_as_tensors(self.replay.state_dict()),
            rng={name: rng.bit_generator.state for name, rng in self._numpy_rngs().items()},
            torch_generator=self._torch_gen.get_state(),
            noise=_as_tensors(self._noise.state_dict()),
            counters={
                "env_steps": self._env_steps,
                "updates": self._updates,
                "credit": self._credit,
                "imitated": self._imitated,
            },
            obs_scale=torch.tensor(self._policy.obs_scale),
        )
        if self.prior is not None:
            state["prior"] = {k: v.clone() for k, v in self.prior.state_dict().items()}
        if self.actor_average is not None:
            average = self.actor_average.state_dict()
            state["actor_average"] = {k: v.clone() for k, v in average.items()}
        critic_side.save_extras(self, state)
        return state

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore a :meth:`state_dict`; ConfigError if its dims or config differ from ours."""
        dims = (state["obs_dim"], state["act_dim"])
        if dims != (self.obs_dim, self.act_dim):
            raise ConfigError(
                f"checkpoint has (obs_dim, act_dim) = {dims}, "
                f"the agent {(self.obs_dim, self.act_dim)}"
            )
        ours = self.config.to_dict()
        theirs = {**DDPGConfig().to_dict(), **state["config"]}  # keys added later: defaults
        diff = [k for k in sorted(set(ours) | set(theirs)) if ours.get(k) != theirs.get(k)]
        if diff:
            pairs = ", ".join(f"{k}={theirs.get(k)!r} (agent: {ours.get(k)!r})" for k in diff)
            raise ConfigError(f"checkpoint config differs from the agent's: {pairs}")
        for name in _NETWORKS:
            getattr(self, name).load_state_dict(state[name])
        self.actor_optim.load_state_dict(state["actor_optim"])
        self.critic_optim.load_state_dict(state["critic_optim"])
        self.replay.load_state_dict(state["replay"])
        for name, rng in self._numpy_rngs().items():
            rng.bit_generator.state = state["rng"][name]
        self._torch_gen.set_state(state["torch_generator"])
        self._noise.load_state_dict(state["noise"])
        counters = state["counters"]
        self._env_steps, self._updates = int(counters["env_steps"]), int(counters["updates"])
        self._credit = int(counters["credit"])
        self._imitated = bool(counters.get("imitated", False))
        self.prior, self._prior_is_zero = None, False
        if "prior" in state:
            prior = Actor(self.obs_dim, self.act_dim, self.config.hidden)
            prior.load_state_dict(state["prior"])
            self._set_prior(prior)
        if self.actor_average is not None:
            self.actor_average.load_state_dict(state["actor_average"])
        self._set_policy(np.asarray(state["obs_scale"], dtype=np.float64))
        critic_side.load_extras(self, state)

    def _numpy_rngs(self) -> dict[str, np.random.Generator]:
        return {"replay": self._replay_rng, "noise": self._noise_rng}

    def _new_noise(self, shape: tuple[int, ...]) -> OrnsteinUhlenbeckNoise:
        cfg = self.config
        return OrnsteinUhlenbeckNoise(shape, cfg.ou_theta, cfg.ou_sigma, cfg.ou_dt, self._noise_rng)

    def _set_policy(self, obs_scale: np.ndarray | None) -> None:
        self._policy = ActorPolicy(self.actor, obs_scale)
        self._scale_t = torch.tensor(self._policy.obs_scale)


def _as_tensors(state: dict[str, Any]) -> dict[str, Any]:
    """numpy arrays → tensors, so that ``torch.load(weights_only=True)`` accepts the state."""
    return {k: torch.from_numpy(v) if isinstance(v, np.ndarray) else v for k, v in state.items()}

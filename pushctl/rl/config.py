"""The DDPG hyper-parameters: one frozen, validated dataclass."""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields
from typing import Any

from pushctl.errors import ConfigError
from pushctl.files.toml import check_keys
from pushctl.ranges import check_range

_POSITIVE_FLOATS = ("actor_lr", "critic_lr", "updates_per_step", "ou_dt", "reward_scale")
_NON_NEGATIVE_FLOATS = (
    "target_noise",
    "target_noise_clip",
    "ou_theta",
    "ou_sigma",
    "critic_grad_clip",
    "actor_final_init",
    "action_penalty",
    "prior_weight",
    "policy_average",
)
_UNIT_FLOATS = ("gamma", "tau")
_POSITIVE_INTS = ("batch_size", "buffer_size", "torch_threads", "actor_delay", "n_step")
_FLAGS = ("twin_critics", "critic_layer_norm", "privileged_critic")
DEMONSTRATORS = ("none", "feedback")
"""Who acts in the warm-up episodes: OU noise alone, or the feedback law alone."""


@dataclass(frozen=True)
class DDPGConfig:
    """Hyper-parameters of :class:`pushctl.rl.ddpg.DDPGAgent` (Lillicrap et al., 2016).

    Fields (default in brackets):

    - ``hidden`` [(256, 256)]: widths of the hidden ReLU layers of actor and critic [units].
    - ``actor_lr`` [1e-4]: Adam learning rate of the actor [1/update].
    - ``critic_lr`` [1e-3]: Adam learning rate of the critic [1/update].
    - ``gamma`` [0.99]: discount factor per environment step, in [0, 1] [-].
    - ``tau`` [0.005]: Polyak factor of the target networks per update, in (0, 1]:
      ``target ← (1 − tau)·target + tau·online`` [-].
    - ``batch_size`` [256]: transitions per gradient update [transitions].
    - ``buffer_size`` [1_000_000]: replay capacity, >= ``batch_size`` [transitions].
    - ``warmup_steps`` [10_000]: environment steps (decisions) of the warm-up, before the
      actor acts and before any update: their actions are the OU exploration noise alone
      (correlated rather than uniform draws, see :func:`pushctl.rl.collect._acting`; the
      same rule in :meth:`DDPGAgent.act`) or, in training with a ``demonstrator``, its law
      [env steps].
    - ``updates_per_step`` [1.0]: gradient updates per environment step, may be fractional
      (0.1 = one update every 10 env steps) [updates/env step].
    - ``ou_theta`` [0.15]: mean-reversion rate of the Ornstein–Uhlenbeck exploration noise,
      with ``ou_theta * ou_dt <= 1`` [1/time unit].
    - ``ou_sigma`` [0.2]: diffusion of the OU noise, in normalised action units [1/√time unit].
    - ``ou_dt`` [1.0]: OU time step per environment step [time unit].
    - ``reward_scale`` [1.0]: factor applied to rewards in the critic target [-].
    - ``critic_grad_clip`` [0.0]: maximum global gradient norm of the critic, 0 = no clipping [-].
    - ``actor_final_init`` [3e-3]: half-width of the uniform initialisation of the actor's
      output layer; 0 starts the residual at exactly zero, so the first policy *is* the base
      controller (Residual Policy Learning, Silver et al. 2018) [-].
    - ``critic_burn_in`` [0]: gradient updates of the critic alone before the actor starts
      learning, so the actor first follows a critic that has seen the base controller's
      returns (Residual Policy Learning's burn-in) [updates].
    - ``action_penalty`` [0.0]: weight of ‖z‖², z the actor's output *before* its tanh, in
      the actor's loss (−Q + action_penalty·‖z‖²): the residual moves away from zero only
      where the critic's gain outweighs it, and, unlike a penalty on the action itself,
      whose gradient vanishes where the tanh saturates, it pulls a saturated actor back;
      in the critic's units (scaled reward) [-].
    - ``demonstrator`` ["none"]: who acts in the warm-up episodes: ``none``, the OU noise
      alone; ``feedback``, the ``feedback`` controller's law (pushctl/defaults/feedback_gains.toml)
      without noise, so the replay buffer starts with a good policy's transitions.
    - ``imitation_updates`` [0]: when the warm-up ends, gradient steps fitting the actor to
      the warm-up's actions (mean squared error, batches of ``batch_size``, the actor's
      optimiser), before any DDPG update: the policy starts from the demonstrator and the
      critic's burn-in then learns that policy's returns (demonstrations as in DDPGfD,
      Večerík et al. 2017; 0: the actor starts at its initialisation) [updates].
    - ``prior_weight`` [0.0]: keep the actor near π₀, the cloned actor after imitation or,
      without imitation, the actor it starts as (with ``actor_final_init = 0`` a zero
      residual: the base law, ``[env] base_law``): the actor's loss becomes
      −Q / mean|Q| + prior_weight·‖π(s) − π₀(s)‖² (+ the action penalty), the critic's
      term normalised by its batch's mean |Q| as in TD3+BC (Fujimoto & Gu, 2021), so the
      weight means the same whatever the reward's scale. 0: plain DDPG's −Q (measured:
      from a cloned feedback law, plain DDPG's first few hundred actor updates left
      pushes 20–30 % off their plan; docs/learning-the-residual.md) [-].
    - ``twin_critics`` [False]: TD3's clipped double Q (Fujimoto et al. 2018): two critics,
      the target the smaller of their targets' values, the actor following the first;
      with ``target_noise`` [0.2] (std of Gaussian noise on the target action, clipped to
      ±``target_noise_clip`` [0.5], normalised action units: target policy smoothing) and
      ``actor_delay`` [1] (critic updates per actor update; TD3's is 2).
    - ``n_step`` [1]: the critic's target sums ``n_step`` decisions' rewards, discounted,
      and bootstraps γ^n_step later (the episode's end cuts the sum): a 100 ms decision's
      effect on the pose shows in a few decisions' rewards more than in one [decisions].
    - ``critic_layer_norm`` [False]: LayerNorm in the critic's hidden layers.
    - ``critic_warmup_updates`` [0]: when the warm-up ends, gradient updates of the critic
      alone on the warm-up's transitions (the base law's, plus the OU noise), before any
      actor update and any new episode (DAWN's critic warm-up); the critic's burn-in comes
      on top [updates].
    - ``privileged_critic`` [False]: an asymmetric critic (Pinto et al. 2017): besides the
      observation it sees the episode's plant unknowns, true parameters and exact pose error
      (:meth:`~pushctl.task.env.PushEnv.privileged_state`) in training; the
      actor never does, so the policy deploys as before.
    - ``policy_average`` [0.0]: Polyak factor per actor step of an averaged copy of the
      actor, ``average ← (1 − f)·average + f·actor`` (weight averaging: Polyak & Juditsky
      1992; in deep RL Nikishin et al. 2018). When > 0 the average, not the actor, is what
      validation scores and a run ships; the actor alone explores. 1e-3 averages over about
      1,000 actor steps. 0: no average [-].
    - ``torch_threads`` [1]: intra-op torch threads, applied by the caller through
      :func:`pushctl.rl.ddpg.configure_torch` (process-wide, so not by the agent) [threads].
    """

    hidden: tuple[int, ...] = (256, 256)
    actor_lr: float = 1e-4
    critic_lr: float = 1e-3
    gamma: float = 0.99
    tau: float = 0.005
    batch_size: int = 256
    buffer_size: int = 1_000_000
    warmup_steps: int = 10_000
    updates_per_step: float = 1.0
    ou_theta: float = 0.15
    ou_sigma: float = 0.2
    ou_dt: float = 1.0
    reward_scale: float = 1.0
    critic_grad_clip: float = 0.0
    actor_final_init: float = 3e-3
    critic_burn_in: int = 0
    action_penalty: float = 0.0
    demonstrator: str = "none"
    imitation_updates: int = 0
    prior_weight: float = 0.0
    twin_critics: bool = False
    target_noise: float = 0.2
    target_noise_clip: float = 0.5
    actor_delay: int = 1
    n_step: int = 1
    critic_layer_norm: bool = False
    critic_warmup_updates: int = 0
    privileged_critic: bool = False
    policy_average: float = 0.0
    torch_threads: int = 1

    def __post_init__(self) -> None:
        hidden = self.hidden
        if not (
            isinstance(hidden, tuple)
            and len(hidden) > 0
            and all(_is_int(h) and h > 0 for h in hidden)
        ):
            raise ConfigError(
                f"ddpg hidden must be a non-empty tuple of positive integers, got {hidden!r}"
            )
        object.__setattr__(self, "hidden", tuple(int(h) for h in hidden))
        check_range("hidden layers", len(self.hidden), "ddpg: ")
        for width in self.hidden:
            check_range("hidden layer width", width, "ddpg: ")
        for name in _POSITIVE_INTS:
            value = getattr(self, name)
            _check(name, value, _is_int(value) and value > 0, "a positive integer")
            object.__setattr__(self, name, int(value))
        if self.demonstrator not in DEMONSTRATORS:
            raise ConfigError(
                f"ddpg demonstrator must be one of {', '.join(DEMONSTRATORS)}, "
                f"got {self.demonstrator!r}"
            )
        for name in _FLAGS:
            value = getattr(self, name)
            _check(name, value, isinstance(value, bool), "true or false")
        for name in (
            "warmup_steps",
            "critic_burn_in",
            "imitation_updates",
            "critic_warmup_updates",
        ):
            value = getattr(self, name)
            _check(name, value, _is_int(value) and value >= 0, "an integer >= 0")
            object.__setattr__(self, name, int(value))
        for name in _POSITIVE_FLOATS + _NON_NEGATIVE_FLOATS + _UNIT_FLOATS:
            value = getattr(self, name)
            _check(name, value, _is_real(value), "a finite number")
            object.__setattr__(self, name, float(value))
        for name in _POSITIVE_FLOATS:
            _check(name, getattr(self, name), getattr(self, name) > 0.0, "a number > 0")
        for name in _NON_NEGATIVE_FLOATS:
            _check(name, getattr(self, name), getattr(self, name) >= 0.0, "a number >= 0")
        _check("gamma", self.gamma, 0.0 <= self.gamma <= 1.0, "a number in [0, 1]")
        _check("tau", self.tau, 0.0 < self.tau <= 1.0, "a number in (0, 1]")
        average = self.policy_average
        _check("policy_average", average, average <= 1.0, "a number in [0, 1]")
        check_range("replay buffer size", self.buffer_size, "ddpg buffer_size: ")
        if self.buffer_size < self.batch_size:
            raise ConfigError(
                f"ddpg buffer_size must be >= batch_size ({self.batch_size}), "
                f"got {self.buffer_size}"
            )
        if self.ou_theta * self.ou_dt > 1.0:
            raise ConfigError(
                f"ddpg ou_theta * ou_dt must be <= 1 (else the noise oscillates), "
                f"got {self.ou_theta} * {self.ou_dt}"
            )

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any]) -> DDPGConfig:
        """A config from a mapping (e.g. a TOML table); missing keys keep their defaults.

        Unknown keys raise a :class:`ConfigError` listing the accepted ones; a list for
        ``hidden`` becomes a tuple.
        """
        check_keys(data, [f.name for f in fields(cls)], "[ddpg]", all_required=False)
        values = dict(data)
        if isinstance(values.get("hidden"), list):
            values["hidden"] = tuple(values["hidden"])
        return cls(**values)

    def to_dict(self) -> dict[str, Any]:
        """Plain Python values (``hidden`` a list); ``from_mapping(to_dict())`` round-trips."""
        values = asdict(self)
        values["hidden"] = list(self.hidden)
        return values


def _is_int(value: object) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


def _is_real(value: object) -> bool:
    return (
        isinstance(value, numbers.Real)
        and not isinstance(value, bool)
        and math.isfinite(float(value))
    )


def _check(name: str, value: object, ok: bool, accepted: str) -> None:
    if not ok:
        raise ConfigError(f"ddpg {name} must be {accepted}, got {value!r}")

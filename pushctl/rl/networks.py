"""Actor and critic MLPs of DDPG, initialised from an explicit torch generator."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import torch
from torch import nn

from pushctl.errors import ConfigError, StateError
from pushctl.rl import batched_actor

FINAL_LAYER_BOUND = 3e-3
"""Half-width of the uniform initialisation of each network's output layer (DDPG paper)."""


def _linear(n_in: int, n_out: int) -> nn.Linear:
    """A zero ``nn.Linear``: ``skip_init`` avoids the default init and its global-RNG draws."""
    layer = nn.utils.skip_init(nn.Linear, n_in, n_out)
    with torch.no_grad():
        layer.weight.zero_()
        layer.bias.zero_()
    return layer


def _mlp(n_in: int, hidden: Sequence[int], n_out: int, layer_norm: bool = False) -> nn.Sequential:
    layers: list[nn.Module] = []
    for width in hidden:
        layers.append(_linear(n_in, int(width)))
        if layer_norm:  # no random draws: weight 1, bias 0
            layers.append(nn.LayerNorm(int(width)))
        layers.append(nn.ReLU())
        n_in = int(width)
    layers.append(_linear(n_in, n_out))
    return nn.Sequential(*layers)


class Actor(nn.Module):
    """Deterministic policy mu(s): ReLU MLP with a tanh output.

    ``forward(obs)``: obs (B, obs_dim) [scaled units] → action (B, act_dim) in [-1, 1].
    Weights are zero (no global-RNG draws) until :func:`initialise` or ``load_state_dict``.
    """

    def __init__(self, obs_dim: int, act_dim: int, hidden: Sequence[int]) -> None:
        super().__init__()
        self.obs_dim, self.act_dim = int(obs_dim), int(act_dim)
        self.hidden = tuple(int(h) for h in hidden)
        self.net = _mlp(self.obs_dim, hidden, self.act_dim)

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        return torch.tanh(self.net(obs))


class Critic(nn.Module):
    """Action value Q(s, a): ReLU MLP on the concatenation [obs, action].

    ``forward(obs, action)``: obs (B, obs_dim) [scaled units], action (B, act_dim) → Q (B,).
    ``layer_norm``: a LayerNorm after each hidden layer's linear map (before the ReLU), which
    keeps the critic's features at one scale as its targets grow (Ball et al. 2023). An
    asymmetric critic's ``obs_dim`` counts the privileged rows it sees besides the
    observation. Weights are zero until :func:`initialise` or ``load_state_dict``.
    """

    def __init__(
        self, obs_dim: int, act_dim: int, hidden: Sequence[int], layer_norm: bool = False
    ) -> None:
        super().__init__()
        self.obs_dim, self.act_dim = int(obs_dim), int(act_dim)
        self.net = _mlp(self.obs_dim + self.act_dim, hidden, 1, layer_norm)

    def forward(self, obs: torch.Tensor, action: torch.Tensor) -> torch.Tensor:
        return self.net(torch.cat((obs, action), dim=-1)).squeeze(-1)


@torch.no_grad()
def initialise(
    module: nn.Module, generator: torch.Generator, final_bound: float = FINAL_LAYER_BOUND
) -> None:
    """Initialise every ``nn.Linear`` of ``module`` from ``generator`` (never the global RNG).

    Hidden layers: weights and biases ~ U(−1/√fan_in, 1/√fan_in). The last ``nn.Linear`` in
    registration order (the output layer): ~ U(−final_bound, final_bound), 3e-3 by default,
    so initial actions and Q values are near zero, as in Lillicrap et al. (2016); 0 makes
    them exactly zero. Layers are drawn in registration order.
    """
    linears = [m for m in module.modules() if isinstance(m, nn.Linear)]
    for i, layer in enumerate(linears):
        last = i == len(linears) - 1
        bound = final_bound if last else 1.0 / math.sqrt(layer.in_features)
        nn.init.uniform_(layer.weight, -bound, bound, generator=generator)
        if layer.bias is not None:
            nn.init.uniform_(layer.bias, -bound, bound, generator=generator)


class ActorPolicy:
    """The deterministic policy: raw observation → ``actor(obs / obs_scale)``.

    ``policy(obs)``: obs (obs_dim,) or (B, obs_dim) [obs units] → float64 action (act_dim,)
    or (B, act_dim) in [-1, 1]. ``obs_scale`` (obs_dim,) [obs units] defaults to ones.
    Rebuild one for evaluation with ``ActorPolicy.from_state(agent.actor_state())``.

    A single observation (a float numpy array) takes a fast path, as it runs millions of
    times, without ``nn.Module``'s calls (docs/performance.md): the layers are evaluated with
    ``torch.addmv`` into preallocated buffers, on detached views of the actor's parameters
    (so optimiser steps and ``load_state_dict`` show through); it equals ``actor.forward`` up
    to float32 rounding. Not thread-safe: use one policy per thread.
    """

    def __init__(self, actor: Actor, obs_scale: np.ndarray | None = None) -> None:
        n = actor.obs_dim
        scale = np.ones(n) if obs_scale is None else np.asarray(obs_scale, dtype=np.float64)
        if scale.shape != (n,) or not (np.isfinite(scale).all() and (scale > 0.0).all()):
            raise ConfigError(f"obs_scale must be {n} finite positive numbers, got {scale!r:.80}")
        self.actor = actor
        self.obs_scale = scale.astype(np.float32)
        self.obs_scale.flags.writeable = False
        self._obs = np.empty(n, dtype=np.float32)
        linears = [m for m in actor.net if isinstance(m, nn.Linear)]
        self._layers = [(lin.weight.detach(), lin.bias.detach()) for lin in linears]
        self._hidden = [torch.empty(lin.out_features) for lin in linears]
        self._inputs = [torch.from_numpy(self._obs)] + self._hidden[:-1]
        self._action = self._hidden[-1].numpy()
        self._batch_layers: list[tuple[np.ndarray, np.ndarray]] = []
        self._batch_versions: tuple[int, ...] = ()

    def scaled(self, obs: np.ndarray) -> np.ndarray:
        """``obs / obs_scale`` as float32, after checking the shape and that values are finite.

        A float (obs_dim,) array lands in an internal buffer that the next call overwrites.
        """
        n = self.actor.obs_dim
        if type(obs) is np.ndarray and obs.shape == (n,) and obs.dtype.kind == "f":
            x = np.divide(obs, self.obs_scale, out=self._obs, casting="same_kind")
            if math.isfinite(x.dot(x)):  # overflows only for |x| > 1e19
                return x
        else:
            array = np.asarray(obs, dtype=np.float32)
            if array.ndim not in (1, 2) or array.shape[-1] != n:
                raise StateError(f"obs must have shape ({n},) or (B, {n}), got {array.shape}")
            x = array / self.obs_scale
        if not np.isfinite(x).all():
            raise StateError(f"obs must be finite, got {obs!r:.80}")
        return x

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        x = self.scaled(obs)
        if x is not self._obs:
            with torch.inference_mode():
                return self.actor(torch.from_numpy(x)).numpy().astype(np.float64)
        layers = zip(self._layers, self._inputs, self._hidden, strict=True)
        for i, ((weight, bias), h_in, h_out) in enumerate(layers):
            torch.addmv(bias, weight, h_in, out=h_out)
            h_out.relu_() if i < len(self._layers) - 1 else h_out.tanh_()
        return self._action.astype(np.float64)

    def batch(self, obs: np.ndarray) -> np.ndarray:
        """Actions of a batch: obs (B, obs_dim) [obs units] → float64 (B, act_dim) in [−1, 1],
        row i bit for bit the action of ``batch(obs[i:i + 1])`` whatever B is (the training
        collectors step a varying number of episodes together; :mod:`pushctl.rl.batched_actor`).
        It equals :meth:`__call__` up to float32 rounding, not to the bit."""
        n = self.actor.obs_dim
        array = np.asarray(obs, dtype=np.float64)
        if array.ndim != 2 or array.shape[1] != n:
            raise StateError(f"obs must have shape (B, {n}), got {array.shape}")
        x = (array / self.obs_scale).astype(np.float32)
        if not np.isfinite(x).all():
            raise StateError(f"obs must be finite, got {obs!r:.80}")
        return batched_actor.forward(x, self._transposed_layers()).astype(np.float64)

    def _transposed_layers(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """The layers as batched_actor takes them, recopied when a parameter changed in place
        (an optimiser step, ``load_state_dict``: torch counts them in ``_version``)."""
        versions = tuple(t._version for layer in self._layers for t in layer)
        if versions != self._batch_versions:
            self._batch_layers = [
                (np.ascontiguousarray(w.numpy().T), b.numpy().copy()) for w, b in self._layers
            ]
            self._batch_versions = versions
        return self._batch_layers

    def state(self) -> dict[str, Any]:
        """A snapshot (tensors and plain values) that :meth:`from_state` rebuilds."""
        return {
            "obs_dim": self.actor.obs_dim,
            "act_dim": self.actor.act_dim,
            "hidden": list(self.actor.hidden),
            "obs_scale": torch.from_numpy(self.obs_scale.copy()),
            "actor": {k: v.clone() for k, v in self.actor.state_dict().items()},
        }

    @staticmethod
    def zero_residual(state: dict[str, Any]) -> dict[str, Any]:
        """A copy of the snapshot ``state`` with the output layer zeroed: the policy that
        outputs 0 for every observation, so the controller is PD-only."""
        actor = {k: v.clone() for k, v in state["actor"].items()}
        last = max(int(key.split(".")[1]) for key in actor)  # net.<index>.weight|bias
        for kind in ("weight", "bias"):
            actor[f"net.{last}.{kind}"].zero_()
        return {**state, "actor": actor}

    @classmethod
    def from_state(cls, state: dict[str, Any]) -> ActorPolicy:
        """The policy saved by :meth:`state`, in eval mode."""
        actor = Actor(state["obs_dim"], state["act_dim"], state["hidden"])
        actor.load_state_dict(state["actor"])
        return cls(actor.eval(), np.asarray(state["obs_scale"], dtype=np.float64))


def configure_torch(threads: int) -> None:
    """Set torch's intra-op thread count for the whole process (e.g. ``config.torch_threads``)."""
    if not isinstance(threads, int) or isinstance(threads, bool) or threads < 1:
        raise ConfigError(f"torch threads must be a positive integer, got {threads!r}")
    torch.set_num_threads(threads)


@torch.no_grad()
def soft_update(target: nn.Module, source: nn.Module, tau: float) -> None:
    """Polyak update in place: ``target ← (1 − tau)·target + tau·source``, tau in [0, 1].

    tau = 1 copies ``source`` exactly, tau = 0 leaves ``target`` unchanged.
    """
    if not 0.0 <= tau <= 1.0:
        raise ConfigError(f"soft_update tau must be in [0, 1], got {tau!r}")
    for t, s in zip(target.parameters(), source.parameters(), strict=True):
        t.lerp_(s, tau)

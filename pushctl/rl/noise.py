"""Ornstein–Uhlenbeck exploration noise, drawn from a caller-owned generator."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from pushctl.errors import ConfigError, StateError


class OrnsteinUhlenbeckNoise:
    """Temporally correlated noise x of shape ``size``, mean 0, Euler–Maruyama discretised.

    Each :meth:`sample` advances every element by one step of dt [time unit]::

        x ← x + theta·(0 − x)·dt + sigma·√dt·ε,   ε ~ N(0, 1)

    an AR(1) process with coefficient ``1 − theta·dt`` whose stationary variance is
    ``sigma²·dt / (1 − (1 − theta·dt)²) = sigma² / (theta·(2 − theta·dt))``
    (≈ sigma²/(2·theta) for small theta·dt). ``size`` may be a tuple: ``(B, act_dim)`` runs
    one independent process per row. The state starts at, and :meth:`reset` returns it to, 0.

    The generator ``rng`` is borrowed, not owned: its state is saved by whoever owns it, and
    :meth:`state_dict` holds only x.
    """

    def __init__(
        self,
        size: int | tuple[int, ...],
        theta: float,
        sigma: float,
        dt: float,
        rng: np.random.Generator,
    ) -> None:
        shape = (size,) if isinstance(size, (int, np.integer)) else tuple(size)
        if not shape or any(int(n) < 1 for n in shape):
            raise ConfigError(f"OU noise size must be positive integers, got {size!r}")
        if not (theta >= 0.0 and sigma >= 0.0 and dt > 0.0 and theta * dt <= 1.0):
            raise ConfigError(
                "OU noise needs theta >= 0, sigma >= 0, dt > 0 and theta*dt <= 1, "
                f"got theta={theta!r}, sigma={sigma!r}, dt={dt!r}"
            )
        self.theta = float(theta)
        self.sigma = float(sigma)
        self.dt = float(dt)
        self._rng = rng
        self._decay = 1.0 - self.theta * self.dt
        self._scale = self.sigma * math.sqrt(self.dt)
        self._x = np.zeros(tuple(int(n) for n in shape))
        self._eps = np.empty_like(self._x)

    @property
    def shape(self) -> tuple[int, ...]:
        """Shape of each sample."""
        return self._x.shape

    def stationary_variance(self) -> float:
        """Exact long-run variance of each element, sigma²/(theta·(2 − theta·dt)) [-]."""
        if self.theta == 0.0:
            return math.inf
        return self.sigma**2 / (self.theta * (2.0 - self.theta * self.dt))

    def sample(self) -> np.ndarray:
        """Advance one step and return a copy of the new state, shape ``size``."""
        return self.step().copy()

    def step(self) -> np.ndarray:
        """Advance one step and return the state itself (no copy; do not modify or keep it)."""
        self._rng.standard_normal(out=self._eps)
        self._x *= self._decay
        self._eps *= self._scale
        self._x += self._eps
        return self._x

    def explore(self, action: np.ndarray | None) -> np.ndarray:
        """DDPG's behaviour action, the one rule of training and :meth:`DDPGAgent.act
        <pushctl.rl.ddpg.DDPGAgent.act>`: the deterministic ``action`` (shape ``size``,
        float64; modified in place) plus one step of this noise, or, during the warm-up
        (``action`` None), the noise alone; clipped to [−1, 1]."""
        step = self.step()
        action = step.copy() if action is None else np.add(action, step, out=action)
        np.minimum(action, 1.0, out=action)  # two ufuncs: 3x faster than np.clip here
        return np.maximum(action, -1.0, out=action)

    def reset(self, rows: np.ndarray | None = None) -> None:
        """Set the state to 0: all of it, or only ``rows`` (indices into the first axis)."""
        if rows is None:
            self._x.fill(0.0)
        else:
            self._x[rows] = 0.0

    def state_dict(self) -> dict[str, Any]:
        """The current state x (a copy)."""
        return {"x": self._x.copy()}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore x, which may have a different shape (the agent resizes for batches)."""
        x = np.asarray(state["x"], dtype=np.float64).copy()
        if not np.isfinite(x).all():
            raise StateError("OU noise state must be finite")
        self._x = x
        self._eps = np.empty_like(x)

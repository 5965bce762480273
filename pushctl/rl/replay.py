"""A fixed-capacity ring buffer of transitions, float32 numpy, sampled with a given generator."""

from __future__ import annotations

from typing import Any

import numpy as np

from pushctl.errors import ConfigError, StateError

FIELDS = ("obs", "action", "reward", "next_obs", "done")
"""Keys of a sampled batch and of :meth:`ReplayBuffer.state_dict`'s arrays."""


class ReplayBuffer:
    """Transitions (obs, action, reward, next_obs, done) in a float32 ring buffer.

    Storage (N = ``capacity``): ``obs`` (N, obs_dim), ``action`` (N, act_dim), ``reward`` (N,),
    ``next_obs`` (N, obs_dim), ``done`` (N,) with 1.0 for a true terminal (no bootstrap) and
    0.0 otherwise, including time-limit truncations. Once full, each new row overwrites the
    oldest one. Values must be finite; shapes and finiteness are checked on every add.
    """

    def __init__(self, capacity: int, obs_dim: int, act_dim: int, priv_dim: int = 0) -> None:
        for name, value in (("capacity", capacity), ("obs_dim", obs_dim), ("act_dim", act_dim)):
            if not isinstance(value, (int, np.integer)) or isinstance(value, bool) or value < 1:
                raise ConfigError(f"replay {name} must be a positive integer, got {value!r}")
        self.capacity = int(capacity)
        self.obs_dim = int(obs_dim)
        self.act_dim = int(act_dim)
        n = self.capacity
        self._data = {
            "obs": np.zeros((n, self.obs_dim), np.float32),
            "action": np.zeros((n, self.act_dim), np.float32),
            "reward": np.zeros(n, np.float32),
            "next_obs": np.zeros((n, self.obs_dim), np.float32),
            "done": np.zeros(n, np.float32),
        }
        self.priv_dim = int(priv_dim)
        if self.priv_dim:  # an asymmetric critic's privileged rows, before and after
            self._data["priv"] = np.zeros((n, self.priv_dim), np.float32)
            self._data["next_priv"] = np.zeros((n, self.priv_dim), np.float32)
        self._pos = 0
        self._size = 0

    def __len__(self) -> int:
        """Number of filled rows, at most ``capacity``."""
        return self._size

    @property
    def position(self) -> int:
        """Row that the next transition will be written to."""
        return self._pos

    def add(self, obs, action, reward, next_obs, done) -> None:
        """Store one transition: obs (obs_dim,), action (act_dim,), scalar reward and done
        (a buffer with privileged rows takes batches only: :meth:`add_batch`)."""
        if self.priv_dim:
            raise StateError("a replay buffer with privileged rows takes add_batch() only")
        rows = self._checked(obs, action, reward, next_obs, done, batch=None)
        i = self._pos
        for name, value in zip(FIELDS, rows, strict=True):
            self._data[name][i] = value
        self._pos = (i + 1) % self.capacity
        self._size = min(self._size + 1, self.capacity)

    def add_batch(self, obs, action, reward, next_obs, done, priv=None, next_priv=None) -> None:
        """Store B transitions: obs (B, obs_dim), action (B, act_dim), reward (B,),
        next_obs (B, obs_dim), done (B,); the same as B calls of :meth:`add` in row order.
        ``priv``, ``next_priv`` (B, priv_dim): the privileged rows, required with a
        ``priv_dim`` and refused without one."""
        if np.ndim(obs) != 2 or np.shape(obs)[0] < 1:
            raise StateError(
                f"replay obs must have shape (B, {self.obs_dim}) with B >= 1, got {np.shape(obs)}"
            )
        batch = int(np.shape(obs)[0])
        rows = self._checked(obs, action, reward, next_obs, done, batch=batch)
        skip = max(0, batch - self.capacity)
        index = (self._pos + skip + np.arange(batch - skip)) % self.capacity
        if (priv is None) != (self.priv_dim == 0) or (next_priv is None) != (self.priv_dim == 0):
            raise StateError(f"replay has priv_dim {self.priv_dim}: priv rows must match it")
        if self.priv_dim:
            shape = (batch, self.priv_dim)
            extra = [np.asarray(priv, np.float32), np.asarray(next_priv, np.float32)]
            if any(a.shape != shape or not np.isfinite(a).all() for a in extra):
                raise StateError(f"replay priv and next_priv must be finite, shape {shape}")
            rows = rows + extra
        names = FIELDS + (("priv", "next_priv") if self.priv_dim else ())
        for name, value in zip(names, rows, strict=True):
            self._data[name][index] = value[skip:]
        self._pos = (self._pos + batch) % self.capacity
        self._size = min(self._size + batch, self.capacity)

    def sample(self, batch_size: int, rng: np.random.Generator) -> dict[str, np.ndarray]:
        """``batch_size`` rows drawn uniformly, with replacement, from the filled ones.

        Returns new arrays keyed by :data:`FIELDS`, each with a leading batch axis.
        """
        if self._size == 0:
            raise StateError("cannot sample from an empty replay buffer")
        if not isinstance(batch_size, (int, np.integer)) or batch_size < 1:
            raise ConfigError(f"replay batch_size must be a positive integer, got {batch_size!r}")
        index = rng.integers(0, self._size, size=int(batch_size))
        return {name: array[index] for name, array in self._data.items()}

    def state_dict(self) -> dict[str, Any]:
        """Copies of the filled rows (the first ``len(self)``), plus dims and ring position."""
        state: dict[str, Any] = {
            "capacity": self.capacity,
            "obs_dim": self.obs_dim,
            "act_dim": self.act_dim,
            "position": self._pos,
            "size": self._size,
        }
        state.update({name: a[: self._size].copy() for name, a in self._data.items()})
        return state

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore exactly what :meth:`state_dict` saved (arrays may be numpy or torch)."""
        saved = (state["capacity"], state["obs_dim"], state["act_dim"])
        if saved != (self.capacity, self.obs_dim, self.act_dim):
            raise ConfigError(
                f"replay state has (capacity, obs_dim, act_dim) = {saved}, "
                f"this buffer {(self.capacity, self.obs_dim, self.act_dim)}"
            )
        size, pos = int(state["size"]), int(state["position"])
        if not (0 <= size <= self.capacity and 0 <= pos < self.capacity):
            raise StateError(f"replay state has size {size} and position {pos} out of range")
        if size < self.capacity and pos != size:
            raise StateError(f"replay state not full (size {size}) but position {pos} != size")
        for name, array in self._data.items():
            rows = np.asarray(state[name], dtype=np.float32)
            if rows.shape != (size,) + array.shape[1:]:
                raise StateError(
                    f"replay state {name} has shape {rows.shape}, expected {size} rows"
                )
            array[:size] = rows
            array[size:] = 0.0
        self._size, self._pos = size, pos

    def _checked(self, obs, action, reward, next_obs, done, batch: int | None) -> list[np.ndarray]:
        lead: tuple[int, ...] = () if batch is None else (batch,)
        shapes = {
            "obs": lead + (self.obs_dim,),
            "action": lead + (self.act_dim,),
            "reward": lead,
            "next_obs": lead + (self.obs_dim,),
            "done": lead,
        }
        rows = []
        for name, value in zip(FIELDS, (obs, action, reward, next_obs, done), strict=True):
            array = np.asarray(value, dtype=np.float32)
            if array.shape != shapes[name]:
                raise StateError(
                    f"replay {name} must have shape {shapes[name]}, got {np.shape(value)}"
                )
            if not np.isfinite(array).all():
                raise StateError(f"replay {name} must be finite, got {value!r:.60}")
            rows.append(array)
        return rows

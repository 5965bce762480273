"""``gymnasium.make_vec("pushctl/Push-v0", num_envs=N)``: N pushes stepped together.

:class:`PushVectorEnv` is a native :class:`gymnasium.vector.VectorEnv` (the registration's
``vector_entry_point``) holding N :class:`~pushctl.task.env.PushEnv` in one process. A step
takes the actions of all N as one (N, 3) array and returns the N observations, rewards and
flags as arrays, so the caller runs one batched policy forward per step for all N (the
training collectors do, :mod:`pushctl.rl.collect`).

It is built on PushEnv's public ``reset``/``step`` only, so sub-environment i gives exactly
what a single PushEnv gives with the same seed and actions: the physics of each push is its
own exact MLCP in compiled kernels already, and a profile of a collector (docs/
vector-env-and-collection.md) shows the world step, not the per-env Python around it, is
where the time goes, so nothing is gained by batching the physics across pushes; the one
batched kernel that pays is the actor's forward (:meth:`ActorPolicy.batch
<pushctl.rl.networks.ActorPolicy.batch>`).

Auto-reset: gymnasium's ``NEXT_STEP`` mode (the default, as ``SyncVectorEnv``): the step
after a sub-environment's last one resets it (its action is ignored; reward 0, not
terminated) and returns the new episode's first observation. A sub-environment reset this
way draws its next episode from its own ``np_random``, as a single PushEnv's
``reset()`` without a seed does. ``DISABLED`` mode leaves resets to the caller:
``reset(options={"reset_mask": mask})`` resets only the sub-environments in ``mask``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode
from gymnasium.vector.utils import batch_space

from pushctl.control.gains import PDGains, load_gains
from pushctl.errors import ConfigError
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig

AUTORESET_MODES = (AutoresetMode.NEXT_STEP, AutoresetMode.DISABLED)


class PushVectorEnv(gym.vector.VectorEnv):
    """``num_envs`` PushEnvs of one ``config`` and ``gains`` (defaults as PushEnv's) stepped
    together. Observations (N, d) float32; actions (N, 3) in [−1, 1]; rewards (N,) float64;
    terminations and truncations (N,) bool; infos: gymnasium's vector form (each key of the
    single env's info batched over N, with its ``_key`` mask of the sub-environments that
    reported it). ``envs``: the sub-environments, for loops that need their episodes."""

    def __init__(
        self,
        num_envs: int,
        config: EnvConfig | None = None,
        gains: PDGains | None = None,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
    ) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)):
            raise ConfigError(f"num_envs must be a positive integer, got {num_envs!r}")
        if num_envs < 1:
            raise ConfigError(f"num_envs must be a positive integer, got {num_envs!r}")
        try:
            mode = AutoresetMode(autoreset_mode)
        except ValueError:
            mode = None
        if mode not in AUTORESET_MODES:
            accepted = ", ".join(m.value for m in AUTORESET_MODES)
            raise ConfigError(f"autoreset_mode must be one of {accepted}, got {autoreset_mode!r}")
        gains = gains if gains is not None else load_gains()
        self._hold([PushEnv(config, gains) for _ in range(int(num_envs))], mode)

    @classmethod
    def of(
        cls, envs: Sequence[PushEnv], autoreset_mode: AutoresetMode | str = "NextStep"
    ) -> PushVectorEnv:
        """A vector env of existing PushEnvs (one config: a collector's reused env)."""
        if not envs or any(env.config != envs[0].config for env in envs):
            raise ConfigError("a vector env needs one or more PushEnvs of one config")
        vector = cls.__new__(cls)
        vector._hold(list(envs), AutoresetMode(autoreset_mode))
        return vector

    def _hold(self, envs: list[PushEnv], mode: AutoresetMode) -> None:
        self.envs = envs
        self.num_envs = len(envs)
        first = envs[0]
        self.config = first.config
        self.metadata = {"render_modes": [], "autoreset_mode": mode}
        self.single_observation_space = first.observation_space
        self.single_action_space = first.action_space
        self.observation_space = batch_space(first.observation_space, self.num_envs)
        self.action_space = batch_space(first.action_space, self.num_envs)
        shape = self.observation_space.shape
        assert shape is not None  # a Box's
        self._observations_shape: tuple[int, ...] = shape
        self._autoreset = np.zeros(self.num_envs, dtype=bool)
        self._started = False

    # ------------------------------------------------------------------ gymnasium API

    def reset(
        self,
        *,
        seed: int | Sequence[int | None] | None = None,
        options: dict[str, Any] | None = None,
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Reset the sub-environments (all, or those of ``options["reset_mask"]``, (N,)
        bool). ``seed``: an int s seeds sub-environment i with s + i (as ``SyncVectorEnv``);
        a sequence gives each its own (None: no reseeding). The other ``options`` go to
        every sub-environment's reset (:data:`pushctl.task.env.RESET_OPTIONS`)."""
        options = dict(options or {})
        mask = np.asarray(options.pop("reset_mask", np.ones(self.num_envs, dtype=bool)))
        if mask.shape != (self.num_envs,) or mask.dtype != np.bool_:
            raise ConfigError(f"reset_mask must be {self.num_envs} booleans, got {mask!r:.80}")
        if not self._started and not mask.all():
            raise ConfigError("the first reset must reset every sub-environment")
        seeds = self._seeds(seed)
        observations = np.zeros(self._observations_shape, dtype=np.float32)
        infos: dict[str, Any] = {}
        for i, env in enumerate(self.envs):
            if mask[i]:
                observations[i], info = env.reset(seed=seeds[i], options=options or None)
                infos = self._add_info(infos, info, i)
                self._autoreset[i] = False
            else:
                observations[i] = env.observation()
        self._started = True
        return observations, infos

    def step(
        self, actions: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """One push step of every sub-environment with its row of ``actions`` (N, 3), or its
        auto-reset if its episode ended at the step before (``NEXT_STEP`` mode)."""
        actions = np.asarray(actions, dtype=float)
        if actions.shape != self.action_space.shape:
            raise ConfigError(
                f"actions must have shape {self.action_space.shape}, got {actions.shape}"
            )
        n = self.num_envs
        observations = np.zeros(self._observations_shape, dtype=np.float32)
        rewards = np.zeros(n)
        terminations = np.zeros(n, dtype=bool)
        truncations = np.zeros(n, dtype=bool)
        infos = []
        for i, env in enumerate(self.envs):
            if self._autoreset[i]:
                observations[i], info = env.reset()
            else:
                observations[i], rewards[i], terminations[i], truncations[i], info = env.step(
                    actions[i]
                )
            infos.append(info)
        if self.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP:
            self._autoreset = terminations | truncations
        return observations, rewards, terminations, truncations, self._batch_infos(infos)

    def get_attr(self, name: str) -> tuple[Any, ...]:
        """Attribute ``name`` of each sub-environment."""
        return tuple(getattr(env, name) for env in self.envs)

    def close_extras(self, **kwargs: Any) -> None:
        for env in self.envs:
            env.close()

    # ------------------------------------------------------------------ internals

    def _batch_infos(self, infos: list[dict[str, Any]]) -> dict[str, Any]:
        """The N infos in gymnasium's vector form, as ``VectorEnv._add_info`` builds it. Step
        infos (same keys; numbers, bools or arrays) take one numpy call per key: the
        generic path pays a Python call per key and sub-environment (docs/performance.md).
        Anything else (an auto-reset's info among them) takes the generic path."""
        keys = infos[0].keys()
        plain = all(info.keys() == keys for info in infos) and all(
            type(value) in (bool, int, float, np.ndarray)
            for info in infos
            for value in info.values()
        )
        if not plain:
            batched: dict[str, Any] = {}
            for i, info in enumerate(infos):
                batched = self._add_info(batched, info, i)
            return batched
        batched = {}
        for key, first in infos[0].items():
            values = [info[key] for info in infos]
            is_array = type(first) is np.ndarray
            array = np.stack(values) if is_array else np.array(values)
            dtype = first.dtype if is_array else np.dtype(type(first))
            if array.dtype != dtype:
                array = array.astype(dtype)  # mixed types in a key: the first's, as gym's
            batched[key] = array
            batched[f"_{key}"] = np.ones(self.num_envs, dtype=bool)
        return batched

    def _seeds(self, seed: int | Sequence[int | None] | None) -> list[int | None]:
        if seed is None:
            return [None] * self.num_envs
        if isinstance(seed, (int, np.integer)):
            if isinstance(seed, bool):
                raise ConfigError(f"reset seed must be an integer or {self.num_envs} of them")
            return [int(seed) + i for i in range(self.num_envs)]
        seeds = list(seed)
        if len(seeds) != self.num_envs:
            raise ConfigError(f"reset needs {self.num_envs} seeds, got {len(seeds)}")
        return seeds


def make_push_vector_env(num_envs: int, **kwargs: Any) -> PushVectorEnv:
    """The ``vector_entry_point`` of ``pushctl/Push-v0``: ``gymnasium.make_vec``'s keyword
    arguments (``config``, ``gains``, ``autoreset_mode``) go to :class:`PushVectorEnv`."""
    return PushVectorEnv(num_envs, **kwargs)

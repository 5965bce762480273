"""The entry points of the registered push environments (:data:`pushctl.task.VERSIONS`): each
version's defaults for the settings a ``config`` leaves out. A ``config`` given to
``gymnasium.make`` is used as it is, so a policy's saved settings run on any id."""

from __future__ import annotations

from typing import Any

from pushctl.control.gains import PDGains
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.vector_env import PushVectorEnv


def push_v0(config: EnvConfig | None = None, gains: PDGains | None = None) -> PushEnv:
    """``pushctl/Push-v0``: :class:`EnvConfig`'s defaults."""
    return PushEnv(config if config is not None else EnvConfig(), gains)


def push_v1(config: EnvConfig | None = None, gains: PDGains | None = None) -> PushEnv:
    """``pushctl/Push-v1``: :meth:`EnvConfig.v1`."""
    return PushEnv(config if config is not None else EnvConfig.v1(), gains)


def push_v0_vector(num_envs: int, config: EnvConfig | None = None, **kwargs: Any) -> PushVectorEnv:
    """``gymnasium.make_vec("pushctl/Push-v0", num_envs)``: ``config``, ``gains`` and
    ``autoreset_mode`` go to :class:`PushVectorEnv`."""
    return PushVectorEnv(num_envs, config=config if config is not None else EnvConfig(), **kwargs)


def push_v1_vector(num_envs: int, config: EnvConfig | None = None, **kwargs: Any) -> PushVectorEnv:
    """``gymnasium.make_vec("pushctl/Push-v1", num_envs)``, as :func:`push_v0_vector`."""
    config = config if config is not None else EnvConfig.v1()
    return PushVectorEnv(num_envs, config=config, **kwargs)

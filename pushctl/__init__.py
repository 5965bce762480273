"""pushctl: multi-point object pushing with a redundant arm.

The stable Python API (docs/model.md):

- :func:`make_world` builds arm + pusher + object + table; ``World.reset``/``World.step``.
- :func:`solve_box_mlcp` solves one box-friction mixed linear complementarity problem.
- :func:`reproducible` pins numpy's CPU code so that a seed gives the same bytes on every
  x86-64 machine; call it before anything imports numpy (the ``pushctl`` command does).
- The gymnasium environment ``pushctl/Push-v1`` (:data:`ENV_ID`)::

      import gymnasium as gym
      import pushctl
      env = gym.make("pushctl/Push-v1")

Importing pushctl changes nothing outside it and loads neither numpy nor the simulator:
the names above load their modules on first use. It registers the environment with
gymnasium when gymnasium is already imported (``import pushctl.rl`` registers it in any
case, and ``gym.make("pushctl:pushctl/Push-v1")`` imports it).
"""

from __future__ import annotations

import importlib
import sys
from typing import TYPE_CHECKING, Any

from pushctl.machine import reproducible

if TYPE_CHECKING:
    from pushctl.contact.mlcp import MLCPResult, solve_box_mlcp
    from pushctl.contact.world import World, WorldConfig
    from pushctl.engines import make_world
    from pushctl.errors import ConfigError, MLCPInputError, PushctlError, StateError
    from pushctl.rl import ENV_ID
    from pushctl.types import StepResult

from pushctl.version import VERSION as __version__

_HOMES = {
    "ENV_ID": "pushctl.rl",
    "ConfigError": "pushctl.errors",
    "MLCPInputError": "pushctl.errors",
    "MLCPResult": "pushctl.contact.mlcp",
    "PushctlError": "pushctl.errors",
    "StateError": "pushctl.errors",
    "StepResult": "pushctl.types",
    "World": "pushctl.contact.world",
    "WorldConfig": "pushctl.contact.world",
    "make_world": "pushctl.engines",
    "solve_box_mlcp": "pushctl.contact.mlcp",
}
"""Where each public name lives: imported on first use (PEP 562)."""


def __getattr__(name: str) -> Any:
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module 'pushctl' has no attribute {name!r}")
    value = getattr(importlib.import_module(home), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_HOMES})


if "gymnasium" in sys.modules:  # registering loads nothing gymnasium has not loaded
    importlib.import_module("pushctl.rl")

__all__ = [
    "ENV_ID",
    "ConfigError",
    "MLCPInputError",
    "MLCPResult",
    "PushctlError",
    "StateError",
    "StepResult",
    "World",
    "WorldConfig",
    "__version__",
    "make_world",
    "reproducible",
    "solve_box_mlcp",
]

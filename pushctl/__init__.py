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
gymnasium in either order of the two imports: at once when gymnasium is already imported,
else as soon as gymnasium is (a hook on ``sys.meta_path`` that runs once, so that
``import pushctl`` does not load gymnasium, and with it numpy, before
:func:`reproducible` can run).
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
from types import ModuleType
from typing import TYPE_CHECKING, Any

from pushctl.machine import reproducible

if TYPE_CHECKING:
    from pushctl.contact.mlcp import MLCPResult, solve_box_mlcp
    from pushctl.contact.world import World, WorldConfig
    from pushctl.engines import make_world
    from pushctl.errors import ConfigError, MLCPInputError, PushctlError, StateError
    from pushctl.task import ENV_ID
    from pushctl.types import StepResult

from pushctl.version import VERSION as __version__

_HOMES = {
    "ENV_ID": "pushctl.task",
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


_REGISTRATION = "pushctl.task"
"""The module whose import registers the environment's ids with gymnasium."""


class _RegisterAfterGymnasium(importlib.abc.MetaPathFinder):
    """Finds nothing itself: when ``gymnasium`` is first imported, it takes itself off
    ``sys.meta_path``, lets the other finders find gymnasium, and has its loader import
    :data:`_REGISTRATION` right after gymnasium's module has run."""

    def find_spec(self, name: str, path: Any = None, target: Any = None) -> Any:
        if name != "gymnasium":
            return None
        sys.meta_path.remove(self)
        spec = importlib.util.find_spec(name)
        loader = spec.loader if spec is not None else None
        if loader is None or not hasattr(loader, "exec_module"):
            return spec
        run_gymnasium = loader.exec_module

        def exec_module(module: ModuleType) -> None:
            run_gymnasium(module)
            importlib.import_module(_REGISTRATION)

        loader.exec_module = exec_module  # type: ignore[method-assign]
        return spec


if "gymnasium" in sys.modules:  # registering loads nothing gymnasium has not loaded
    importlib.import_module(_REGISTRATION)
elif not any(isinstance(finder, _RegisterAfterGymnasium) for finder in sys.meta_path):
    sys.meta_path.insert(0, _RegisterAfterGymnasium())

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

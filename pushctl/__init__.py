"""pushctl: multi-point object pushing with a redundant arm.

The stable Python API (docs/model.md):

- :func:`make_world` builds arm + pusher + object + table; ``World.reset``/``World.step``.
- :func:`solve_box_mlcp` solves one box-friction mixed linear complementarity problem.
- ``import pushctl`` registers the gymnasium environment ``pushctl/Push-v0`` (:data:`ENV_ID`)::

      import gymnasium as gym, pushctl
      env = gym.make("pushctl/Push-v0")
"""

from pushctl.machine import pin_cpu_code

pin_cpu_code()  # before numpy loads: numpy's AVX2 code on any x86-64, so the same bytes

from pushctl.kernel_cache import drop_stale  # noqa: E402

drop_stale()  # before any kernel loads: numba's cache does not follow calls across files

from pushctl.contact.build import make_world  # noqa: E402
from pushctl.contact.mlcp import MLCPResult, solve_box_mlcp  # noqa: E402
from pushctl.contact.world import StepResult, World, WorldConfig  # noqa: E402
from pushctl.errors import ConfigError, MLCPInputError, PushctlError, StateError  # noqa: E402

# Importing pushctl.rl registers "pushctl/Push-v0" with a string entry point, so neither the
# environment module nor torch loads until gymnasium.make. Registration at import is what
# Gymnasium's own plugin packages do (ale_py, shimmy): Gymnasium 1.0 removed the entry-point
# plugin loader ("gymnasium.envs" group), so pyproject.toml declares none. Without an import,
# gymnasium.make("pushctl:pushctl/Push-v0") imports pushctl first (Gymnasium's module prefix).
from pushctl.rl import ENV_ID  # noqa: E402
from pushctl.version import VERSION as __version__  # noqa: E402

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
    "solve_box_mlcp",
]

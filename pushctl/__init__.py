"""pushctl: multi-point object pushing with a redundant arm.

The stable Python API (docs/model.md):

- :func:`make_world` builds arm + pusher + object + table; ``World.reset``/``World.step``.
- :func:`solve_box_mlcp` solves one box-friction mixed linear complementarity problem.
"""

from pushctl.contact.build import make_world
from pushctl.contact.mlcp import MLCPResult, solve_box_mlcp
from pushctl.contact.world import StepResult, World, WorldConfig
from pushctl.errors import ConfigError, MLCPInputError, PushctlError, StateError

__version__ = "0.1.0"

__all__ = [
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

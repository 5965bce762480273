"""MuJoCo as an independent plant (the only importer of ``mujoco``): the pushing scene built
from the project's specs and a world with the interface of :mod:`pushctl.contact.world`.

Build it with ``pushctl.make_world(..., engine="mujoco")``; see docs/mujoco.md.
"""

from pushctl.mujoco.scene import MujocoSettings
from pushctl.mujoco.world import MujocoWorld, MujocoWorldConfig

__all__ = ["MujocoSettings", "MujocoWorld", "MujocoWorldConfig"]

"""Pushing without an arm: a kinematic pusher (round prongs on a prescribed path) pushes a
convex slider resting on support points, through the world's own step
(:meth:`pushctl.contact.world.World.push`): one box-friction MLCP per step.

``push_along(shape, path, object_pose=..., dt=...)`` pushes a shape along a path;
:class:`KinematicPushWorld` steps the same world by hand. See docs/realdata.md.
"""

from pushctl.contact.world_config import FRICTION_MODELS
from pushctl.kinematic.push import PushTrace, push_along, straight_path
from pushctl.kinematic.shape import GRAVITY, PressurePrior, Slider
from pushctl.kinematic.world import (
    Friction,
    KinematicPushWorld,
    Pusher,
    StepReport,
)

__all__ = [
    "FRICTION_MODELS",
    "GRAVITY",
    "Friction",
    "KinematicPushWorld",
    "PressurePrior",
    "PushTrace",
    "Pusher",
    "Slider",
    "StepReport",
    "push_along",
    "straight_path",
]

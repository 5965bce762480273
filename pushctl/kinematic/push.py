"""Push this shape along this path: the one call most users want.

>>> import numpy as np
>>> from pushctl.kinematic import push_along, straight_path
>>> square = [(-0.045, -0.045), (0.045, -0.045), (0.045, 0.045), (-0.045, 0.045)]
>>> path = straight_path((-0.05, 0.0, 0.0), (0.0, 0.0, 0.0), speed=0.02, dt=0.05)
>>> trace = push_along(square, path, object_pose=(0.0, 0.0, 0.0), dt=0.05)
>>> bool(trace.poses[-1, 0] > 0.0)   # the square moved along +x
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from pushctl.errors import ConfigError
from pushctl.kinematic.shape import PressurePrior, Slider
from pushctl.kinematic.world import Friction, KinematicPushWorld, Pusher


@dataclass(frozen=True)
class PushTrace:
    """What a push did: ``poses`` (T, 3) the slider's pose-frame poses [m, m, rad] at the
    path's T samples, ``normal_force`` (T − 1, k) [N] per step and prong, ``converged``
    whether every step's MLCP verified."""

    poses: np.ndarray
    normal_force: np.ndarray
    converged: bool


def straight_path(start: ArrayLike, end: ArrayLike, speed: float, dt: float) -> np.ndarray:
    """Pusher poses (T, 3) moving from ``start`` to ``end`` (x, y, θ) at constant ``speed``
    [m/s] sampled every ``dt`` [s] (the last step may be shorter: the path ends at ``end``)."""
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    length = float(np.hypot(*(end[:2] - start[:2])))
    if not (speed > 0 and dt > 0):
        raise ConfigError(f"speed and dt must be positive, got {speed!r}, {dt!r}")
    steps = max(1, math.ceil(length / (speed * dt) - 1e-9))
    s = np.minimum(np.arange(steps + 1) * speed * dt / max(length, 1e-300), 1.0)
    return start + s[:, None] * (end - start)


def push_along(
    shape: Slider | ArrayLike,
    path: ArrayLike,
    *,
    object_pose: ArrayLike,
    dt: float,
    pusher: Pusher | None = None,
    friction: Friction | None = None,
    mass: float = 1.0,
    prior: PressurePrior | None = None,
) -> PushTrace:
    """Push ``shape`` with prongs whose pusher pose follows ``path``.

    Args:
        shape: a :class:`Slider`, or convex footprint vertices (V, 2) [m] in the object's
            pose frame (then ``mass`` [kg] and ``prior`` make the slider).
        path: pusher poses (T, 3) [m, m, rad], one every ``dt`` [s].
        object_pose: the slider's start pose (3,), at rest.
        pusher: the prongs (default: one 4.75 mm tip at the pusher frame's origin).
        friction: coefficients and ground model (default :class:`Friction`).

    Returns:
        A :class:`PushTrace`.
    """
    slider = shape if isinstance(shape, Slider) else Slider.from_vertices(shape, mass, prior)
    path = np.asarray(path, dtype=float)
    if path.ndim != 2 or path.shape[1] != 3 or len(path) < 2 or not np.isfinite(path).all():
        raise ConfigError(f"path must be (T >= 2, 3) finite pusher poses, got {path.shape}")
    world = KinematicPushWorld(slider, pusher or Pusher(), friction or Friction(), dt)
    world.reset(object_pose)
    poses = np.empty((len(path), 3))
    poses[0] = world.pose
    forces = np.zeros((len(path) - 1, len(world.pusher.offsets)))
    converged = True
    for i in range(len(path) - 1):
        report = world.step(path[i], path[i + 1])
        poses[i + 1] = world.pose
        forces[i] = report.normal_force
        converged &= report.converged
    return PushTrace(poses, forces, converged)

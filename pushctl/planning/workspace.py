"""Where the object starts and where the pusher has to be along a plan.

Default start (documented in docs/planning.md): the object sits straight in front of the arm's
ready configuration, heading 0 (pushed face towards the arm), its pushed face
``FACE_AHEAD_OF_READY`` = 76 mm ahead of the ready prongs along +x, on the ready pusher's y.
For the Kinova Gen2 7-DOF (ready pusher at x = 0.30 m) that puts the cube's centre of mass at
x = 0.420 m and the wedge's at 0.4227 m, inside the 0.40–0.45 m of docs/design.md §3, which
keeps every evaluation target (up to 0.25 m further) within the arm's reach.

During the push the pusher frame (the prongs' midpoint on the plate's front face) sits on
the pushed face at the plan's offset δ, at the object's centre-of-mass height, x along the
face's inward normal: its world pose follows from the planned object pose alone.
"""

from __future__ import annotations

import numpy as np

from pushctl.objects import ObjectSpec
from pushctl.types import PlanarPose

FACE_AHEAD_OF_READY = 0.076
"""Distance [m] from the ready prongs to the object's pushed face at the default start."""


def default_start(obj: ObjectSpec, ready_pusher_position: np.ndarray) -> PlanarPose:
    """The default start pose of ``obj`` in front of an arm whose ready pusher frame is at
    ``ready_pusher_position`` (3,) [m]."""
    x = float(ready_pusher_position[0]) + FACE_AHEAD_OF_READY + obj.face_offset
    return PlanarPose(x, float(ready_pusher_position[1]), 0.0)


def pusher_path(obj: ObjectSpec, poses: np.ndarray, offset: float) -> tuple[np.ndarray, np.ndarray]:
    """Pusher frame positions (N, 3) [m] and yaws (N,) [rad] that put the prongs on the
    pushed face at plate offset ``offset`` [m] for object poses ``poses`` (N, 3)."""
    cos, sin = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    local_n, local_t = -obj.face_offset, offset
    x = poses[:, 0] + cos * local_n - sin * local_t
    y = poses[:, 1] + sin * local_n + cos * local_t
    return np.column_stack([x, y, np.full(len(poses), obj.com_height)]), poses[:, 2].copy()

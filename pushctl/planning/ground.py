"""Ground friction on a sliding object, from the simulator's support-point model.

The object's weight rests on its support points with loads ``ObjectSpec.support_loads``
(static equilibrium, the same the world uses). A point that slides feels μ_g·N_j against
its slip direction (the world's slip-aligned friction box with the cross row released). The
planner evaluates this at the planned motion; the slip direction of each point is taken
from the motion's geometric direction (dp/ds, dθ/ds), which is the limit of the velocity's
direction as the speed goes to 0, so a plan that starts or ends at rest still knows which
way friction will act when it moves (docs/design.md §4).
"""

from __future__ import annotations

import numpy as np

from pushctl.config import GRAVITY
from pushctl.objects import ObjectSpec

# A support point moving slower than this fraction of the fastest one [-] is at the
# instant centre and feels no kinetic friction.
_AT_ICR = 1e-12


def sliding_friction(
    obj: ObjectSpec,
    mu_ground: float,
    pose: np.ndarray,
    direction: np.ndarray,
    gravity: float = GRAVITY,
    limits: np.ndarray | None = None,
) -> np.ndarray:
    """Ground friction wrench on the object at each pose, world frame, (N, 3) [N, N, N·m].

    ``pose`` (N, 3) (x, y, θ); ``direction`` (N, 3) a twist (vx, vy, ω) giving only the
    direction of motion (any positive scale; the magnitude of friction does not depend on
    speed). The torque is about the centre of mass. A row of zeros in ``direction`` gives
    zero friction (an object at rest can hold any friction up to the limit). ``limits``
    (N, S) [N]: each support point's sliding friction μ_j N_j per pose, in place of the
    uniform μ_g N_j (a plant with friction varying over the table).
    """
    supports = np.asarray(obj.support_points, dtype=float)  # (S, 2) local
    if limits is None:
        limits = mu_ground * np.asarray(obj.support_loads) * (gravity / GRAVITY)  # (S,)
    cos, sin = np.cos(pose[:, 2]), np.sin(pose[:, 2])
    # support points relative to the centre of mass, world axes: (N, S, 2)
    rx = cos[:, None] * supports[:, 0] - sin[:, None] * supports[:, 1]
    ry = sin[:, None] * supports[:, 0] + cos[:, None] * supports[:, 1]
    omega = direction[:, 2:3]
    ux = direction[:, 0:1] - omega * ry  # point velocity direction: v + ω × r
    uy = direction[:, 1:2] + omega * rx
    speed = np.hypot(ux, uy)
    moving = speed > _AT_ICR * np.maximum(speed.max(axis=1, keepdims=True), 1e-300)
    scale = np.where(moving, limits / np.where(moving, speed, 1.0), 0.0)
    fx, fy = -scale * ux, -scale * uy
    torque = rx * fy - ry * fx
    return np.column_stack([fx.sum(axis=1), fy.sum(axis=1), torque.sum(axis=1)])

"""A world with a kinematic pusher: the prongs follow a prescribed path and only the slider
is dynamic. It is :class:`pushctl.contact.world.World` without an arm, stepped by
:meth:`~pushctl.contact.world.World.push`: the same contact rows, ground friction models
and MLCP solve as the arm's world (docs/model.md); this module adds the pusher's geometry
(round prongs in a pusher frame) and the slider's pose frame.

Per step, in impulses p = h λ [N·s] over the slider's centroid velocity u = (vx, vy, ω):
per prong within reach of the footprint, a unilateral normal row (signed distance to the
polygon minus the prong's radius; a gap may close within the step) and a tangential row
with |p_t| ≤ μ_c p_n, the prong's prescribed velocity in the rows' free velocity; per
support point j (load N_j from the pressure prior), ground friction of bound h μ_g N_j in
one of the world's models (:data:`~pushctl.contact.world_config.FRICTION_MODELS`): the
slip-aligned box, the polygon fixed to the table, or the box along the table's axes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from pushctl.contact.world import World, WorldConfig
from pushctl.errors import ConfigError
from pushctl.kinematic.shape import Slider


@dataclass(frozen=True)
class Pusher:
    """Round prongs rigidly attached to a pusher frame.

    - ``offsets``: (k, 2) prong centres in the pusher frame [m]; (0, 0) for one tip. The
      pusher frame's x axis is its push direction θ.
    - ``radius``: prong radius [m] (> 0).
    """

    offsets: tuple[tuple[float, float], ...] = ((0.0, 0.0),)
    radius: float = 4.75e-3

    def __post_init__(self) -> None:
        arr = np.asarray(self.offsets, dtype=float)
        if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) < 1 or not np.isfinite(arr).all():
            raise ConfigError(
                f"pusher offsets must be k >= 1 finite (x, y) pairs [m], got {self.offsets!r}"
            )
        if not (math.isfinite(self.radius) and self.radius > 0):
            raise ConfigError(f"prong radius must be positive [m], got {self.radius!r}")

    @classmethod
    def row(cls, count: int, spacing: float, radius: float) -> Pusher:
        """``count`` prongs ``spacing`` [m] apart across the push direction, centred."""
        ys = (np.arange(count) - (count - 1) / 2) * spacing
        return cls(tuple((0.0, float(y)) for y in ys), radius)

    def prong_positions(self, pose: np.ndarray) -> np.ndarray:
        """Pusher poses (..., 3) → prong centres (..., k, 2) [m] in the world."""
        pose = np.asarray(pose, dtype=float)
        off = np.asarray(self.offsets)
        c, s = np.cos(pose[..., 2])[..., None], np.sin(pose[..., 2])[..., None]
        x = pose[..., 0:1] + c * off[:, 0] - s * off[:, 1]
        y = pose[..., 1:2] + s * off[:, 0] + c * off[:, 1]
        return np.stack((x, y), -1)


@dataclass(frozen=True)
class Friction:
    """Friction coefficients and the ground model.

    - ``mu_contact``: prong–object μ_c [-]; ``mu_ground``: object–table μ_g [-].
    - ``model``: one of the world's
      :data:`~pushctl.contact.world_config.FRICTION_MODELS`; ``polygon`` by default (the
      world's own default, ``slip_box``, does not settle when friction stops the slider
      within a step, as in slow pushes with long steps: docs/model.md); ``facets``: the
      polygon's sides (a multiple of 4, >= 8).
    """

    mu_contact: float = 0.25
    mu_ground: float = 0.3
    model: str = "polygon"
    facets: int = 8

    def __post_init__(self) -> None:
        self.world_config(1.0)  # the world's checks, one message each

    def world_config(self, dt: float) -> WorldConfig:
        """The world's settings for these coefficients and this model, step ``dt`` [s]."""
        return WorldConfig(
            dt=dt,
            mu_ground=self.mu_ground,
            mu_contact=self.mu_contact,
            friction_model=self.model,
            facets=self.facets,
        )


@dataclass(frozen=True)
class StepReport:
    """One step's contact outcome: normal and tangential forces (k,) [N] per prong (0
    without contact; tangential along the contact normal turned +90°), whether the MLCP
    verified, and how many MLCPs were solved."""

    normal_force: np.ndarray
    tangential_force: np.ndarray
    converged: bool
    solves: int


class KinematicPushWorld:
    """A slider on a table pushed by prongs whose motion is prescribed.

    Args:
        slider: the object (:class:`~pushctl.kinematic.shape.Slider`).
        pusher: the prongs.
        friction: coefficients and ground model.
        dt: step [s] (> 0).

    ``world`` is the :class:`~pushctl.contact.world.World` it steps.
    """

    def __init__(self, slider: Slider, pusher: Pusher, friction: Friction, dt: float) -> None:
        if not (math.isfinite(dt) and dt > 0):
            raise ConfigError(f"dt must be positive [s], got {dt!r}")
        self.slider, self.pusher, self.friction, self.dt = slider, pusher, friction, float(dt)
        self.world = World(slider, None, friction.world_config(self.dt))  # type: ignore[arg-type]
        self.reset(np.zeros(3))

    def reset(self, object_pose: ArrayLike) -> None:
        """Place the slider at rest at ``object_pose`` (x, y, θ) of its pose frame."""
        self.world.reset(self.slider.centroid_pose(np.asarray(object_pose, dtype=float)))

    @property
    def pose(self) -> np.ndarray:
        """The slider's pose-frame pose (3,) [m, m, rad]."""
        return self.slider.frame_pose(self.world.object_pose)

    @property
    def velocity(self) -> np.ndarray:
        """The slider's centroid velocity (vx, vy, ω) (3,) [m/s, m/s, rad/s]."""
        return self.world.object_velocity

    def step(self, pusher_pose: ArrayLike, next_pusher_pose: ArrayLike) -> StepReport:
        """Advance one step while the pusher moves from ``pusher_pose`` to
        ``next_pusher_pose`` (each (3,) [m, m, rad])."""
        p0 = self.pusher.prong_positions(np.asarray(pusher_pose, dtype=float))
        p1 = self.pusher.prong_positions(np.asarray(next_pusher_pose, dtype=float))
        solves = self.world.stats.solves
        result = self.world.push(p0, (p1 - p0) / self.dt, self.pusher.radius)
        forces = result.contact_forces
        return StepReport(
            forces[:, 0].copy(),
            forces[:, 1].copy(),
            bool(result.mlcp_converged),
            self.world.stats.solves - solves,
        )

"""Where the pusher frame should be, and how fast it should move, at every control step.

The pusher frame (origin at the prongs' midpoint on the plate's front face, x along the push,
z up; :mod:`pushctl.arm.pusher`) is held level: its desired orientation is a pure yaw. Two
references drive it: the push (the plan's object poses carried onto the pushed face at the
plan's prong offset) and the approach (a minimum-jerk move from wherever the arm is to the
first pose of the push).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pushctl.errors import ConfigError
from pushctl.planning.plan import Plan


@dataclass(frozen=True)
class PusherReference:
    """A sampled pusher-frame reference, N samples ``dt`` [s] apart.

    ``position`` (N, 3) [m] and ``yaw`` (N,) [rad], world frame; ``linear_velocity`` (N, 3)
    [m/s] and ``yaw_rate`` (N,) [rad/s]: the feed-forward twist at each sample.
    """

    dt: float
    position: np.ndarray
    yaw: np.ndarray
    linear_velocity: np.ndarray
    yaw_rate: np.ndarray

    def __len__(self) -> int:
        return len(self.yaw)

    @property
    def twist(self) -> np.ndarray:
        """Feed-forward twists (N, 6) [m/s, rad/s], rows [linear; angular], world axes."""
        angular = np.zeros((len(self), 3))
        angular[:, 2] = self.yaw_rate
        return np.hstack([self.linear_velocity, angular])


def push_reference(plan: Plan) -> PusherReference:
    """The pusher reference of a plan: its ``pusher_positions`` and ``pusher_yaws``, with
    the velocity of the pusher origin as a point of the object, v + ω × (p_pusher − p)."""
    trajectory = plan.trajectory
    velocity = trajectory.velocity  # (N, 3): vx, vy, ω
    lever = plan.pusher_positions[:, :2] - trajectory.pose[:, :2]
    linear = np.zeros((len(velocity), 3))
    linear[:, 0] = velocity[:, 0] - velocity[:, 2] * lever[:, 1]
    linear[:, 1] = velocity[:, 1] + velocity[:, 2] * lever[:, 0]
    return PusherReference(
        dt=trajectory.dt,
        position=plan.pusher_positions.copy(),
        yaw=plan.pusher_yaws.copy(),
        linear_velocity=linear,
        yaw_rate=velocity[:, 2].copy(),
    )


def minimum_jerk(
    start_position: np.ndarray,
    start_yaw: float,
    end_position: np.ndarray,
    end_yaw: float,
    duration: float,
    dt: float,
) -> PusherReference:
    """A minimum-jerk move from rest to rest: s(τ) = 10τ³ − 15τ⁴ + 6τ⁵ along the straight
    line and the yaw difference, sampled at t = 0, dt, …, duration (inclusive)."""
    if not (math.isfinite(duration) and duration > 0.0 and math.isfinite(dt) and dt > 0.0):
        raise ConfigError(f"a move needs duration > 0 and dt > 0 s, got {duration!r}, {dt!r}")
    steps = max(1, round(duration / dt))
    tau = np.linspace(0.0, 1.0, steps + 1)
    s = tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2)
    ds = 30.0 * tau**2 * (1.0 - tau) ** 2 / (steps * dt)
    start_position = np.asarray(start_position, dtype=float)
    delta = np.asarray(end_position, dtype=float) - start_position
    delta_yaw = end_yaw - start_yaw
    return PusherReference(
        dt=dt,
        position=start_position + s[:, None] * delta,
        yaw=start_yaw + s * delta_yaw,
        linear_velocity=ds[:, None] * delta,
        yaw_rate=ds * delta_yaw,
    )


def hold(position: np.ndarray, yaw: float, steps: int, dt: float) -> PusherReference:
    """Stay at ``position`` (3,) [m], ``yaw`` [rad] for ``steps`` + 1 samples."""
    n = steps + 1
    return PusherReference(
        dt=dt,
        position=np.tile(np.asarray(position, dtype=float), (n, 1)),
        yaw=np.full(n, float(yaw)),
        linear_velocity=np.zeros((n, 3)),
        yaw_rate=np.zeros(n),
    )


def concatenate(*parts: PusherReference) -> PusherReference:
    """References one after the other; each part's first sample replaces the previous
    part's last (they are meant to meet there)."""
    if not parts:
        raise ConfigError("concatenate needs at least one reference")
    dt = parts[0].dt
    first, *rest = parts
    arrays = [[first.position], [first.yaw], [first.linear_velocity], [first.yaw_rate]]
    for part in rest:
        if not math.isclose(part.dt, dt, rel_tol=1e-12):
            raise ConfigError(f"references with different steps: {dt} s and {part.dt} s")
        for target in arrays:
            target[-1] = target[-1][:-1]
        arrays[0].append(part.position)
        arrays[1].append(part.yaw)
        arrays[2].append(part.linear_velocity)
        arrays[3].append(part.yaw_rate)
    return PusherReference(dt, *(np.concatenate(items) for items in arrays))

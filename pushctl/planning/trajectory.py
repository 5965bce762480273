"""The instant-centre-of-rotation arc from a start pose to a goal pose (docs/design.md §4).

For Δθ ≠ 0 the ICR is the unique point c with R(Δθ)(p0 − c) + c = p1: rotating the start
pose by Δθ about c gives the goal, every point of the body moves on a circle about c, and
the planned pose after arc fraction s is

    p(s) = c + R(s Δθ)(p0 − c),      θ(s) = θ0 + s Δθ.

Written with complex numbers (z = x + i y, d = p1 − p0) this is

    p(s) = p0 + (e^{i s Δθ} − 1) / (e^{i Δθ} − 1) · d
         = p0 + s · sinc(s Δθ/2) / sinc(Δθ/2) · e^{i (s − 1) Δθ/2} · d,

which has no division by zero and tends to the straight line p0 + s d as Δθ → 0
(sinc x = sin x / x). Its derivatives in s are p'(s) = e^{i (s − ½) Δθ} d / sinc(Δθ/2) and
p''(s) = i Δθ p'(s); time derivatives follow from the profile's ṡ and s̈ by the chain rule,
so velocities and accelerations are analytic, never finite differences.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pushctl.errors import ConfigError
from pushctl.planning.profiles import AngularProfile, make_profile
from pushctl.types import PlanarPose

MAX_STEPS = 1_000_000
"""Longest plan accepted [steps]; 20 s at 0.01 s is 2000."""

# Below this |Δθ| [rad] the ICR is reported as absent (it lies beyond 1e9 × |d|).
_STRAIGHT = 1e-9


def _sinc(x: np.ndarray | float) -> np.ndarray:
    """sin(x)/x with the limit 1 at 0 (numpy's sinc is sin(πx)/(πx))."""
    return np.sinc(np.asarray(x, dtype=float) / math.pi)


def _rotate(angle: np.ndarray, vector: np.ndarray) -> np.ndarray:
    """Rotate the 2-vector ``vector`` by each of ``angle`` (N,) → (N, 2)."""
    cos, sin = np.cos(angle), np.sin(angle)
    return np.column_stack([cos * vector[0] - sin * vector[1], sin * vector[0] + cos * vector[1]])


def _perp(vectors: np.ndarray) -> np.ndarray:
    """e_z × v for each row of ``vectors`` (N, 2)."""
    return np.column_stack([-vectors[:, 1], vectors[:, 0]])


@dataclass(frozen=True)
class Trajectory:
    """A planned push, sampled at ``t = k·dt`` for k = 0 … n_steps (both ends included).

    ``t`` (N,) [s]; ``s`` (N,) arc fraction [-]; ``pose`` (N, 3) (x, y, θ) [m, m, rad];
    ``velocity`` (N, 3) (vx, vy, ω) [m/s, m/s, rad/s]; ``acceleration`` (N, 3)
    [m/s², m/s², rad/s²]; all in the world frame. ``path_tangent`` (N, 2) is dp/ds [m]: the
    direction the centre of mass moves in, defined even where ṡ = 0. ``icr`` (2,) [m] is
    the instant centre of rotation, ``None`` for a straight translation.
    """

    start: PlanarPose
    goal: PlanarPose
    profile: str
    duration: float
    dt: float
    t: np.ndarray
    s: np.ndarray
    pose: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    path_tangent: np.ndarray
    icr: np.ndarray | None

    @property
    def n_steps(self) -> int:
        """Number of control steps (samples − 1)."""
        return len(self.t) - 1

    @property
    def delta_theta(self) -> float:
        """Rotation from start to goal [rad], in (−π, π]."""
        return self.goal.theta - self.start.theta

    @property
    def displacement(self) -> np.ndarray:
        """Goal minus start position (2,) [m]."""
        return np.array([self.goal.x - self.start.x, self.goal.y - self.start.y])

    @property
    def radius(self) -> float:
        """Radius of the centre of mass's circle [m]; ``inf`` for a straight push."""
        half = 0.5 * self.delta_theta
        if abs(half) < 0.5 * _STRAIGHT:
            return math.inf
        return float(np.linalg.norm(self.displacement)) / (2.0 * abs(math.sin(half)))

    @property
    def arc_length(self) -> float:
        """Length of the centre of mass's path [m] (= radius·|Δθ|, or |d| when straight)."""
        return float(np.linalg.norm(self.displacement) / _sinc(0.5 * self.delta_theta))

    @property
    def push_angle(self) -> float:
        """Direction of the centre of mass's motion relative to the pushed face's inward
        normal e_n [rad]; constant along the arc (the body turns with its path).
        NaN for a pure rotation (the centre of mass does not move)."""
        d = self.displacement
        if not np.any(d):
            return math.nan
        angle = math.atan2(d[1], d[0]) - self.start.theta - 0.5 * self.delta_theta
        return math.remainder(angle, 2.0 * math.pi)


def instant_centre(start: PlanarPose, goal: PlanarPose) -> np.ndarray | None:
    """The ICR c (2,) [m] with R(Δθ)(p0 − c) + c = p1, or None when Δθ is (numerically) 0."""
    delta = goal.theta - start.theta
    if abs(delta) < _STRAIGHT:
        return None
    p0 = complex(start.x, start.y)
    d = complex(goal.x - start.x, goal.y - start.y)
    # p0 − c = d / (e^{iΔθ} − 1) = d e^{−iΔθ/2} / (2i sin(Δθ/2))
    c = p0 - d * complex(math.cos(-0.5 * delta), math.sin(-0.5 * delta)) / (
        2j * math.sin(0.5 * delta)
    )
    return np.array([c.real, c.imag])


def step_count(duration: float, dt: float) -> int:
    """Number of steps of ``dt`` in ``duration``; ConfigError unless both are positive and
    ``duration`` is a whole number of steps (to 1e-9 relative)."""
    for label, value in (("duration", duration), ("dt", dt)):
        if not (isinstance(value, int | float) and math.isfinite(value) and value > 0.0):
            raise ConfigError(f"{label} must be a positive number of seconds, got {value!r}")
    n = round(duration / dt)
    if n < 1 or abs(n * dt - duration) > 1e-9 * duration:
        raise ConfigError(
            f"duration {duration} s must be a whole number (>= 1) of steps of dt = {dt} s"
        )
    if n > MAX_STEPS:
        raise ConfigError(f"duration / dt = {n} steps; at most {MAX_STEPS} are accepted")
    return n


def check_rotation(start: PlanarPose, goal: PlanarPose) -> float:
    """Δθ [rad]; ConfigError for a non-finite pose or |Δθ| > π (turn the other way instead)."""
    for label, pose in (("start", start), ("goal", goal)):
        if not np.all(np.isfinite(pose.as_array())):
            raise ConfigError(f"{label} pose must be finite numbers, got {pose}")
    delta = goal.theta - start.theta
    if abs(delta) > math.pi + 1e-12:
        raise ConfigError(
            f"the goal turns the object by {math.degrees(delta):.1f} deg; "
            "accepted: -180 to 180 deg from the start heading"
        )
    return delta


def plan_icr(
    start: PlanarPose,
    goal: PlanarPose,
    duration: float,
    dt: float,
    profile: str | AngularProfile = "constant",
) -> Trajectory:
    """Plan the ICR arc from ``start`` to ``goal`` in ``duration`` [s] sampled every ``dt``
    [s], timed by ``profile`` (a name from ``PROFILE_NAMES`` or an :class:`AngularProfile`).

    Raises ConfigError for non-positive or mismatched times and |Δθ| > 180°.
    """
    n = step_count(duration, dt)
    delta = check_rotation(start, goal)
    profile = make_profile(profile) if isinstance(profile, str) else profile
    t = dt * np.arange(n + 1)
    s, ds_dtau, dds_dtau = profile.evaluate(t / duration)
    s_dot, s_ddot = ds_dtau / duration, dds_dtau / duration**2

    d = np.array([goal.x - start.x, goal.y - start.y])
    scale = _sinc(0.5 * delta)
    position = start.as_array()[:2] + (s * _sinc(0.5 * s * delta) / scale)[:, None] * _rotate(
        0.5 * (s - 1.0) * delta, d
    )
    tangent = _rotate((s - 0.5) * delta, d) / scale  # dp/ds
    curvature_term = delta * _perp(tangent)  # d²p/ds²
    velocity = tangent * s_dot[:, None]
    acceleration = tangent * s_ddot[:, None] + curvature_term * (s_dot**2)[:, None]

    pose = np.column_stack([position, start.theta + delta * s])
    twist = np.column_stack([velocity, delta * s_dot])
    accel = np.column_stack([acceleration, delta * s_ddot])
    return Trajectory(
        start=start,
        goal=goal,
        profile=profile.name,
        duration=float(duration),
        dt=float(dt),
        t=t,
        s=s,
        pose=pose,
        velocity=twist,
        acceleration=accel,
        path_tangent=tangent,
        icr=instant_centre(start, goal),
    )

"""The approach before a push, and the paths a re-landing reuses: from the ready
configuration to the prongs touching the pushed face at the plan's offset (not part of the
trace or the metrics). :class:`~pushctl.episode.runner.Episode` servos its PD along them."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pushctl.control.reference import PusherReference, concatenate, hold, minimum_jerk
from pushctl.errors import ConfigError


@dataclass(frozen=True)
class ApproachSettings:
    """The approach, from the ready configuration to the prongs touching the pushed face at
    the plan's offset (not part of the trace or the metrics): a minimum-jerk move of
    ``move_time`` [s] to ``standoff`` [m] behind the face, then one of ``creep_time`` [s] onto
    it, then ``settle_time`` [s] holding there."""

    standoff: float = 0.010
    move_time: float = 2.0
    creep_time: float = 1.0
    settle_time: float = 0.2

    def __post_init__(self) -> None:
        for name in ("standoff", "move_time", "creep_time", "settle_time"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ConfigError(f"approach {name} must be finite and >= 0, got {value!r}")
        if self.move_time <= 0.0 or self.creep_time <= 0.0:
            raise ConfigError("approach move_time and creep_time must be > 0 s")


def standoff_point(settings: ApproachSettings, contact: np.ndarray, yaw: float) -> np.ndarray:
    """The point (3,) [m] the approach's ``standoff`` behind ``contact`` along the face
    normal of a plate at ``yaw`` [rad]."""
    normal = np.array([math.cos(yaw), math.sin(yaw), 0.0])
    return contact - settings.standoff * normal


def onto_face(
    settings: ApproachSettings, dt: float, standoff: np.ndarray, contact: np.ndarray, yaw: float
) -> list[PusherReference]:
    """A landing's last parts: the creep from ``standoff`` onto ``contact``
    (``creep_time``), then ``settle_time`` holding there; ``dt`` [s] the step."""
    parts = [minimum_jerk(standoff, yaw, contact, yaw, settings.creep_time, dt)]
    settle_steps = round(settings.settle_time / dt)
    if settle_steps:
        parts.append(hold(contact, yaw, settle_steps, dt))
    return parts


def approach_path(
    settings: ApproachSettings,
    dt: float,
    ready_position: np.ndarray,
    ready_rotation: np.ndarray,
    contact: np.ndarray,
    yaw: float,
) -> PusherReference:
    """Ready pose (the pusher at ``ready_position`` (3,) [m] with rotation ``ready_rotation``
    (3, 3)) → standoff → touching at ``contact`` (3,) [m] with the plate at ``yaw`` [rad] →
    settle."""
    standoff = standoff_point(settings, contact, yaw)
    ready_yaw = math.atan2(ready_rotation[1, 0], ready_rotation[0, 0])
    parts = [
        minimum_jerk(ready_position, ready_yaw, standoff, yaw, settings.move_time, dt),
        *onto_face(settings, dt, standoff, contact, yaw),
    ]
    return concatenate(*parts)

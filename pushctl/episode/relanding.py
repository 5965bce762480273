"""Putting the prongs back on the plan's spot of the face, for controllers that read the
object's pose (docs/plant-unknowns.md, "Re-landing").

The approach aims at the object's *believed* pose, so a placement error lands the prongs
off the plan's spot across the face (:mod:`pushctl.episode.landed`), and once they stick no
controller moves them back without sliding. A controller that reads the object's pose can
do what a person would: lift the plate off the face, move it across by the distance the
measurement says, and put it back. Then the prongs push where the plan's force distribution
assumed they would, and the pose error left is one the object, locked to the plate, follows
the plate out of. PD-only (the paper's π_H) stays open loop in the object's pose: it pushes
from where the approach landed.

Only the component across the plate is corrected. Along the push the creep closes any gap
itself, and the plate's yaw turns the object flat against it when both prongs bear.
"""

from __future__ import annotations

import math

import numpy as np

from pushctl.episode.proxy import ProxyEffects, camera_frames, draw_camera_noise, proxy_rng

LANDING_PURPOSE = "landing"
"""The proxy generator's purpose (:func:`~pushctl.episode.proxy.proxy_rng`) of the camera
frames read while the plate backs off: their own stream, so the push's frames, and PD-only's
run of the same scenario, are the same with and without a re-landing."""


def landing_shift(
    believed_start: np.ndarray,
    measured: np.ndarray,
    contact: np.ndarray,
    yaw: float,
    bound: float = math.inf,
) -> np.ndarray:
    """The plate's move (3,) [m] (world x, y, z = 0) across its face that puts the plan's
    contact spot back on the object as measured.

    ``believed_start`` (3,) [m, m, rad]: the pose the plan starts from (where the approach
    aimed); ``measured`` (3,): the object's pose as the controller reads it; ``contact``
    (2+,) [m]: the pusher origin's position at the plan's start (world x, y); ``yaw``
    [rad]: the plate's yaw there (its face normal is (cos yaw, sin yaw)). The plan's spot,
    fixed to the object, is carried from the believed pose to the measured one; of its move
    only the part along the plate's face is kept (along the normal the creep closes the
    gap). ``bound`` [m]: the largest x or y component (the reference offset's bound, which
    then holds the plate there); a longer move is shortened along its own direction."""
    b = np.asarray(believed_start, dtype=float)
    m = np.asarray(measured, dtype=float)
    # the spot turns with the object about its centre and moves with it
    dx, dy = float(contact[0]) - b[0], float(contact[1]) - b[1]
    c, s = math.cos(m[2] - b[2]), math.sin(m[2] - b[2])
    move_x = (m[0] - b[0]) + (c * dx - s * dy - dx)
    move_y = (m[1] - b[1]) + (s * dx + c * dy - dy)
    tangent = (-math.sin(yaw), math.cos(yaw))
    across = move_x * tangent[0] + move_y * tangent[1]
    shift = np.array([across * tangent[0], across * tangent[1], 0.0])
    largest = float(np.max(np.abs(shift[:2])))
    if largest > bound:
        shift *= bound / largest
    return shift


def camera_noise_at_rest(
    effects: ProxyEffects, duration: float, seed: int | None, case: str
) -> np.ndarray:
    """The mean noise (3,) [m, m, rad] of the proxy camera's frames over ``duration`` [s]
    of an object at rest (the plate backing off), from their own generator
    (:data:`LANDING_PURPOSE`; ``seed`` and ``case``, object/profile, name it)."""
    frames = camera_frames(duration, effects.camera_rate)
    rng = proxy_rng(seed, LANDING_PURPOSE, case)
    return draw_camera_noise(effects, frames, rng).mean(axis=0)

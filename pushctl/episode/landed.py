"""Where the prongs landed on the face, and the force error against what the plant needed
with the prongs there (docs/plant-unknowns.md).

The approach aims at the object's *believed* pose, so a placement error lands the prongs
off the plan's spot across the face, and once they stick no controller moves them back
without sliding. ``force_error``'s reference (:attr:`Episode.plant_forces`) puts the plate
at the plan's spot: with both prongs sticking, the torque the object needs is balanced by a
different split of the normal forces where they really are (the split moves by 2 N s / d
for total normal force N, prong spacing d and landing shift s), so part of that error is the
reference's and no controller can remove it. ``force_error_landed`` recomputes the plant's
needs with the plate where it landed (:data:`LANDED_AT` into the push) and measures against
that: what a controller could still have changed, given where its prongs are.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from pushctl.episode.trace import Trace

if TYPE_CHECKING:
    from pushctl.episode.runner import Episode

LANDED_AT = 0.5
"""[s] into the push: where the prongs sit then is where they landed (both carry load)."""


def spot_offset(trace: Trace, row: int) -> float:
    """How far across the push [m] the pusher origin sits on the object at trace ``row``,
    against where the plan puts it: the object-frame y of (pusher − object) minus the
    plan's (desired pusher − desired pose). From the true object pose (also on the proxy)."""

    def across(pusher: np.ndarray, pose: np.ndarray) -> float:
        dx, dy = pusher[0] - pose[0], pusher[1] - pose[1]
        return float(-np.sin(pose[2]) * dx + np.cos(pose[2]) * dy)

    actual = across(np.asarray(trace.pusher_position[row]), np.asarray(trace.object_pose[row]))
    planned = across(
        np.asarray(trace.pusher_position_des[row]), np.asarray(trace.desired_pose[row])
    )
    return actual - planned


def landed(trace: Trace) -> float:
    """Where the prongs landed across the face [m]: :func:`spot_offset` at :data:`LANDED_AT`
    (the last row of a shorter trace)."""
    row = min(int(np.searchsorted(np.asarray(trace.t), LANDED_AT)), trace.n_steps)
    return spot_offset(trace, row)


def landed_force_error(episode: Episode, trace: Trace) -> tuple[float, float]:
    """(where the prongs landed [m], ``force_error_landed`` [N]) of ``episode``'s finished
    push ``trace``: the mean over rows 1 … N and prongs of ‖F_landed,i − λ_i‖₂, where
    F_landed are the plant's needs (:meth:`Episode.plant_forces_at`) with the plate where
    it landed (:func:`landed`): one force distribution over the plan."""
    shift = landed(trace)
    rows = slice(1, trace.n_steps + 1)
    needed = episode.plant_forces_at(shift).forces[rows]  # (N, k, 2)
    measured = np.asarray(trace.contact_forces, dtype=float)[rows]  # (N, k, 2)
    return shift, float(np.mean(np.linalg.norm(needed - measured, axis=2)))

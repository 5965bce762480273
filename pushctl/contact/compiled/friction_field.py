"""The friction field's per-step arithmetic, compiled
(:class:`~pushctl.contact.ground_field.FrictionField`): its multiplier at points, at an
object's support points, and the world's friction bounds with the warm start rescaled."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def update_support_bounds(
    pose, support_points, wavevectors, phases, amplitude, variation, uniform, limits, guess,
    scaled,
):  # fmt: skip
    """``FrictionField.update_support_bounds``, writing ``limits`` and ``scaled`` (the
    caller's arrays: numba's boxing of returned arrays costs more)."""
    new = uniform * support_multiplier(
        pose, support_points, wavevectors, phases, amplitude, variation
    )
    if guess.shape[0]:
        scaled[:] = guess
        n_support = new.shape[0]
        start = guess.shape[0] - 2 * n_support
        for j in range(n_support):
            ratio = new[j] / max(limits[j], 1e-300)
            scaled[start + 2 * j] *= ratio
            scaled[start + 2 * j + 1] *= ratio
    limits[:] = new


@njit(cache=True)
def support_multiplier(pose, support_points, wavevectors, phases, amplitude, variation):
    """``support_positions`` of one pose, then :func:`multiplier`."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    points = np.empty_like(support_points)
    for j in range(support_points.shape[0]):
        px, py = support_points[j, 0], support_points[j, 1]
        points[j, 0] = pose[0] + c * px - s * py
        points[j, 1] = pose[1] + s * px + c * py
    return multiplier(points, wavevectors, phases, amplitude, variation)


@njit(cache=True)
def multiplier(points, wavevectors, phases, amplitude, variation):
    """``FrictionField.__call__`` for points (S, 2): 1 + a tanh(f/2), f the mode sum."""
    out = np.empty(points.shape[0])
    for j in range(points.shape[0]):
        total = 0.0
        for m in range(phases.shape[0]):
            total += math.cos(
                points[j, 0] * wavevectors[m, 0] + points[j, 1] * wavevectors[m, 1] + phases[m]
            )
        out[j] = 1.0 + variation * math.tanh(0.5 * amplitude * total)
    return out

"""Prongs on a prescribed path, the other source of pusher motion besides an arm: their
contact geometry and the step state the world's kernels take (:meth:`World.push
<pushctl.contact.world.World.push>`).

With no arm the kernels read ``v_arm`` as the prescribed velocities of the prongs in
contact (:func:`~pushctl.contact.compiled.assembly.prescribed_part`): the rows are an arm
prong's, with the prescribed velocity in place of the arm's free velocity and no inverse
mass."""

from __future__ import annotations

import math

import numpy as np

from pushctl.contact.rows import mask_indices, prong_geometry
from pushctl.contact.step_solver import StepSolver, StepState
from pushctl.contact.world_config import WorldConfig
from pushctl.errors import StateError

_NO_ARM_MATRIX = np.zeros((0, 0))
_NO_ARM_VECTOR = np.zeros(0)


def checked_prongs(positions, velocities, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """``positions`` and ``velocities`` as C-contiguous (k, 2) float arrays, k >= 1, finite;
    ``radius`` finite and >= 0. StateError naming what is wrong otherwise."""
    pos = np.ascontiguousarray(positions, dtype=float)
    vel = np.ascontiguousarray(velocities, dtype=float)
    k = pos.shape[0] if pos.ndim == 2 else -1
    if not (pos.shape == (k, 2) and vel.shape == (k, 2) and k >= 1
            and np.isfinite(pos).all() and np.isfinite(vel).all()):  # fmt: skip
        raise StateError(
            "prong_positions and prong_velocities must be finite (k >= 1, 2) arrays, got "
            f"{np.shape(positions)} and {np.shape(velocities)}"
        )
    if not (math.isfinite(radius) and radius >= 0.0):
        raise StateError(f"prong radius must be finite and >= 0 m, got {radius!r}")
    return pos, vel


def prescribed_state(
    edges: np.ndarray,
    pose: np.ndarray,
    velocity: np.ndarray,
    positions: np.ndarray,
    velocities: np.ndarray,
    radius: float,
    reach: float,
) -> tuple[tuple[int, ...], StepState]:
    """The prongs in contact and the step's state for prongs of ``radius`` [m] at
    ``positions`` (k, 2) [m] moving at ``velocities`` (k, 2) [m/s]: those whose centre is
    nearer than ``reach`` [m] to the footprint (edge records ``edges`` of the object at
    ``pose`` (3,), moving at ``velocity`` (3,)), their gaps less the radius."""
    geometry, _, mask = prong_geometry(edges, pose, positions, reach)
    prongs = mask_indices(mask)
    geometry[:, 0] -= radius
    v_prongs = np.ascontiguousarray(velocities[list(prongs)].reshape(-1))
    state = (geometry, np.zeros((len(prongs), 3, 0)), _NO_ARM_MATRIX, _NO_ARM_VECTOR,
             v_prongs, _NO_ARM_VECTOR, _NO_ARM_VECTOR, pose, velocity)  # fmt: skip
    return prongs, state


def push_substeps(
    solver: StepSolver,
    edges: np.ndarray,
    pose: np.ndarray,
    velocity: np.ndarray,
    prong_positions,
    prong_velocities,
    radius: float,
    config: WorldConfig,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, bool, int, np.ndarray]:
    """One world step of ``config.substeps`` solves of ``solver`` with prongs of ``radius``
    [m] at ``prong_positions`` (k, 2) [m] moving at ``prong_velocities`` (k, 2) [m/s] (see
    :func:`checked_prongs`); a prong takes part where its gap less its travel in the step
    is below ``contact_margin``. Returns the object's pose (3,) and velocity (3,) after the
    step, the prongs' mean forces (k, 2) [N], the worst solve's residual and whether it
    converged, the pivots, the gaps (k,) [m] at the step's end. A substep at rest with no
    prong in reach is not solved."""
    positions, velocities = checked_prongs(prong_positions, prong_velocities, radius)
    h = solver.model.h
    reach = config.contact_margin + radius + h * float(np.hypot(*velocities.T).max())
    forces = np.zeros((len(positions), 2))
    residual, converged, iterations = 0.0, True, 0
    for _ in range(config.substeps):
        prongs, state = prescribed_state(
            edges, pose, velocity, positions, velocities, radius, reach
        )
        if prongs or velocity.any():
            solved = solver.solve(state, prongs)
            for row, prong in enumerate(prongs):
                forces[prong] += solved.forces[row]
            velocity, pose = solved.v_obj, solved.pose
            iterations += solved.pivots
            if solved.residual > residual:
                residual, converged = solved.residual, solved.converged
        positions = positions + h * velocities
    gaps = prong_geometry(edges, pose, positions, 0.0)[1] - radius
    return pose, velocity, forces / config.substeps, residual, converged, iterations, gaps

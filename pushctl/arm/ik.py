"""Damped least-squares inverse kinematics of one frame, with a posture task in the null space.

Deterministic: the same model, target and seed give the same answer bit for bit. Joint limits
are respected by clamping every iterate into ``[lower + margin, upper − margin]``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin


@dataclass(frozen=True)
class IKResult:
    """Outcome of :func:`solve_frame_ik`.

    ``q`` (nq,) [rad] is the last iterate (the solution when ``converged``);
    ``position_error`` [m] and ``rotation_error`` [rad] are the norms of the translational and
    rotational parts of log6 of the frame's pose relative to the target.
    """

    q: np.ndarray
    converged: bool
    iterations: int
    position_error: float
    rotation_error: float


@dataclass(frozen=True)
class IKSettings:
    """Tuning of :func:`solve_frame_ik`.

    ``damping`` [-] is the Levenberg–Marquardt term added to J Jᵀ (mixed m/rad units);
    ``max_step`` [rad] caps the largest joint change per iteration; ``posture_gain`` [-] is
    the fraction of the posture error removed per iteration within the task's null space,
    and the solver stops once that null-space step is below ``posture_tolerance`` [rad] (or
    at ``max_iterations``); ``limit_margin`` [rad] keeps iterates strictly inside the limits.
    """

    max_iterations: int = 300
    position_tolerance: float = 1e-9
    rotation_tolerance: float = 1e-9
    damping: float = 1e-10
    max_step: float = 0.2
    posture_gain: float = 0.5
    posture_tolerance: float = 1e-7
    limit_margin: float = 1e-3


def frame_error(
    model: pin.Model, data: pin.Data, frame_id: int, q: np.ndarray, oMdes: pin.SE3
) -> tuple[np.ndarray, pin.SE3]:
    """log6 of the frame's pose in the target frame, (6,) [m, rad], and that relative pose."""
    pin.forwardKinematics(model, data, q)
    oMf = pin.updateFramePlacement(model, data, frame_id)
    dMf = oMdes.actInv(oMf)
    return pin.log6(dMf).vector, dMf


def _step(model, data, frame_id, q, err, dMf, q_posture, settings):
    """One damped Gauss–Newton step with the posture task in the task's null space.

    Returns ``(dq (nv,) [rad], null-space part of dq (nv,) [rad])``. The null-space
    projector is exact (SVD pseudo-inverse) so that the posture pull does not disturb the
    task to first order; the task step uses the damped inverse for robustness.
    """
    jac = pin.Jlog6(dMf) @ pin.computeFrameJacobian(model, data, q, frame_id, pin.LOCAL)
    gram = jac @ jac.T + settings.damping * np.eye(jac.shape[0])
    dq_task = -jac.T @ np.linalg.solve(gram, err)
    posture = settings.posture_gain * pin.difference(model, q, q_posture)
    dq_null = posture - np.linalg.pinv(jac, rcond=1e-9) @ (jac @ posture)
    dq = dq_task + dq_null
    largest = np.max(np.abs(dq))
    scale = 1.0 if largest <= settings.max_step else settings.max_step / largest
    return dq * scale, dq_null * scale


def solve_frame_ik(
    model: pin.Model,
    data: pin.Data,
    frame_id: int,
    oMdes: pin.SE3,
    q_seed: np.ndarray,
    q_posture: np.ndarray | None = None,
    settings: IKSettings | None = None,
) -> IKResult:
    """Find q (nq,) [rad] putting frame ``frame_id`` at world pose ``oMdes``.

    Starts at ``q_seed`` (nq,) and, for redundant arms, pulls the self-motion toward
    ``q_posture`` (default: the seed). ``data`` is used as scratch space.
    """
    settings = settings or IKSettings()
    lower = model.lowerPositionLimit + settings.limit_margin
    upper = model.upperPositionLimit - settings.limit_margin
    q = np.clip(np.array(q_seed, dtype=float), lower, upper)
    q_posture = q.copy() if q_posture is None else np.asarray(q_posture, dtype=float)
    null_step = np.inf
    for iteration in range(settings.max_iterations + 1):
        err, dMf = frame_error(model, data, frame_id, q, oMdes)
        pos_err, rot_err = float(np.linalg.norm(err[:3])), float(np.linalg.norm(err[3:]))
        on_target = pos_err < settings.position_tolerance and rot_err < settings.rotation_tolerance
        if on_target and null_step < settings.posture_tolerance:
            break
        if iteration == settings.max_iterations:
            break
        dq, dq_null = _step(model, data, frame_id, q, err, dMf, q_posture, settings)
        null_step = float(np.max(np.abs(dq_null)))
        q = np.clip(pin.integrate(model, q, dq), lower, upper)
    return IKResult(q, on_target, iteration, pos_err, rot_err)

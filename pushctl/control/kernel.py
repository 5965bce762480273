"""The PD baseline's per-step arithmetic as one compiled call (numba).

:func:`pd_torque` computes exactly what the plain-numpy reference of the tests
(``tests/control/pd_reference.py``) does; compiled, it is one call where numpy makes dozens
of small ones (docs/performance.md). It calls no kernel of another file.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def pd_torque(
    jacobian: np.ndarray,
    gravity: np.ndarray,
    q: np.ndarray,
    position: np.ndarray,
    rotation: np.ndarray,
    position_des: np.ndarray,
    yaw_des: float,
    twist_ff: np.ndarray,
    residual: np.ndarray,
    task_gain: np.ndarray,
    damping_sq: float,
    posture_gain: float,
    q_posture: np.ndarray,
    joint_gain: float,
    tau_limit: np.ndarray,
    v_limit: np.ndarray,
    tau: np.ndarray,
    q_dot_des: np.ndarray,
    twist: np.ndarray,
):
    """One PD step (see :mod:`pushctl.control.pd`). Shapes: ``jacobian`` (6, nv); ``gravity``,
    ``q``, ``q_posture``, ``tau_limit``, ``v_limit`` (nv,); ``position``, ``position_des``
    (3,); ``rotation`` (3, 3); ``twist_ff``, ``task_gain`` (6,); ``residual`` (3,) planar
    twist on rows (0, 1, 5). Writes ``tau`` (nv,), ``q_dot_des`` (nv,) and ``twist`` (6,),
    the caller's new arrays (numba's boxing of returned arrays costs more); returns whether
    a limit was hit."""
    nv = q.shape[0]
    c, s = math.cos(yaw_des), math.sin(yaw_des)
    # E = R_des Rᵀ with R_des = R_z(yaw_des); the error is the vee of its skew part.
    e = np.empty((3, 3))
    for i in range(3):
        r0, r1, r2 = rotation[i, 0], rotation[i, 1], rotation[i, 2]
        # row j of R_des times row i of R (Rᵀ's column i)
        e[0, i] = c * r0 - s * r1
        e[1, i] = s * r0 + c * r1
        e[2, i] = r2
    for i in range(3):
        twist[i] = twist_ff[i] + task_gain[i] * (position_des[i] - position[i])
    twist[3] = twist_ff[3] + task_gain[3] * 0.5 * (e[2, 1] - e[1, 2])
    twist[4] = twist_ff[4] + task_gain[4] * 0.5 * (e[0, 2] - e[2, 0])
    twist[5] = twist_ff[5] + task_gain[5] * 0.5 * (e[1, 0] - e[0, 1])
    twist[0] += residual[0]
    twist[1] += residual[1]
    twist[5] += residual[2]
    posture = posture_gain * (q_posture - q)
    gram = jacobian @ jacobian.T
    for i in range(6):
        gram[i, i] += damping_sq
    q_dot = posture + jacobian.T @ np.linalg.solve(gram, twist - jacobian @ posture)
    ratio = 0.0
    for j in range(nv):
        ratio = max(ratio, abs(q_dot[j]) / v_limit[j])
    saturated = ratio > 1.0
    if saturated:
        q_dot = q_dot / ratio
    q_dot_des[:] = q_dot
    tau[:] = joint_gain * q_dot + gravity
    for j in range(nv):
        if tau[j] > tau_limit[j]:
            tau[j] = tau_limit[j]
            saturated = True
        elif tau[j] < -tau_limit[j]:
            tau[j] = -tau_limit[j]
            saturated = True
    return saturated

"""The PD baseline's law in plain numpy: the reference the compiled
:func:`pushctl.control.kernel.pd_torque` (run by :meth:`PDController.command`) is tested
against. It reads the controller's own gains and limits."""

from __future__ import annotations

import numpy as np

from pushctl.arm import ArmTerms
from pushctl.checks import finite_vector
from pushctl.control.pd import (
    PLANAR_TWIST_ROWS,
    PDCommand,
    PDController,
    rotation_error,
    yaw_rotation,
)


def reference_command(
    controller: PDController,
    terms: ArmTerms,
    q: np.ndarray,
    position_des: np.ndarray,
    yaw_des: float,
    twist_ff: np.ndarray,
    residual: np.ndarray | None = None,
) -> PDCommand:
    """:meth:`PDController.command`, step by step in numpy."""
    error = np.empty(6)
    error[:3] = position_des - terms.pusher_position
    error[3:] = rotation_error(yaw_rotation(yaw_des), terms.pusher_rotation)
    twist = twist_ff + controller._task_gain * error
    if residual is not None:
        twist[list(PLANAR_TWIST_ROWS)] += finite_vector("residual", residual, 3)
    jacobian = terms.pusher_jacobian
    posture = controller.gains.posture_gain * (controller._q_posture - q)
    # J⁺ v + (I − J⁺J) z = z + Jᵀ (J Jᵀ + λ²I)⁻¹ (v − J z): one 6×6 solve for both.
    gram = jacobian @ jacobian.T + controller._damping
    q_dot = posture + jacobian.T @ np.linalg.solve(gram, twist - jacobian @ posture)
    ratio = float(np.max(np.abs(q_dot) / controller._v_limit))
    saturated = ratio > 1.0
    if saturated:
        q_dot = q_dot / ratio
    tau = controller._joint_gain * q_dot + terms.g
    if np.any(np.abs(tau) > controller._tau_limit):
        saturated = True
        tau = np.clip(tau, -controller._tau_limit, controller._tau_limit)
    return PDCommand(tau, controller.gains.kv, q_dot, twist, saturated)

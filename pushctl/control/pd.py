"""The PD baseline (the paper's π_H, docs/design.md §5): operational-space IK and a joint PD.

Per control step, from the pusher frame's desired pose and feed-forward twist:

1. ``v_e = v_ff + K_x (x_des − x)`` on all six task directions: position error in metres,
   orientation error as the rotation vector of ``R_des Rᵀ`` (world axes; the sin-scaled
   vee of its skew part, exact to first order, which is all a feedback term needs);
   a residual planar twist (vx, vy, ω_z), when given, is added here (Algorithm 1);
2. ``q̇_des = J⁺ v_e + (I − J⁺ J) k_post (q_ready − q)`` with the damped pseudo-inverse
   ``J⁺ = Jᵀ (J Jᵀ + λ² I)⁻¹`` (eq. 14), scaled down as a whole if a joint would exceed its
   velocity limit;
3. ``q_des = q + h q̇_des``; ``τ = K_p (q_des − q) + K_v (q̇_des − q̇) + g(q)`` (eq. 15 with
   gravity compensation). The ``−K_v q̇`` part is handed to the world as ``implicit_kv``
   (applied to the new joint velocity: a stiff PD at h = 0.01 s is then unconditionally
   stable); the rest, clipped to the joint torque limits, is returned as the torque.

Note that with ``q_des = q + h q̇_des`` (docs/design.md §5's form of eq. 15) the stiffness term is
``K_p h q̇_des``: the joint loop is a velocity loop of gain ``K_p h + K_v``, and position is
held by the operational-space feedback ``K_x``.

:meth:`PDController.command` runs the compiled :func:`pushctl.control.kernel.pd_torque`; the
same law in plain numpy, its reference, lives with the tests (``tests/control/pd_reference.py``).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from pushctl.arm import ArmModel, ArmTerms
from pushctl.checks import finite_vector
from pushctl.control.gains import PDGains
from pushctl.control.kernel import pd_torque

PLANAR_TWIST_ROWS = (0, 1, 5)
"""Rows of the 6-D twist [vx, vy, vz, ωx, ωy, ωz] that a planar residual (vx, vy, ω_z) acts on."""


class PDCommand(NamedTuple):
    """One control step's output: ``tau`` (nv,) [N·m] the explicit torque (gravity and
    stiffness terms, clipped to the limits), ``implicit_kv`` [N·m·s/rad] the damping gain the
    world applies to the new joint velocity, ``q_dot_des`` (nv,) [rad/s], ``twist`` (6,) the
    commanded pusher twist [m/s, rad/s], ``saturated`` whether a torque or velocity limit
    was hit."""

    tau: np.ndarray
    implicit_kv: float
    q_dot_des: np.ndarray
    twist: np.ndarray
    saturated: bool


def rotation_error(rotation_des: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """(3,) world-axes rotation error taking ``rotation`` (3, 3) to ``rotation_des`` (3, 3):
    sin(angle)·axis of ``R_des Rᵀ`` [rad] (equal to the rotation vector to first order)."""
    error = rotation_des @ rotation.T
    return 0.5 * np.array(
        [error[2, 1] - error[1, 2], error[0, 2] - error[2, 0], error[1, 0] - error[0, 1]]
    )


def yaw_rotation(yaw: float) -> np.ndarray:
    """R_z(yaw) (3, 3): the level pusher frame's orientation."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


class PDController:
    """Joint PD with gravity compensation behind damped pseudo-inverse IK, for one arm.

    ``dt`` [s] is the control step h. Stateless between steps: :meth:`command` is a pure
    function of the arm state and the reference, so one controller serves any number of
    episodes.
    """

    def __init__(self, arm: ArmModel, gains: PDGains, dt: float) -> None:
        self.arm, self.gains, self.dt = arm, gains, float(dt)
        self._task_gain = np.array([gains.kx_linear] * 3 + [gains.kx_angular] * 3)
        self._damping = gains.ik_damping**2 * np.eye(6)
        self._joint_gain = gains.kp * self.dt + gains.kv  # τ = (K_p h + K_v) q̇_des − K_v q̇ + g
        self._q_posture = arm.q_ready.copy()
        self._no_residual = np.zeros(3)
        self._tau_limit = arm.torque_limit.copy()
        self._v_limit = arm.velocity_limit.copy()

    def command(
        self,
        terms: ArmTerms,
        q: np.ndarray,
        position_des: np.ndarray,
        yaw_des: float,
        twist_ff: np.ndarray,
        residual: np.ndarray | None = None,
    ) -> PDCommand:
        """The torque for one step. ``terms``: the arm at ``q`` (nq,) [rad] (the world's
        :attr:`~pushctl.contact.world.World.arm_terms`); ``position_des`` (3,) [m] and
        ``yaw_des`` [rad] the desired pusher pose; ``twist_ff`` (6,) its feed-forward twist;
        ``residual`` (3,) an extra planar twist (vx [m/s], vy [m/s], ω_z [rad/s])."""
        gains, nv = self.gains, self._v_limit.size
        tau, q_dot, twist = np.empty(nv), np.empty(nv), np.empty(6)  # the kernel's outputs
        saturated = pd_torque(
            terms.pusher_jacobian,
            terms.g,
            q,
            terms.pusher_position,
            terms.pusher_rotation,
            position_des,
            float(yaw_des),
            twist_ff,
            self._no_residual if residual is None else finite_vector("residual", residual, 3),
            self._task_gain,
            gains.ik_damping**2,
            gains.posture_gain,
            self._q_posture,
            self._joint_gain,
            self._tau_limit,
            self._v_limit,
            tau,
            q_dot,
            twist,
        )
        return PDCommand(tau, gains.kv, q_dot, twist, bool(saturated))

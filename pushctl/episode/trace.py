"""What one push leaves behind: the per-step trace of docs/design.md §8, in memory and as CSV.

Rows are the samples t = 0, h, …, T of the push (N + 1 rows for N steps). Row 0 is the
state the approach left (its forces are those of the approach's last step); row n ≥ 1 holds
the state at t_n and the forces the world applied over the step (t_{n−1}, t_n]. Metrics
(:mod:`pushctl.episode.metrics`) average rows 1 … N, the N steps of the push.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd


@dataclass(frozen=True)
class Trace:
    """A push, N + 1 samples. Object frame quantities as in docs/design.md §2.

    ``t`` (N+1,) [s]; ``object_pose``, ``desired_pose`` (N+1, 3) (x [m], y [m], θ [rad]);
    ``contact_forces``, ``desired_forces`` (N+1, k, 2) (normal, tangential) [N] per prong;
    ``contact_torque``, ``desired_torque`` (N+1,) Σ τ_z,i about the centre of mass [N·m];
    ``prong_gaps`` (N+1, k) [m] (negative: penetration); ``arm_q`` (N+1, nq) [rad];
    ``arm_v`` (N+1, nv) [rad/s]; ``arm_tau`` (N+1, nv) [N·m] the joint torque applied over
    the step ending at the row (the controller's torque minus its implicit K_v q̇);
    ``pusher_position`` (N+1, 3) [m] and ``pusher_position_des`` (N+1, 3) [m] the pusher
    frame, actual and planned; ``mu_contact`` the plant's prong friction (for slip);
    ``arc_length`` [m] and ``delta_theta`` [rad] of the planned path (the metrics' scales);
    ``measured_pose`` (N+1, 3) or None: the object pose as the reality proxy's camera reports
    it (:func:`~pushctl.episode.proxy.camera_poses`), which the pose metrics use when given.
    ``desired_forces`` are what the plant needed to follow the plan (its true parameters and
    plant unknowns); ``plan_forces`` (N+1, k, 2) [N] or None are the nominal plan's own (the
    paper's "desired values computed from our dynamic optimization").
    ``arm_tau`` is the actuators' torque: on the proxy the delayed command, friction excluded.
    """

    t: np.ndarray
    object_pose: np.ndarray
    desired_pose: np.ndarray
    contact_forces: np.ndarray
    desired_forces: np.ndarray
    contact_torque: np.ndarray
    desired_torque: np.ndarray
    prong_gaps: np.ndarray
    arm_q: np.ndarray
    arm_v: np.ndarray
    arm_tau: np.ndarray
    pusher_position: np.ndarray
    pusher_position_des: np.ndarray
    mu_contact: float
    arc_length: float
    delta_theta: float
    measured_pose: np.ndarray | None = None
    plan_forces: np.ndarray | None = None

    @property
    def n_steps(self) -> int:
        return len(self.t) - 1

    @property
    def n_prongs(self) -> int:
        return self.contact_forces.shape[1]

    def to_frame(self) -> pd.DataFrame:
        """The trace CSV's columns (docs/design.md §8), SI units and radians: ``t, obj_x, obj_y,
        obj_theta, des_x, des_y, des_theta, lambda_n_i, lambda_t_i …, force_n_des_i,
        force_t_des_i …, tau_z, tau_z_des``, then the arm joints ``q_j, dq_j, tau_j``, then
        the prong gaps ``gap_i`` and the pusher frame ``pusher_x, pusher_y, pusher_z``, with
        a camera its poses ``cam_x, cam_y, cam_theta``, and with the nominal plan's forces
        ``force_n_plan_i, force_t_plan_i``."""
        columns: dict[str, np.ndarray] = {"t": self.t}
        for prefix, pose in (("obj", self.object_pose), ("des", self.desired_pose)):
            for i, name in enumerate(("x", "y", "theta")):
                columns[f"{prefix}_{name}"] = pose[:, i]
        for i in range(self.n_prongs):
            columns[f"lambda_n_{i + 1}"] = self.contact_forces[:, i, 0]
            columns[f"lambda_t_{i + 1}"] = self.contact_forces[:, i, 1]
        for i in range(self.n_prongs):
            columns[f"force_n_des_{i + 1}"] = self.desired_forces[:, i, 0]
            columns[f"force_t_des_{i + 1}"] = self.desired_forces[:, i, 1]
        columns["tau_z"] = self.contact_torque
        columns["tau_z_des"] = self.desired_torque
        for prefix, values in (("q", self.arm_q), ("dq", self.arm_v), ("tau", self.arm_tau)):
            for j in range(values.shape[1]):
                columns[f"{prefix}_{j + 1}"] = values[:, j]
        for i in range(self.n_prongs):
            columns[f"gap_{i + 1}"] = self.prong_gaps[:, i]
        for i, name in enumerate(("x", "y", "z")):
            columns[f"pusher_{name}"] = self.pusher_position[:, i]
        if self.measured_pose is not None:
            for i, name in enumerate(("x", "y", "theta")):
                columns[f"cam_{name}"] = self.measured_pose[:, i]
        if self.plan_forces is not None:
            for i in range(self.n_prongs):
                columns[f"force_n_plan_{i + 1}"] = self.plan_forces[:, i, 0]
                columns[f"force_t_plan_{i + 1}"] = self.plan_forces[:, i, 1]
        return pd.DataFrame(columns)


def contact_torques(
    object_pose: np.ndarray, prong_positions: np.ndarray, forces: np.ndarray
) -> np.ndarray:
    """Σ_i τ_z,i [N·m], (B,): :func:`prong_torques` summed over the prongs."""
    return prong_torques(object_pose, prong_positions, forces).sum(axis=1)


def prong_torques(
    object_pose: np.ndarray, prong_positions: np.ndarray, forces: np.ndarray
) -> np.ndarray:
    """τ_z,i [N·m], (B, k), of prong forces ``forces`` (B, k, 2) (normal along the object's
    e_n, tangential along e_t) applied at ``prong_positions`` (B, k, ≥2) [m] world, about the
    centre of mass of the object at ``object_pose`` (B, 3). The lever is the prong's position
    in the object frame: on the pushed face that is (−face offset, t_i), as in the plan."""
    c = np.cos(object_pose[:, 2])[:, None]
    s = np.sin(object_pose[:, 2])[:, None]
    dx = prong_positions[:, :, 0] - object_pose[:, 0:1]
    dy = prong_positions[:, :, 1] - object_pose[:, 1:2]
    local_n = c * dx + s * dy
    local_t = -s * dx + c * dy
    return local_n * forces[:, :, 1] - local_t * forces[:, :, 0]

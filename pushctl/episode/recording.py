"""The rows an :class:`~pushctl.episode.runner.Episode` records at every push step, and the
:class:`~pushctl.episode.trace.Trace` made of them."""

from __future__ import annotations

import numpy as np

from pushctl.arm import ArmTerms
from pushctl.episode.trace import Trace, contact_torques
from pushctl.planning import ForcePlan, Plan
from pushctl.types import StepResult


class Recording:
    """``rows`` rows (t = 0 … t_N) of the object pose (3,) [m, m, rad], the prongs' contact
    forces (k, 2) [N], gaps (k,) [m] and positions (k, 3) [m], the pusher origin (3,) [m],
    the arm's q (nq,) and v (nv,), and the command's τ (nv,) [N·m] and implicit K_v
    [N·m·s/rad] (:meth:`applied_torques`)."""

    def __init__(self, rows: int, n_prongs: int, nq: int, nv: int) -> None:
        self.pose = np.zeros((rows, 3))
        self.forces = np.zeros((rows, n_prongs, 2))
        self.gaps = np.zeros((rows, n_prongs))
        self.prongs = np.zeros((rows, n_prongs, 3))
        self.pusher = np.zeros((rows, 3))
        self.q = np.zeros((rows, nq))
        self.v = np.zeros((rows, nv))
        self.tau = np.zeros((rows, nv))
        self.kv = np.zeros(rows)  # the implicit K_v of each step's command

    def record(
        self, row: int, result: StepResult, terms: ArmTerms, tau: np.ndarray, kv: float = 0.0
    ) -> None:
        """Row ``row``: the step's ``result``, the arm's ``terms`` after it, its τ and K_v."""
        self.pose[row] = result.object_pose
        self.forces[row] = result.contact_forces
        self.gaps[row] = result.prong_gaps
        self.prongs[row] = terms.prong_positions
        self.pusher[row] = terms.pusher_position
        self.q[row] = result.arm_q
        self.v[row] = result.arm_v
        self.tau[row] = tau
        self.kv[row] = kv

    def applied_torques(self, rows: slice) -> np.ndarray:
        """The joint torques applied over the recorded steps ``rows`` (rows, nv) [N·m]:
        τ − K_v q̇ of each step's new velocity, with the same products and differences as a
        step made them. Rows with K_v = 0 are τ itself, untouched (τ − 0·q̇ could turn a
        −0.0 into 0.0)."""
        torques = self.tau[rows].copy()
        kv = self.kv[rows]
        damped = kv != 0.0
        torques[damped] -= kv[damped, None] * self.v[rows][damped]
        return torques

    def trace(
        self,
        rows: slice,
        plan: Plan,
        plant_forces: ForcePlan,
        mu_contact: float,
        measured: np.ndarray | None,
    ) -> Trace:
        """The trace of ``rows`` beside the ``plan`` and the ``plant_forces`` it needed;
        ``measured``: the camera's poses of those rows (None: none)."""
        forces = self.forces[rows]
        return Trace(
            t=plan.trajectory.t[rows].copy(),
            object_pose=self.pose[rows].copy(),
            desired_pose=plan.trajectory.pose[rows].copy(),
            contact_forces=forces.copy(),
            desired_forces=plant_forces.forces[rows].copy(),
            contact_torque=contact_torques(self.pose[rows], self.prongs[rows], forces),
            desired_torque=plant_forces.total_torque[rows].copy(),
            prong_gaps=self.gaps[rows].copy(),
            arm_q=self.q[rows].copy(),
            arm_v=self.v[rows].copy(),
            arm_tau=self.applied_torques(rows),
            pusher_position=self.pusher[rows].copy(),
            pusher_position_des=plan.pusher_positions[rows].copy(),
            mu_contact=mu_contact,
            arc_length=plan.trajectory.arc_length,
            delta_theta=plan.trajectory.delta_theta,
            measured_pose=measured,
            plan_forces=plan.forces.forces[rows].copy(),
        )

"""Can the arm hold the pusher along a path? Inverse kinematics pose after pose.

Used by the planner to check a plan's pusher poses against the arm's reach and joint limits
before anything runs. Each pose is solved from the previous solution (a continuous path,
so the arm does not jump between IK branches), with the ready configuration as the
posture the redundancy is pulled towards.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pushctl.arm.ik import IKSettings
from pushctl.arm.model import ArmModel

PATH_IK = IKSettings(
    max_iterations=100, position_tolerance=1e-6, rotation_tolerance=1e-5, posture_tolerance=1e-3
)
"""IK settings for path checks: 1 µm / 10 µrad, a loose posture task (speed over polish)."""

# A joint closer than this to a limit [rad] (beyond IK's own margin) is reported at it.
_AT_LIMIT = 2e-3


@dataclass(frozen=True)
class ReachReport:
    """IK along M pusher poses.

    ``q`` (M, nq) [rad]; ``position_error`` (M,) [m]; ``rotation_error`` (M,) [rad];
    ``condition`` (M,) cond of the pusher Jacobian [-]; ``reached`` (M,) bool;
    ``joints_at_limit``: for the first unreached pose, the 1-based joints at a limit.
    """

    q: np.ndarray
    position_error: np.ndarray
    rotation_error: np.ndarray
    condition: np.ndarray
    reached: np.ndarray
    joints_at_limit: tuple[int, ...]

    @property
    def first_unreached(self) -> int | None:
        """Index of the first pose the arm cannot reach, or None."""
        bad = np.flatnonzero(~self.reached)
        return int(bad[0]) if bad.size else None


def pusher_target(position: np.ndarray, yaw: float) -> pin.SE3:
    """Pusher frame placement: origin at ``position`` (3,) [m], x along the push direction
    at ``yaw`` [rad] about +z, z up."""
    return pin.SE3(pin.utils.rotate("z", float(yaw)), np.asarray(position, dtype=float))


def check_pusher_path(
    arm: ArmModel, positions: np.ndarray, yaws: np.ndarray, q_seed: np.ndarray | None = None
) -> ReachReport:
    """Solve IK for the pusher at ``positions`` (M, 3) [m] with ``yaws`` (M,) [rad] in
    order, each from the previous solution (the first from ``q_seed``, default the ready
    configuration). Stops at the first pose out of reach (later rows stay unreached)."""
    count = len(positions)
    q = np.array(arm.q_ready if q_seed is None else q_seed, dtype=float)
    qs = np.tile(q, (count, 1))
    position_error = np.full(count, np.inf)
    rotation_error = np.full(count, np.inf)
    condition = np.full(count, np.inf)
    reached = np.zeros(count, dtype=bool)
    at_limit: tuple[int, ...] = ()
    for i in range(count):
        result = arm.inverse_kinematics(
            pusher_target(positions[i], yaws[i]), q, q_posture=arm.q_ready, settings=PATH_IK
        )
        qs[i], position_error[i], rotation_error[i] = (
            result.q,
            result.position_error,
            result.rotation_error,
        )
        if not result.converged:
            near = (result.q - arm.q_lower < _AT_LIMIT + PATH_IK.limit_margin) | (
                arm.q_upper - result.q < _AT_LIMIT + PATH_IK.limit_margin
            )
            at_limit = tuple(int(j) + 1 for j in np.flatnonzero(near))
            break
        reached[i] = True
        condition[i] = arm.pusher_condition_number(result.q)
        q = result.q
    return ReachReport(qs, position_error, rotation_error, condition, reached, at_limit)

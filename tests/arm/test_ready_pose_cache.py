"""The ready pose's IK is kept by kinematics (ArmModel._solve_ready): an arm whose joints,
limits and pusher frame are another's gets that arm's answer, bit for bit what its own IK
finds; another mounting gets its own; the copies are independent."""

from __future__ import annotations

from dataclasses import replace
from math import radians

import numpy as np

import pushctl.arm.model as arm_model
from pushctl.arm import ArmConfig, load_arm
from pushctl.config import PusherConfig


def test_a_kept_ready_pose_is_the_one_the_ik_finds_and_a_mounting_gets_its_own() -> None:
    heavier = ArmConfig(pusher=replace(PusherConfig(), mass=0.35))  # kinematics unchanged
    arm_model._READY_POSES.clear()
    fresh = load_arm(heavier)  # solves and keeps
    again = load_arm(ArmConfig(pusher=replace(PusherConfig(), mass=0.2)))  # same kinematics
    assert len(arm_model._READY_POSES) == 1
    assert again.q_ready.tobytes() == fresh.q_ready.tobytes()
    arm_model._READY_POSES.clear()
    solved = load_arm(ArmConfig(pusher=replace(PusherConfig(), mass=0.2)))  # its own IK
    assert solved.q_ready.tobytes() == again.q_ready.tobytes()
    assert solved.ready_ik.iterations == again.ready_ik.iterations
    mounted = load_arm(ArmConfig(pusher=replace(PusherConfig(), mount_yaw=radians(1.0))))
    assert len(arm_model._READY_POSES) == 2
    assert not np.array_equal(mounted.q_ready, solved.q_ready)
    again.ready_ik.q[:] = 0.0  # a copy: the kept answer and the other arms keep theirs
    assert load_arm(heavier).q_ready.tobytes() == solved.q_ready.tobytes()


def test_the_kept_answers_are_bounded() -> None:
    arm_model._READY_POSES.clear()
    for k in range(arm_model._READY_POSES_KEPT + 3):
        yaw = radians(0.01 * (k + 1))
        load_arm(ArmConfig(pusher=replace(PusherConfig(), mount_yaw=yaw)))
    assert len(arm_model._READY_POSES) == arm_model._READY_POSES_KEPT

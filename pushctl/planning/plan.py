"""A complete push plan: the ICR arc, its force distribution and the arm's reach along it.

``make_plan`` never raises for a plan that merely cannot be executed: it returns a
:class:`Plan` whose ``problems`` say why (the CLI turns them into an error). It raises
ConfigError only for requests that are malformed (times, |Δθ| > 180°, a goal behind the
pushed face, friction out of range).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from pushctl.arm.model import ArmModel
from pushctl.arm.reach import ReachReport, check_pusher_path
from pushctl.config import GRAVITY, PusherConfig
from pushctl.errors import ConfigError, PlanError
from pushctl.objects import ObjectSpec
from pushctl.planning.forces import ForcePlan, ForceSettings, distribute_forces
from pushctl.planning.profiles import AngularProfile
from pushctl.planning.trajectory import Trajectory, check_rotation, plan_icr
from pushctl.planning.workspace import default_start, pusher_path
from pushctl.types import PlanarPose

REACH_SAMPLES = 50
"""Intervals along the plan at which the arm's reach is checked by IK (plus both ends)."""


@dataclass(frozen=True)
class Plan:
    """A planned push of ``obj`` with ``pusher`` under ``settings`` (friction, margins):
    ``trajectory``, ``forces`` and, when an arm was given, ``reach`` at the samples
    ``reach_steps`` (M,) of the trajectory.
    ``pusher_positions`` (N, 3) [m] and ``pusher_yaws`` (N,) [rad]: the pusher frame along
    the plan. ``problems``: why the plan cannot be executed (empty when it can)."""

    obj: ObjectSpec
    pusher: PusherConfig
    settings: ForceSettings
    trajectory: Trajectory
    forces: ForcePlan
    pusher_positions: np.ndarray
    pusher_yaws: np.ndarray
    arm_name: str | None
    reach: ReachReport | None
    reach_steps: np.ndarray
    problems: tuple[str, ...] = field(default=())

    @property
    def feasible(self) -> bool:
        return not self.problems

    def raise_if_infeasible(self) -> None:
        """PlanError with the first problem, if there is one."""
        if self.problems:
            raise PlanError(self.problems[0])

    def to_frame(self) -> pd.DataFrame:
        """One row per sample: the columns of ``pushctl plan --out`` (SI units, radians)."""
        tr, fp = self.trajectory, self.forces
        icr = tr.icr if tr.icr is not None else np.array([math.nan, math.nan])
        columns: dict[str, np.ndarray] = {"t": tr.t}
        for i, name in enumerate(("x", "y", "theta")):
            columns[name] = tr.pose[:, i]
        for i, name in enumerate(("vx", "vy", "omega")):
            columns[name] = tr.velocity[:, i]
        for i, name in enumerate(("ax", "ay", "alpha")):
            columns[name] = tr.acceleration[:, i]
        columns["icr_x"] = np.full(len(tr.t), icr[0])
        columns["icr_y"] = np.full(len(tr.t), icr[1])
        for i in range(fp.forces.shape[1]):
            columns[f"force_n_des_{i + 1}"] = fp.forces[:, i, 0]
            columns[f"force_t_des_{i + 1}"] = fp.forces[:, i, 1]
        for i in range(fp.forces.shape[1]):
            columns[f"tau_z_des_{i + 1}"] = fp.torques[:, i]
        columns["tau_z_des"] = fp.total_torque
        columns["ne_residual"] = fp.residual
        return pd.DataFrame(columns)


def check_push_direction(trajectory: Trajectory) -> None:
    """ConfigError if the goal lies behind the pushed face (the object would be pulled)."""
    angle = trajectory.push_angle
    if math.isfinite(angle) and abs(angle) >= 0.5 * math.pi:
        raise ConfigError(
            f"the goal is behind the pushed face: the object would move "
            f"{math.degrees(angle):+.1f} deg off the face's inward normal and have to be "
            "pulled; accepted: goals ahead of the face (within ±90 deg of its normal, and "
            "within ±atan(μ_c) of it to be feasible)"
        )


def _reach_problem(
    plan_steps: np.ndarray,
    reach: ReachReport,
    trajectory: Trajectory,
    positions: np.ndarray,
    yaws: np.ndarray,
    arm_name: str,
) -> str | None:
    bad = reach.first_unreached
    if bad is None:
        return None
    step = int(plan_steps[bad])
    x, y, z = positions[step]
    limits = (
        f", joint {', '.join(map(str, reach.joints_at_limit))} at its limit"
        if reach.joints_at_limit
        else ""
    )
    return (
        f"goal out of reach: at step {step} (t = {trajectory.t[step]:.2f} s) the pusher at "
        f"({x:.3f}, {y:.3f}, {z:.3f}) m, yaw {math.degrees(yaws[step]):.1f} deg is out of "
        f"{arm_name}'s reach (IK stops {1e3 * reach.position_error[bad]:.1f} mm and "
        f"{math.degrees(reach.rotation_error[bad]):.2f} deg short{limits}); bring the goal "
        "closer to the arm"
    )


def make_plan(
    obj: ObjectSpec,
    goal: tuple[float, float, float] | np.ndarray | None = None,
    *,
    start: tuple[float, float, float] | np.ndarray | None = None,
    profile: str | AngularProfile = "constant",
    duration: float = 20.0,
    dt: float = 0.01,
    forces: ForceSettings | None = None,
    arm: ArmModel | None = None,
    gravity: float = GRAVITY,
) -> Plan:
    """Plan pushing ``obj`` from ``start`` to ``goal`` (x [m], y [m], θ [rad]) with the
    pusher of ``arm`` (its prong layout, ready pose for the default start, and IK reach).

    Without an arm, the default pusher layout is used, the default start assumes the
    Kinova Gen2 7-DOF's ready pose and reach is not checked.
    """
    if goal is None:
        raise ConfigError("a goal pose (x, y, theta) is required")
    if not (math.isfinite(gravity) and gravity >= 0.0):
        raise ConfigError(f"gravity must be a finite magnitude >= 0 m/s², got {gravity!r}")
    settings = forces or ForceSettings()
    pusher = arm.pusher if arm is not None else PusherConfig()
    ready = arm.ready_pusher_position if arm is not None else np.array([0.30, 0.0, 0.06])
    start_pose = default_start(obj, ready) if start is None else PlanarPose.from_array(start)
    goal_pose = PlanarPose.from_array(goal)
    check_rotation(start_pose, goal_pose)
    if np.allclose(start_pose.as_array(), goal_pose.as_array(), rtol=0.0, atol=1e-12):
        raise ConfigError("the goal equals the start: there is nothing to push")
    trajectory = plan_icr(start_pose, goal_pose, duration, dt, profile)
    check_push_direction(trajectory)
    force_plan = distribute_forces(trajectory, obj, pusher.prong_offsets(), settings, gravity)
    positions, yaws = pusher_path(obj, trajectory.pose, force_plan.offset)
    problems = [force_plan.reason] if force_plan.reason else []
    steps = np.unique(np.linspace(0, trajectory.n_steps, REACH_SAMPLES + 1).round().astype(int))
    reach = None
    if arm is not None:
        reach = check_pusher_path(arm, positions[steps], yaws[steps])
        problem = _reach_problem(steps, reach, trajectory, positions, yaws, arm.name)
        if problem:
            problems.append(problem)
    return Plan(
        obj=obj,
        pusher=pusher,
        settings=settings,
        trajectory=trajectory,
        forces=force_plan,
        pusher_positions=positions,
        pusher_yaws=yaws,
        arm_name=arm.name if arm is not None else None,
        reach=reach,
        reach_steps=steps,
        problems=tuple(problems),
    )

"""Why a force distribution fails: one sentence with numbers, for the first bad step.

With every prong on one face (r_i = (−d, t_i)), the prongs can produce the wrench
(w_n, w_t, w_τ) exactly when (i) w_n > 0 (a pusher only pushes), (ii) |w_t| ≤ μ_c w_n (the
summed friction cones; tangential forces can be split in proportion to the normal ones),
and (iii) the centre of pressure the torque needs, c = −(w_τ + d w_t)/w_n, lies between the
outermost prongs. The checks run in that order and the first that fails is reported.
"""

from __future__ import annotations

import math

import numpy as np

from pushctl.planning.trajectory import Trajectory

# Forces [N] below this count as zero in the explanation.
_TINY_FORCE = 1e-9


def _where(trajectory: Trajectory, step: int, count: int) -> str:
    others = f" and {count - 1} later steps" if count > 1 else ""
    return f"step {step} (t = {trajectory.t[step]:.2f} s){others}"


def _lateral_hint(trajectory: Trajectory) -> str:
    if trajectory.delta_theta == 0.0:
        return "reduce the goal's lateral offset, or raise μ_c"
    return "move the goal's lateral offset towards the direction of rotation"


def explain(
    trajectory: Trajectory,
    wrench: np.ndarray,
    points: np.ndarray,
    mu_contact: float,
    step: int,
    count: int,
) -> str:
    """The reason the wrench at ``step`` cannot be produced; ``count`` bad steps in all."""
    w_n, w_t, w_tau = (float(v) for v in wrench[step])
    where = _where(trajectory, step, count)
    depth = -float(points[0, 0])
    t_lo, t_hi = float(points[:, 1].min()), float(points[:, 1].max())
    if w_n <= _TINY_FORCE:
        if w_n < -_TINY_FORCE:
            return (
                f"infeasible at {where}: the plan needs a pull of {-w_n:.3f} N along the face "
                "normal (it brakes harder than ground friction does); a pusher can only push"
            )
        return (
            f"infeasible at {where}: the plan needs {w_tau:.4f} N·m about the centre of mass "
            "with no net push (a pure rotation); prongs on one face cannot turn the object "
            "in place"
        )
    if abs(w_t) > mu_contact * w_n:
        angle = math.degrees(math.atan2(w_t, w_n))
        cone = math.degrees(math.atan(mu_contact))
        return (
            f"infeasible at {where}: the plan needs a side force of {abs(w_t):.3f} N with a "
            f"push of {w_n:.3f} N, {abs(angle):.1f} deg off the face normal; μ_c = "
            f"{mu_contact:g} allows at most {cone:.1f} deg ({_lateral_hint(trajectory)})"
        )
    # achievable torque: −d w_t − Σ t_i F_n,i with Σ F_n,i = w_n, t_i in [t_lo, t_hi]
    tau_a, tau_b = -depth * w_t - t_hi * w_n, -depth * w_t - t_lo * w_n
    if min(tau_a, tau_b) <= w_tau <= max(tau_a, tau_b):
        return (
            f"the force QP failed at {where} although the wrench ({w_n:.4f} N, {w_t:.4f} N, "
            f"{w_tau:.5f} N·m) is within the prongs' reach: a solver fault, please report it"
        )
    count_word = {1: "one prong", 2: "two prongs"}.get(len(points), f"{len(points)} prongs")
    spots = " and ".join(f"{1e3 * t:+.1f}" for t in points[:, 1])
    return (
        f"infeasible at {where}: the plan needs {w_tau:.4f} N·m about the centre of mass; "
        f"{count_word} at {spots} mm along the face pushing {w_n:.3f} N with μ_c = "
        f"{mu_contact:g} give {min(tau_a, tau_b):.4f} to {max(tau_a, tau_b):.4f} N·m"
    )

"""The metrics of one push (docs/design.md §7), computed from its
:class:`~pushctl.episode.trace.Trace`.

Every mean is over the N push steps, rows 1 … N of the trace; row 0 (the state the approach
left) never counts. With p = object (x, y), p_des = desired (x, y), θ and θ_des the object's
and the plan's heading (continuous, not wrapped: the world does not wrap θ), λ_i = (λ_n, λ_t)
the contact force of prong i and F_des,i the plan's force for it:

- ``translation_error_pct`` [%] = mean ‖p − p_des‖ / arc_length × 100;
- ``angle_error_pct`` [%] = mean |θ − θ_des| / |Δθ| × 100, NaN when Δθ = 0 (a straight push
  has no angle scale; ``angle_error_deg`` covers it);
- ``force_error`` [N] = mean over steps and prongs of ‖F_des,i − λ_i‖₂, F_des what the
  plant needed to follow the plan (its true parameters, support loads and friction field);
- ``force_error_plan`` [N] = the same against the nominal plan's forces (the trace's
  ``plan_forces``; NaN without them): the paper's definition, which also counts the part of
  the plan's error that no controller following the plan can remove;
- ``torque_error`` [N·m] = mean |τ_des − τ|, both already Σ over the prongs;
- ``contact_loss_fraction`` [1] = fraction of steps where some prong has λ_n < threshold;
- ``slip_fraction`` [1] = fraction of steps where some prong in contact (λ_n > threshold)
  has |λ_t| ≥ (1 − 10⁻³) μ_c λ_n: its force is on the friction cone's boundary, it slides;
- ``max_penetration`` [m] = max(0, −min gap) over the steps (gaps are signed, < 0 penetrates);
- ``final_position_error`` [m] = ‖p − p_des‖ and ``final_angle_error`` [rad] = |θ − θ_des|
  at the last row;
- ``angle_error_deg`` [deg] = mean |θ − θ_des| in degrees (defined for straight pushes too).

The pose (p, θ) is the trace's ``measured_pose`` when it has one (the reality proxy's camera,
docs/design.md §7: on the proxy, as on the paper's robot, poses are measured, not known), else its
true ``object_pose``. Forces are always the true contact forces.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np

from pushctl.episode.trace import Trace
from pushctl.errors import ConfigError, StateError

SLIP_TOLERANCE = 1e-3
"""Relative slack on the friction cone: |λ_t| ≥ (1 − SLIP_TOLERANCE) μ_c λ_n counts as slip."""

FAILED_ANGLE_PCT = 20.0
"""A push fails when its angle error exceeds this [%] ..."""
FAILED_TRANSLATION_PCT = 3.0
"""... or its translation error this [%]: both several times PD-only's typical push."""


def push_failed(translation_pct, angle_pct):
    """Whether a push with these errors [%] failed (:data:`FAILED_ANGLE_PCT`,
    :data:`FAILED_TRANSLATION_PCT`): a bool for numbers, elementwise for arrays or Series."""
    return (angle_pct > FAILED_ANGLE_PCT) | (translation_pct > FAILED_TRANSLATION_PCT)


METRIC_UNITS: dict[str, str] = {
    "translation_error_pct": "%",
    "angle_error_pct": "%",
    "force_error": "N",
    "force_error_plan": "N",
    "torque_error": "N·m",
    "contact_loss_fraction": "1",
    "slip_fraction": "1",
    "max_penetration": "m",
    "final_position_error": "m",
    "final_angle_error": "rad",
    "angle_error_deg": "deg",
}
"""The unit of each :class:`EpisodeMetrics` field, for tables."""


@dataclass(frozen=True)
class EpisodeMetrics:
    """The metrics of one push, SI units (see the module docstring for the definitions).

    ``translation_error_pct`` [%] of the arc length; ``angle_error_pct`` [%] of |Δθ| (NaN for
    a straight push); ``force_error`` and ``force_error_plan`` [N]; ``torque_error`` [N·m];
    ``contact_loss_fraction`` and ``slip_fraction`` [1] of the steps; ``max_penetration`` [m] (≥ 0);
    ``final_position_error`` [m]; ``final_angle_error`` [rad]; ``angle_error_deg`` [deg].
    """

    translation_error_pct: float
    angle_error_pct: float
    force_error: float
    force_error_plan: float
    torque_error: float
    contact_loss_fraction: float
    slip_fraction: float
    max_penetration: float
    final_position_error: float
    final_angle_error: float
    angle_error_deg: float

    def as_dict(self) -> dict[str, float]:
        """The fields by name, in declaration order (the order of :data:`METRIC_UNITS`)."""
        return {f.name: float(getattr(self, f.name)) for f in fields(self)}


def _ratio_pct(mean_error: float, scale: float) -> float:
    """``mean_error / |scale| × 100`` [%], NaN when the scale is 0 (nothing to compare to)."""
    return math.nan if scale == 0.0 else 100.0 * mean_error / abs(scale)


def compute_metrics(trace: Trace, contact_threshold: float = 1e-3) -> EpisodeMetrics:
    """The :class:`EpisodeMetrics` of ``trace`` over its push steps, rows 1 … N.

    ``contact_threshold`` [N]: a prong whose normal force λ_n is below it has lost contact;
    one whose λ_n is above it is in contact (and may slip). ``translation_error_pct`` is NaN
    if the plan's arc length is 0, as ``angle_error_pct`` is if its Δθ is 0.

    Raises :class:`~pushctl.errors.StateError` for a trace without push steps (N = 0) and
    :class:`~pushctl.errors.ConfigError` for a negative or non-finite threshold.
    """
    if trace.n_steps < 1:
        raise StateError(f"a trace needs at least 1 push step for metrics, got {trace.n_steps}")
    if not (math.isfinite(contact_threshold) and contact_threshold >= 0.0):
        raise ConfigError(f"contact_threshold must be finite and >= 0 N, got {contact_threshold!r}")

    seen = trace.object_pose if trace.measured_pose is None else trace.measured_pose
    pose = np.asarray(seen, dtype=float)[1:]  # (N, 3)
    pose_des = np.asarray(trace.desired_pose, dtype=float)[1:]  # (N, 3)
    forces = np.asarray(trace.contact_forces, dtype=float)[1:]  # (N, k, 2)
    forces_des = np.asarray(trace.desired_forces, dtype=float)[1:]  # (N, k, 2)
    torque = np.asarray(trace.contact_torque, dtype=float)[1:]  # (N,)
    torque_des = np.asarray(trace.desired_torque, dtype=float)[1:]  # (N,)
    gaps = np.asarray(trace.prong_gaps, dtype=float)[1:]  # (N, k)

    position_error = np.linalg.norm(pose[:, :2] - pose_des[:, :2], axis=1)  # (N,) [m]
    angle_error = np.abs(pose[:, 2] - pose_des[:, 2])  # (N,) [rad]
    mean_angle_error = float(np.mean(angle_error))

    normal, tangential = forces[:, :, 0], forces[:, :, 1]  # (N, k) [N]
    in_contact = normal > contact_threshold
    on_cone = np.abs(tangential) >= (1.0 - SLIP_TOLERANCE) * trace.mu_contact * normal
    lost = np.any(normal < contact_threshold, axis=1)  # (N,)
    slipping = np.any(in_contact & on_cone, axis=1)  # (N,)

    return EpisodeMetrics(
        translation_error_pct=_ratio_pct(float(np.mean(position_error)), trace.arc_length),
        angle_error_pct=_ratio_pct(mean_angle_error, trace.delta_theta),
        force_error=float(np.mean(np.linalg.norm(forces_des - forces, axis=2))),
        force_error_plan=_force_error_plan(trace, forces),
        torque_error=float(np.mean(np.abs(torque_des - torque))),
        contact_loss_fraction=float(np.mean(lost)),
        slip_fraction=float(np.mean(slipping)),
        max_penetration=max(0.0, -float(np.min(gaps))),
        final_position_error=float(position_error[-1]),
        final_angle_error=float(angle_error[-1]),
        angle_error_deg=math.degrees(mean_angle_error),
    )


def _force_error_plan(trace: Trace, forces: np.ndarray) -> float:
    """Mean ‖F_plan,i − λ_i‖₂ [N] over rows 1 … N (``forces`` (N, k, 2)); NaN without plan
    forces in the trace."""
    if trace.plan_forces is None:
        return math.nan
    planned = np.asarray(trace.plan_forces, dtype=float)[1:]
    return float(np.mean(np.linalg.norm(planned - forces, axis=2)))


def force_component_errors(trace: Trace) -> tuple[float, float]:
    """Mean |F_n,des,i − λ_n,i| and mean |F_t,des,i − λ_t,i| [N] over the push steps (rows
    1 … N) and prongs: the normal and tangential curves of the paper's Fig. 5."""
    if trace.n_steps < 1:
        raise StateError(f"a trace needs at least 1 push step for metrics, got {trace.n_steps}")
    error = np.abs(np.asarray(trace.desired_forces)[1:] - np.asarray(trace.contact_forces)[1:])
    return float(error[:, :, 0].mean()), float(error[:, :, 1].mean())


def pose_error_pct(error: Sequence[float], arc_length: float, turn: float) -> float:
    """One step's pose ``error`` (3,) [m, m, rad] in the units of the two errors above:
    100 ‖e_xy‖ / ``arc_length`` + 100 |e_θ| / ``turn`` [%] (``turn`` = |Δθ| [rad]), each
    part 0 where its scale is 0 (the per-step sum whose mean over the push is
    translation_error_pct + angle_error_pct)."""
    e_x, e_y, e_theta = error
    translation = 100.0 * math.hypot(e_x, e_y) / arc_length if arc_length > 0.0 else 0.0
    return translation + (100.0 * abs(e_theta) / turn if turn > 0.0 else 0.0)

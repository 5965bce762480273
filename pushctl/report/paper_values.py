"""The paper's published Tables III and IV, transcribed from the paper text
(``../shared/seeds/000_21b0af2e2484936f.txt``, Chen, Dai, Kövecses, section IV), for the
report to print beside ours.

What the numbers are, and why they are not ours:

- **Table III** ("Mean tracking percentage errors for each object and angular trajectory
  over 50 real-world trials"): translation and angle error [%], PD-only and RL-assisted,
  measured **on the real robot** with a 30 Hz camera. The paper does not say what the
  percentages are relative to; ours (docs/design.md §7) are the mean ‖p − p_des‖ over the push
  relative to the planned arc length, and the mean |θ − θ_des| relative to |Δθ|, on the
  ``sim`` plant.
- **Table IV** ("Mean planar force/torque tracking errors"): printed in units of 10⁻¹ N and
  10⁻³ N·m; stored here **in SI (N, N·m)**, i.e. the printed force × 0.1 and torque × 0.001.
  Its "Real" columns are the real robot's internal force/torque estimates; our ``proxy``
  plant stands in for that robot and is not one. The paper describes its force error as the
  mean of "absolute force deviations" (eq. 17 weighs |ΔF_n| and |ΔF_t| per prong, and
  |Δτ_z| per prong); ours is the mean over prongs of the Euclidean ‖F_des,i − λ_i‖₂ and the
  torque error is |Σ τ_des − Σ τ| of the totals about the centre of mass.
"""

from __future__ import annotations

PAPER = (
    "Chen, Dai, Kövecses: Hybrid Contact Dynamics and Residual-RL Framework for Multi-Point "
    "Object Pushing"
)
"""The source of every value in this module."""

TABLE3_SOURCE = "paper Table III: 50 real-world trials per row, PD-only vs RL-assisted [%]"
TABLE4_SOURCE = (
    "paper Table IV: sim (Vortex) and real robot, printed in 10^-1 N and 10^-3 N·m, "
    "stored in N and N·m"
)

TABLE3: dict[tuple[str, str], dict[str, float]] = {
    ("cube", "constant"): {
        "translation_error_pd": 22.3,
        "translation_error_rl": 4.0,
        "angle_error_pd": 14.5,
        "angle_error_rl": 4.0,
    },
    ("cube", "trapezoid"): {
        "translation_error_pd": 25.8,
        "translation_error_rl": 4.2,
        "angle_error_pd": 16.7,
        "angle_error_rl": 4.8,
    },
    ("cube", "chirp"): {
        "translation_error_pd": 26.5,
        "translation_error_rl": 4.8,
        "angle_error_pd": 17.4,
        "angle_error_rl": 5.2,
    },
    ("wedge", "constant"): {
        "translation_error_pd": 23.0,
        "translation_error_rl": 4.2,
        "angle_error_pd": 13.3,
        "angle_error_rl": 5.5,
    },
    ("wedge", "trapezoid"): {
        "translation_error_pd": 27.9,
        "translation_error_rl": 4.5,
        "angle_error_pd": 15.8,
        "angle_error_rl": 4.8,
    },
    ("wedge", "chirp"): {
        "translation_error_pd": 29.6,
        "translation_error_rl": 4.8,
        "angle_error_pd": 18.7,
        "angle_error_rl": 4.3,
    },
}
"""Paper Table III [%] by (object, profile), keyed by our ``table3.csv`` column names."""

# Table IV as printed: force in 10^-1 N, torque in 10^-3 N·m, in the paper's column order
# PD sim, PD real, RL sim, RL real. Converted to SI below.
_TABLE4_PRINTED: dict[tuple[str, str], tuple[tuple[float, ...], tuple[float, ...]]] = {
    ("cube", "constant"): ((1.71, 1.85, 0.65, 0.73), (6.02, 6.34, 2.26, 2.52)),
    ("cube", "trapezoid"): ((1.88, 2.02, 0.72, 0.81), (6.67, 7.21, 2.62, 2.96)),
    ("cube", "chirp"): ((2.05, 2.18, 0.78, 0.89), (7.44, 7.81, 2.93, 3.52)),
    ("wedge", "constant"): ((1.95, 2.08, 0.74, 0.83), (6.51, 6.91, 2.47, 3.13)),
    ("wedge", "trapezoid"): ((2.12, 2.56, 0.81, 0.92), (7.14, 7.61, 2.18, 2.63)),
    ("wedge", "chirp"): ((2.28, 2.43, 0.88, 0.94), (7.95, 8.33, 2.08, 2.48)),
}
_TABLE4_ORDER = ("pd_sim", "pd_proxy", "rl_sim", "rl_proxy")
FORCE_SCALE = 0.1
"""Paper Table IV force unit, 10⁻¹ N, in N."""
TORQUE_SCALE = 1e-3
"""Paper Table IV torque unit, 10⁻³ N·m, in N·m."""


def _table4() -> dict[tuple[str, str], dict[str, float]]:
    table: dict[tuple[str, str], dict[str, float]] = {}
    for key, (forces, torques) in _TABLE4_PRINTED.items():
        # the paper's force error is against its plan: our force_error_plan
        row = {
            f"force_error_plan_{c}": v * FORCE_SCALE
            for c, v in zip(_TABLE4_ORDER, forces, strict=True)
        }
        row |= {
            f"torque_error_{c}": v * TORQUE_SCALE
            for c, v in zip(_TABLE4_ORDER, torques, strict=True)
        }
        table[key] = row
    return table


TABLE4: dict[tuple[str, str], dict[str, float]] = _table4()
"""Paper Table IV in N and N·m by (object, profile), keyed by our ``table4.csv`` column names;
the paper's "Real" columns sit under our ``_proxy`` names (the closest thing we have). Its
force errors are against the desired forces of its plan ("computed from our dynamic
optimization"), so they are keyed ``force_error_plan_*``; our ``force_error_*`` (against what
the plant needed) has no paper counterpart."""

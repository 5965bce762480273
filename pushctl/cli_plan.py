"""``pushctl plan``: parse, plan, summarise, write. Registered on the app in :mod:`pushctl.cli`."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from rich.table import Table

from pushctl.errors import ConfigError
from pushctl.planning import Plan

POSE_FORMAT = "x,y,theta_deg (metres, metres, degrees), e.g. 0.62,0.03,30"
PLOT_SUFFIXES = (".png", ".pdf", ".svg")


def parse_pose(option: str, text: str) -> tuple[float, float, float]:
    """``"x,y,theta_deg"`` → (x [m], y [m], θ [rad]); ConfigError naming ``option``."""
    parts = text.replace(" ", "").split(",")
    try:
        x, y, theta_deg = (float(part) for part in parts)
    except ValueError:
        raise ConfigError(f"{option} must be {POSE_FORMAT}; got {text!r}") from None
    if not all(math.isfinite(v) for v in (x, y, theta_deg)):
        raise ConfigError(f"{option} must be finite numbers {POSE_FORMAT}; got {text!r}")
    return x, y, math.radians(theta_deg)


def check_output(option: str, path: Path | None, suffixes: tuple[str, ...]) -> None:
    """ConfigError unless ``path`` can be written: existing directory, accepted suffix."""
    if path is None:
        return
    if path.suffix.lower() not in suffixes:
        raise ConfigError(f"{option} must end in {', '.join(suffixes)}; got {str(path)!r}")
    if not path.parent.is_dir():
        raise ConfigError(f"{option}: directory {str(path.parent)!r} does not exist")
    if path.is_dir():
        raise ConfigError(f"{option}: {str(path)!r} is a directory, expected a file name")


def _mm(value: float) -> str:
    return f"{1e3 * value:.1f} mm"


def summary_table(plan: Plan) -> Table:
    """The rich summary printed by ``pushctl plan``."""
    tr, fp = plan.trajectory, plan.forces
    mu_contact, mu_ground = plan.settings.mu_contact, plan.settings.mu_ground
    table = Table(title=f"plan: {plan.obj.name}, {tr.profile} profile", show_header=False)
    start, goal = tr.start, tr.goal
    table.add_row(
        "start → goal",
        f"({start.x:.3f}, {start.y:.3f}) m, {math.degrees(start.theta):.1f} deg → "
        f"({goal.x:.3f}, {goal.y:.3f}) m, {math.degrees(goal.theta):.1f} deg",
    )
    if tr.icr is None:
        table.add_row("ICR", "none: a straight translation")
    else:
        table.add_row("ICR", f"({tr.icr[0]:.3f}, {tr.icr[1]:.3f}) m, radius {tr.radius:.3f} m")
    table.add_row("arc length (centre of mass)", _mm(tr.arc_length))
    table.add_row("Δθ", f"{math.degrees(tr.delta_theta):+.1f} deg")
    cone = math.degrees(math.atan(mu_contact))
    table.add_row(
        "push direction from face normal",
        f"{math.degrees(tr.push_angle):+.1f} deg (friction cone ±{cone:.1f} deg)",
    )
    table.add_row("duration, steps", f"{tr.duration:g} s, {tr.n_steps} steps of {tr.dt:g} s")
    lo, hi = fp.offset_range
    table.add_row("prong offset δ", f"{_mm(fp.offset)} (admissible {_mm(lo)} to {_mm(hi)})")
    points = ", ".join(f"{1e3 * t:+.1f}" for t in fp.prong_points[:, 1])
    table.add_row("prongs along the face", f"{points} mm")
    for i in range(fp.forces.shape[1]):
        normal, tangential = fp.forces[:, i, 0], np.abs(fp.forces[:, i, 1])
        table.add_row(
            f"prong {i + 1}: F_n, |F_t| peak",
            f"{normal.max():.3f} N (min {normal.min():.3f} N), {tangential.max():.3f} N",
        )
    table.add_row("|τ_z,des| peak (total)", f"{np.abs(fp.total_torque).max():.4f} N·m")
    table.add_row("Newton–Euler residual, max", f"{fp.residual.max():.2e} N")
    table.add_row("μ_c, μ_g", f"{mu_contact:g}, {mu_ground:g}")
    if plan.reach is not None:
        condition = plan.reach.condition[plan.reach.reached]
        worst = f"{condition.max():.1f}" if condition.size else "–"
        table.add_row(f"arm {plan.arm_name}: cond J along the path, max", worst)
    verdict = "[green]feasible[/green]" if plan.feasible else "[red]infeasible[/red]"
    table.add_row("feasibility", verdict)
    return table

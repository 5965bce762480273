"""``pushctl plan``: parse, plan, summarise, write."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import numpy as np
import typer
from rich.table import Table

from pushctl.cli.common import (
    DIMENSIONLESS,
    FORCE_HELP,
    OBJECT_HELP,
    PLOT_SUFFIXES,
    POSE,
    PUSHER_DEFAULT,
    PUSHER_HELP,
    SECONDS,
    Command,
    check_output,
    console,
    fail,
    fail_write,
    invocation,
    parse_pose,
)
from pushctl.errors import PushctlError
from pushctl.files.output_guard import refuse_existing_files

if TYPE_CHECKING:
    from pushctl.planning import Plan

app = typer.Typer()


@app.command(cls=Command)
def plan(
    ctx: typer.Context,
    goal: Annotated[str, typer.Option(metavar=POSE, help="goal pose, e.g. 0.62,0.03,30")],
    object_name: Annotated[str, typer.Option("--object", help=OBJECT_HELP)] = "cube",
    pusher: Annotated[
        Path | None,
        typer.Option(help=PUSHER_HELP, show_default=PUSHER_DEFAULT),
    ] = None,
    profile: Annotated[str, typer.Option(help="constant, trapezoid or chirp")] = "constant",
    start: Annotated[
        str | None,
        typer.Option(metavar=POSE, help="start pose", show_default="in front of the ready pose"),
    ] = None,
    duration: Annotated[float, typer.Option(metavar=SECONDS, help="push duration")] = 20.0,
    dt: Annotated[float, typer.Option(metavar=SECONDS, help="control step")] = 0.01,
    mu_contact: Annotated[
        float, typer.Option(metavar=DIMENSIONLESS, help="prong-object friction μ_c")
    ] = 0.4,
    mu_ground: Annotated[
        float, typer.Option(metavar=DIMENSIONLESS, help="object-table friction μ_g")
    ] = 0.3,
    arm: Annotated[str, typer.Option(help="kinova-gen2-7dof, kinova-j2s6s200 or panda")] = (
        "kinova-gen2-7dof"
    ),
    out: Annotated[Path | None, typer.Option(help="write the plan as CSV here")] = None,
    plot: Annotated[Path | None, typer.Option(help="save a figure (.png, .pdf, .svg)")] = None,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
) -> None:
    """Plan a push: ICR arc, angular profile, prong forces; check the arm can follow it."""
    from pushctl.arm import ArmConfig, load_arm
    from pushctl.arm.pusher_file import resolve_pusher
    from pushctl.config import PusherConfig
    from pushctl.files.provenance import provenance_line, write_csv
    from pushctl.objects import resolve_object
    from pushctl.planning import ForceSettings, make_plan
    from pushctl.planning.profiles import make_profile

    try:
        check_output("--out", out, (".csv",))
        check_output("--plot", plot, PLOT_SUFFIXES)
        refuse_existing_files("--out/--plot", (out, plot), force)
        goal_pose = parse_pose("--goal", goal)
        start_pose = None if start is None else parse_pose("--start", start)
        timing = make_profile(profile)
        settings = ForceSettings(mu_contact=mu_contact, mu_ground=mu_ground)
        plate = resolve_pusher(pusher)
        spec = resolve_object(object_name, pusher_mass=None if plate is None else plate.mass)
        plate = replace(plate or PusherConfig(), mass=spec.pusher_mass)
        model = load_arm(ArmConfig(name=arm, pusher=plate))
        result = make_plan(
            spec,
            goal_pose,
            start=start_pose,
            profile=timing,
            duration=duration,
            dt=dt,
            forces=settings,
            arm=model,
        )
        console.print(summary_table(result))
        result.raise_if_infeasible()
    except PushctlError as error:
        fail(error)
    figure = None
    if plot is not None:
        from pushctl.report import plan_figure

        figure = plan_figure(result)
    try:
        if out is not None:
            write_csv(out, result.to_frame(), provenance_line(invocation(ctx)))
            console.print(f"wrote {out}")
        if plot is not None and figure is not None:
            from pushctl.files.provenance import write_atomic

            write_atomic(plot, lambda tmp: figure.savefig(tmp, format=plot.suffix[1:], dpi=150))
            console.print(f"wrote {plot}")
    except (OSError, PushctlError) as error:
        fail_write(error)


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

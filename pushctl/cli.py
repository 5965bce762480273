"""The ``pushctl`` command line. Each command parses, validates, calls the core, renders.

Built so far: ``pushctl info`` and ``pushctl plan``. ``simulate``, ``train``, ``evaluate`` and
``report`` come with the issues that build them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console
from rich.table import Table

from pushctl.errors import PushctlError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Multi-point object pushing with a redundant arm: simulate, plan, train, evaluate.",
)
console = Console()
error_console = Console(stderr=True, soft_wrap=True)


def _fail(error: PushctlError) -> None:
    """One line on stderr, exit code 2, no traceback."""
    error_console.print(f"error: {error}", markup=False, highlight=False)
    raise typer.Exit(code=2)


@app.callback()
def _main() -> None:
    """pushctl: multi-point object pushing experiments."""


@app.command()
def info(
    object_name: Annotated[
        str, typer.Option("--object", help="cube, wedge, or a TOML object file")
    ] = "cube",
    arm: Annotated[str, typer.Option(help="kinova-gen2-7dof, kinova-j2s6s200 or panda")] = (
        "kinova-gen2-7dof"
    ),
) -> None:
    """Show the model of an object and an arm: mass properties, supports, ready pose."""
    from pushctl.arm import ArmConfig, load_arm
    from pushctl.config import PusherConfig
    from pushctl.objects import resolve_object

    try:
        spec = resolve_object(object_name)
        model = load_arm(ArmConfig(name=arm, pusher=PusherConfig(mass=spec.pusher_mass)))
    except PushctlError as error:
        _fail(error)
    table = Table(title=f"object {spec.name!r}", show_header=False)
    table.add_row("mass", f"{spec.mass:.4g} kg")
    table.add_row("I_z about the centre of mass", f"{spec.inertia_z:.4e} kg·m²")
    table.add_row("centre of mass height", f"{1e3 * spec.com_height:.2f} mm")
    table.add_row("centre of mass to pushed face", f"{1e3 * spec.face_offset:.2f} mm")
    for point, load in zip(np.asarray(spec.support_points), spec.support_loads, strict=True):
        table.add_row(
            "support point (x, y) / load",
            f"({1e3 * point[0] + 0.0:.1f}, {1e3 * point[1] + 0.0:.1f}) mm / {load:.4f} N",
        )
    table.add_row("pusher mass (Table II)", f"{spec.pusher_mass:.3g} kg")
    console.print(table)
    arm_table = Table(title=f"arm {model.name!r}", show_header=False)
    arm_table.add_row("joints (nq, nv)", f"{model.nq}, {model.nv}")
    arm_table.add_row("armature", ", ".join(f"{a:.4g}" for a in model.armature) + " kg·m²")
    arm_table.add_row("damping", ", ".join(f"{d:.4g}" for d in model.damping) + " N·m·s/rad")
    arm_table.add_row("ready q", ", ".join(f"{q:.4f}" for q in model.q_ready) + " rad")
    position = ", ".join(f"{x:.3f}" for x in model.ready_pusher_position)
    arm_table.add_row("ready pusher position", f"({position}) m")
    jacobian = model.pusher_jacobian(model.q_ready)
    mass = model.compute(model.q_ready, np.zeros(model.nv)).M
    arm_table.add_row("cond J (pusher, ready)", f"{np.linalg.cond(jacobian):.1f}")
    arm_table.add_row(
        "smallest eigenvalue of M (ready)", f"{np.linalg.eigvalsh(mass)[0]:.4f} kg·m²"
    )
    console.print(arm_table)


@app.command()
def plan(
    goal: Annotated[str, typer.Option(help="goal pose x,y,theta_deg [m, m, deg]")],
    object_name: Annotated[
        str, typer.Option("--object", help="cube, wedge, or a TOML object file")
    ] = "cube",
    profile: Annotated[str, typer.Option(help="constant, trapezoid or chirp")] = "constant",
    start: Annotated[
        str | None,
        typer.Option(help="start pose x,y,theta_deg; default: in front of the ready pose"),
    ] = None,
    duration: Annotated[float, typer.Option(help="push duration [s]")] = 20.0,
    dt: Annotated[float, typer.Option(help="control step [s]")] = 0.01,
    mu_contact: Annotated[float, typer.Option(help="prong-object friction μ_c")] = 0.4,
    mu_ground: Annotated[float, typer.Option(help="object-table friction μ_g")] = 0.3,
    arm: Annotated[str, typer.Option(help="kinova-gen2-7dof, kinova-j2s6s200 or panda")] = (
        "kinova-gen2-7dof"
    ),
    out: Annotated[Path | None, typer.Option(help="write the plan as CSV here")] = None,
    plot: Annotated[Path | None, typer.Option(help="save a figure (.png, .pdf, .svg)")] = None,
) -> None:
    """Plan a push: ICR arc, angular profile, prong forces; check the arm can follow it."""
    from pushctl.arm import ArmConfig, load_arm
    from pushctl.cli_plan import PLOT_SUFFIXES, check_output, parse_pose, summary_table
    from pushctl.config import PusherConfig
    from pushctl.objects import resolve_object
    from pushctl.planning import ForceSettings, make_plan
    from pushctl.planning.profiles import make_profile
    from pushctl.provenance import provenance_line, write_csv

    try:
        check_output("--out", out, (".csv",))
        check_output("--plot", plot, PLOT_SUFFIXES)
        goal_pose = parse_pose("--goal", goal)
        start_pose = None if start is None else parse_pose("--start", start)
        timing = make_profile(profile)
        settings = ForceSettings(mu_contact=mu_contact, mu_ground=mu_ground)
        spec = resolve_object(object_name)
        model = load_arm(ArmConfig(name=arm, pusher=PusherConfig(mass=spec.pusher_mass)))
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
        _fail(error)
    figure = None
    if plot is not None:
        from pushctl.report import plan_figure

        figure = plan_figure(result)
    try:
        if out is not None:
            write_csv(out, result.to_frame(), provenance_line("pushctl plan " + _arguments()))
            console.print(f"wrote {out}")
        if plot is not None and figure is not None:
            from pushctl.provenance import write_atomic

            write_atomic(plot, lambda tmp: figure.savefig(tmp, format=plot.suffix[1:], dpi=150))
            console.print(f"wrote {plot}")
    except OSError as error:
        _fail(PushctlError(f"cannot write {error.filename}: {error.strerror}"))


def _arguments() -> str:
    """This process's arguments after the command name, for provenance lines."""
    import shlex
    import sys

    return shlex.join(sys.argv[2:])


if __name__ == "__main__":
    app()

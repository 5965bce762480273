"""``pushctl simulate``: one push with a controller; its steps are in
:mod:`pushctl.cli.simulate_steps` (imported when the command runs)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from pushctl.cli.common import (
    DIMENSIONLESS,
    FORCE_HELP,
    KILOGRAMS,
    OBJECT_HELP,
    PLOT_SUFFIXES,
    POSE,
    PUSHER_DEFAULT,
    PUSHER_HELP,
    SECONDS,
    Command,
    check_output,
    console,
    controller_help,
    error_console,
    fail,
    invocation,
    parse_pose,
    renamed_option,
    take_renamed,
    write_outputs,
)
from pushctl.errors import PushctlError
from pushctl.files.output_guard import refuse_existing_files

app = typer.Typer()


@app.command(cls=Command)
def simulate(
    ctx: typer.Context,
    object_name: Annotated[str, typer.Option("--object", help=OBJECT_HELP)] = "cube",
    pusher: Annotated[
        Path | None,
        typer.Option(help=PUSHER_HELP, show_default=PUSHER_DEFAULT),
    ] = None,
    profile: Annotated[str, typer.Option(help="constant, trapezoid or chirp")] = "constant",
    goal: Annotated[
        str | None,
        typer.Option(metavar=POSE, help="goal pose, e.g. 0.62,0.03,30; or use --scenario"),
    ] = None,
    scenario_seed: Annotated[
        int | None,
        typer.Option(
            "--scenario",
            help="draw the goal (and with --randomize the plant) as scenario N of the "
            "evaluation stream: evaluate's trial N",
        ),
    ] = None,
    controller: Annotated[str, typer.Option(help=controller_help())] = "pd",
    policy: Annotated[
        Path | None,
        typer.Option(help="rl's policy", show_default="results/training/policy.pt, shipped"),
    ] = None,
    randomize: Annotated[
        bool,
        typer.Option(
            "--randomize", help="draw μ_g, μ_c, masses and plant unknowns from the plant's ranges"
        ),
    ] = False,
    plant: Annotated[
        str, typer.Option(help="sim, proxy (the reality proxy) or mujoco (docs/mujoco.md)")
    ] = "sim",
    mu_ground: Annotated[
        float | None,
        typer.Option(
            metavar=DIMENSIONLESS,
            help="plant's object-table μ_g",
            show_default="nominal; drawn with --randomize",
        ),
    ] = None,
    mu_contact: Annotated[
        float | None,
        typer.Option(
            metavar=DIMENSIONLESS,
            help="plant's prong-object μ_c",
            show_default="nominal; drawn with --randomize",
        ),
    ] = None,
    object_mass: Annotated[
        float | None,
        typer.Option(
            metavar=KILOGRAMS,
            help="plant's object mass",
            show_default="nominal; drawn with --randomize",
        ),
    ] = None,
    duration: Annotated[float, typer.Option(metavar=SECONDS, help="push duration")] = 20.0,
    gains: Annotated[
        Path | None,
        typer.Option(help="PD gains file", show_default="pushctl/defaults/pd_gains.toml"),
    ] = None,
    arm: Annotated[str, typer.Option(help="kinova-gen2-7dof, kinova-j2s6s200 or panda")] = (
        "kinova-gen2-7dof"
    ),
    out: Annotated[Path | None, typer.Option(help="write the trace as CSV here")] = None,
    plot: Annotated[Path | None, typer.Option(help="save a figure (.png, .pdf, .svg)")] = None,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
    seed: Annotated[int | None, renamed_option("--seed")] = None,
) -> None:
    """Run one push with a controller: approach, push, metrics, trace and figure."""
    from pushctl.arm.pusher_file import resolve_pusher
    from pushctl.cli.simulate_steps import (
        check_controller,
        check_plant,
        check_pusher,
        metrics_table,
        push,
        scenario_table,
        simulate_scenario,
    )
    from pushctl.cli.warm import note_if_cold
    from pushctl.control import load_gains
    from pushctl.episode.metrics import compute_metrics

    scenario_seed = take_renamed(ctx, "--scenario", scenario_seed, "--seed", seed)
    try:
        check_output("--out", out, (".csv",))
        check_output("--plot", plot, PLOT_SUFFIXES)
        refuse_existing_files("--out/--plot", (out, plot), force)
        check_controller(controller)
        check_plant(plant)
        goal_pose = None if goal is None else parse_pose("--goal", goal)
        pd_gains = load_gains(gains)
        overrides = {"mu_ground": mu_ground, "mu_contact": mu_contact, "object_mass": object_mass}
        plate = resolve_pusher(pusher)
        check_pusher(plate, controller)
        scenario, redrawn = simulate_scenario(
            object_name,
            profile,
            goal_pose,
            scenario_seed,
            randomize,
            overrides,
            duration,
            arm,
            plant,
            plate,
        )
        note_if_cold(error_console)
        trace, made = push(scenario, controller, pd_gains, policy, plant)
        console.print(scenario_table(scenario, made.trajectory.start, redrawn))
        metrics = compute_metrics(trace)
    except PushctlError as error:
        fail(error)
    console.print(metrics_table(metrics))
    figure = None
    if plot is not None:
        from pushctl.report import trace_figure

        figure = trace_figure(trace)
    command = invocation(ctx)
    extra = f"seed {scenario_seed}" if scenario_seed is not None else "no seed"
    write_outputs(command, out, trace.to_frame() if out else None, plot, figure, extra)

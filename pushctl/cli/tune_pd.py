"""``pushctl tune-pd``: search the PD gains on the tuning stream, write the gains file."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from pushctl.cli.common import (
    FORCE_HELP,
    SECONDS,
    Command,
    check_output,
    console,
    error_console,
    fail,
    invocation,
    renamed_option,
    take_renamed,
    write_text,
)
from pushctl.errors import PushctlError
from pushctl.files.output_guard import refuse_existing_files

app = typer.Typer()


@app.command("tune-pd", cls=Command)
def tune_pd_command(
    ctx: typer.Context,
    first_scenario: Annotated[
        int, typer.Option(help="the tuning set's first scenario (tuning stream)")
    ] = 0,
    per_case: Annotated[int, typer.Option(help="scenarios per object × profile")] = 2,
    objects: Annotated[str, typer.Option(help="comma-separated objects")] = "cube,wedge",
    profiles: Annotated[str, typer.Option(help="comma-separated profiles")] = (
        "constant,trapezoid,chirp"
    ),
    duration: Annotated[float, typer.Option(metavar=SECONDS, help="push duration")] = 20.0,
    max_rounds: Annotated[int, typer.Option(help="refinement sweeps after the grid")] = 6,
    out: Annotated[
        Path,
        typer.Option(help="gains file to write (never the shipped gains)"),
    ] = Path("experiments/pd_gains.toml"),
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
    seed: Annotated[int | None, renamed_option("--seed")] = None,
) -> None:
    """Search the PD gains on a tuning set disjoint from evaluation; write the gains file."""
    from pushctl.cli.simulate_steps import check_profile, tuning_record
    from pushctl.cli.warm import note_if_cold
    from pushctl.evaluation.tune_pd import best_candidate, tune_pd, tuning_scenarios
    from pushctl.objects import resolve_object

    first_scenario = take_renamed(ctx, "--first-scenario", first_scenario, "--seed", seed)
    target = out
    try:
        check_output("--out", target, (".toml",))
        refuse_existing_files("--out", (target,), force)
        object_names = tuple(name for name in objects.split(",") if name)
        profile_names = tuple(name for name in profiles.split(",") if name)
        for name in object_names:
            resolve_object(name)
        for name in profile_names:
            check_profile(name)
        if not object_names or not profile_names:
            raise PushctlError("--objects and --profiles each need at least one name")
        if per_case < 1:
            raise PushctlError(f"--per-case must be an integer >= 1, got {per_case}")
        if max_rounds < 0:
            raise PushctlError(f"--max-rounds must be >= 0, got {max_rounds}")
        note_if_cold(error_console)
        with console.status("drawing the tuning set"):
            scenarios, redrawn = tuning_scenarios(
                first_scenario, object_names, profile_names, per_case, duration
            )
        with console.status("grid search") as status:

            def report(candidate) -> None:
                g = candidate.gains
                status.update(
                    f"K_p {g.kp:.4g}, K_v {g.kv:.4g}, K_x {g.kx_linear:.4g}: "
                    f"{candidate.objective:.4f} % tracking error"
                )

            candidates = tune_pd(scenarios, max_rounds=max_rounds, progress=report)
    except PushctlError as error:
        fail(error)
    best = best_candidate(candidates)
    table = Table(title=f"PD gain search: {len(scenarios)} tuning episodes, best 10")
    for column in ("K_p", "K_v", "K_x", "translation %", "angle %", "objective"):
        table.add_column(column, justify="right")
    for candidate in sorted(candidates, key=lambda c: c.objective)[:10]:
        g = candidate.gains
        table.add_row(
            f"{g.kp:.4g}",
            f"{g.kv:.4g}",
            f"{g.kx_linear:.4g}",
            f"{candidate.translation_error_pct:.4f}",
            f"{candidate.angle_error_pct:.4f}",
            f"{candidate.objective:.4f}",
        )
    console.print(table)
    text = tuning_record(
        best, candidates, first_scenario, per_case, object_names, profile_names, duration, redrawn,
        invocation(ctx),
    )  # fmt: skip
    write_text(target, text)

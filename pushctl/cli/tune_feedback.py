"""``pushctl tune-feedback``: search the feedback baseline's gains on the tuning stream;
its steps are in :mod:`pushctl.cli.tune_feedback_steps`."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

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


@app.command("tune-feedback", cls=Command)
def tune_feedback_command(
    ctx: typer.Context,
    first_scenario: Annotated[
        int, typer.Option(help="the tuning set's first scenario (tuning stream)")
    ] = 0,
    per_case: Annotated[int, typer.Option(help="scenarios per object × profile")] = 2,
    duration: Annotated[float, typer.Option(metavar=SECONDS, help="push duration")] = 20.0,
    plant: Annotated[
        str, typer.Option(help="tuning pushes on sim, proxy or both (each per_case per cell)")
    ] = "both",
    out: Annotated[
        Path,
        typer.Option(help="gains file to write (never the shipped gains)"),
    ] = Path("experiments/feedback_gains.toml"),
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
    seed: Annotated[int | None, renamed_option("--seed")] = None,
) -> None:
    """Search the feedback baseline's gains (k, k_i) on the tuning stream; write the file."""
    from pushctl.cli.tune_feedback_steps import run_search
    from pushctl.cli.warm import note_if_cold

    first_scenario = take_renamed(ctx, "--first-scenario", first_scenario, "--seed", seed)
    try:
        check_output("--out", out, (".toml",))
        refuse_existing_files("--out", (out,), force)
        note_if_cold(error_console)
        target, text, table = run_search(
            first_scenario, per_case, duration, out, invocation(ctx), console, plant
        )
    except PushctlError as error:
        fail(error)
    console.print(table)
    write_text(target, text)

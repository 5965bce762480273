"""``pushctl tune-feedback``: search the feedback baseline's gains on the tuning stream;
its steps are in :mod:`pushctl.cli.tune_feedback_steps`."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from pushctl.cli.common import (
    FORCE_HELP,
    check_output,
    console,
    fail,
    invocation,
    write_text,
)
from pushctl.errors import PushctlError
from pushctl.output_guard import refuse_existing_files

app = typer.Typer()


@app.command("tune-feedback")
def tune_feedback_command(
    ctx: typer.Context,
    seed: Annotated[int, typer.Option(help="first scenario seed of the tuning set")] = 0,
    per_case: Annotated[int, typer.Option(help="scenarios per object × profile")] = 2,
    duration: Annotated[float, typer.Option(help="push duration [s]")] = 20.0,
    plant: Annotated[
        str, typer.Option(help="tuning pushes on sim, proxy or both (each per_case per cell)")
    ] = "both",
    out: Annotated[
        Path | None,
        typer.Option(help="gains file to write; default experiments/feedback_gains.toml"),
    ] = None,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
) -> None:
    """Search the feedback baseline's gains (k, k_i) on the tuning stream; write the file."""
    from pushctl.cli.tune_feedback_steps import run_search
    from pushctl.control.feedback import DEFAULT_FEEDBACK_FILE

    try:
        check_output("--out", out, (".toml",))
        refuse_existing_files("--out", (out if out is not None else DEFAULT_FEEDBACK_FILE,), force)
        target, text, table = run_search(
            seed, per_case, duration, out, invocation(ctx), console, plant
        )
    except PushctlError as error:
        fail(error)
    console.print(table)
    write_text(target, text)

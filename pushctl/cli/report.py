"""``pushctl report``: the tables and figures from the results CSVs; its steps are in
:mod:`pushctl.cli.report_steps`."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from pushctl.cli.common import (
    FORCE_HELP,
    Command,
    console,
    error_console,
    fail,
    fail_write,
    invocation,
)
from pushctl.errors import PushctlError
from pushctl.files.output_guard import refuse_existing_files

app = typer.Typer()


@app.command(cls=Command)
def report(
    ctx: typer.Context,
    in_dir: Annotated[
        Path,
        typer.Option(
            "--in",
            help="results directory holding evaluation/ (and training/ for Fig. 5), or an "
            "evaluation directory; the shipped ones: results",
        ),
    ] = Path("runs"),
    out: Annotated[Path, typer.Option(help="directory for the tables and figures")] = Path(
        "runs/report"
    ),
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
    trust_undigested: Annotated[
        bool,
        typer.Option(
            "--trust-undigested",
            help="report from pushctl CSVs without their digest (an edit to them goes unseen)",
        ),
    ] = False,
) -> None:
    """Tables III and IV (CSV and Markdown, beside the paper's values) and Figs. 5, 6 and 8
    from the evaluation and training CSVs (without a training run, Fig. 5 is skipped)."""
    from pushctl.cli.report_steps import (
        check_out_dir,
        counts_table,
        make_report,
        report_paths,
        write_report,
    )

    try:
        check_out_dir(out)
        refuse_existing_files("--out", report_paths(out), force)
        with console.status("reading the results and drawing the figures"):
            made = make_report(in_dir, invocation(ctx), trust_undigested)
        written = write_report(made, out)
    except PushctlError as error:
        fail(error)
    except OSError as error:
        fail_write(error)
    console.print(counts_table(made))
    for note in made.notes:
        console.print(f"note: {note}", highlight=False, soft_wrap=True)
    for warning in made.warnings:
        error_console.print(f"warning: {warning}", style="bold", highlight=False, markup=False)
    for path in written:
        console.print(f"wrote {path}")

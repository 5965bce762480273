"""``pushctl reproduce`` (``make reproduce-tables``): train, evaluate, report and bench, timed,
with a manifest; the work is in :mod:`pushctl.reproduce.steps`.

Run from the checkout's root. ``--seeds 0``: other training seeds, e.g. one. ``--quick``: the
``quick`` preset, 4 trials, no bench, everything under ``results-quick/`` and ``runs/quick``
(the committed ``results/`` stays as it is). ``--preset NAME``: another training preset,
the full evaluation. Nothing it did not make is overwritten: the steps overwrite the results
directory's files only when that directory is absent, empty, or holds a manifest of an
earlier reproduction (the shipped ``results/`` does, so a clean clone reproduces into it);
anything else is refused with one line naming ``--force``. A training run directory with a
checkpoint is resumed.
"""

from __future__ import annotations

from typing import Annotated

import typer

from pushctl.cli.common import Command, console, error_console, fail
from pushctl.errors import ConfigError

app = typer.Typer()


@app.command("reproduce", cls=Command)
def reproduce_command(
    quick: Annotated[
        bool, typer.Option("--quick", help="quick preset, 4 trials, into results-quick/")
    ] = False,
    seeds: Annotated[
        str | None,
        typer.Option(
            help="training seeds, e.g. 0,1,2 or 0-2 or 0", show_default="0-4; 0,1,2 with --quick"
        ),
    ] = None,
    preset: Annotated[
        str | None,
        typer.Option(
            help="training preset",
            show_default="experiments/train_paper_v1.toml; quick with --quick",
        ),
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", help="overwrite a results directory it did not make")
    ] = False,
) -> None:
    """Make the shipped results again: train, evaluate, report, bench (about 2 h on two
    cores: docs/performance.md)."""
    from pushctl.files.output_guard import hold
    from pushctl.reproduce.manifest import minutes
    from pushctl.reproduce.plan import MANIFEST, check_owned
    from pushctl.reproduce.steps import choose_setup, reproduce

    try:
        setup = choose_setup(quick, force, seeds, preset)
        if setup.results.exists() and not setup.results.is_dir():
            raise ConfigError(f"{setup.results} is a file; give a directory")
        hold("the results directory", setup.results, directory=True)  # one at a time
        refusal = check_owned(setup)
        if refusal is not None:
            raise ConfigError(refusal)
    except ConfigError as error:
        fail(error)
    records = reproduce(setup)
    failed = [r for r in records if r.returncode != 0]
    if failed:
        step = failed[0]
        error_console.print(f"error: step {step.name} failed: {step.command}", markup=False)
        raise typer.Exit(code=step.returncode)
    total = minutes(sum(r.seconds for r in records))
    console.print(f"reproduce: done in {total}; see {setup.results / MANIFEST}", markup=False)

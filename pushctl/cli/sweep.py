"""``pushctl sweep CONFIG.toml``: a grid or random search over preset keys × seeds on Ray,
scored on the validation set (tuning stream); writes the runs, ``trials.csv``,
``summary.csv`` and ``sweep.png`` (:mod:`pushctl.runs.sweep`)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from pushctl.cli.common import Command

app = typer.Typer()


@app.command(cls=Command)
def sweep(
    ctx: typer.Context,
    config: Annotated[Path, typer.Argument(help="sweep file (see experiments/sweep_gate.toml)")],
    out: Annotated[
        Path | None, typer.Option(help="sweep directory", show_default="runs/sweep-CONFIG")
    ] = None,
    resume: Annotated[
        bool, typer.Option("--resume", help="continue the runs in --out, re-score them")
    ] = False,
    address: Annotated[
        str | None,
        typer.Option(help="Ray cluster to join", show_default="RAY_ADDRESS, else a local one"),
    ] = None,
) -> None:
    """Train every configuration of a sweep file × its seeds (one Ray task each), score each
    run's policy on the validation set, and write trials.csv, summary.csv and sweep.png."""
    from pushctl.cli.common import console, fail, fail_write, interrupted, invocation
    from pushctl.cli.train_seeds import run_jobs_with_progress
    from pushctl.errors import ConfigError, PushctlError
    from pushctl.files.output_guard import hold, occupied
    from pushctl.files.provenance import provenance_line
    from pushctl.runs.sweep import gather, score_policy, sweep_jobs
    from pushctl.runs.sweep_config import read_sweep

    directory = out if out is not None else Path("runs") / f"sweep-{config.stem}"
    try:
        chosen = read_sweep(config)
        hold("--out", directory, directory=True)  # one command at a time, until this one ends
        if occupied(directory) and not resume:
            raise ConfigError(
                f"{directory} already holds a sweep; pass --resume to continue it "
                "or choose another --out"
            )
        made_by = provenance_line(invocation(ctx).replace(" config ", " ", 1))
        jobs = sweep_jobs(chosen, directory, made_by)
        results = run_jobs_with_progress(jobs, address, console, finish=score_policy)
        result = gather(chosen, results)
        written = write_sweep(directory, result, made_by)
    except PushctlError as error:
        fail(error)
    except KeyboardInterrupt:
        interrupted(f"`pushctl sweep {config} --resume --out {directory}` continues")
    except OSError as error:
        fail_write(error)
    console.print(summary_table(result))
    for path in written:
        console.print(f"wrote {path}")


def write_sweep(directory: Path, result, made_by: str) -> list[Path]:
    """``trials.csv`` and ``summary.csv`` under ``made_by`` and ``sweep.png``, each
    atomically; the figure is in place before the tables appear."""
    from pushctl.files.provenance import write_atomic, write_csv
    from pushctl.report.sweep_figure import sweep_figure
    from pushctl.runs.sweep import FIGURE_FILE, SUMMARY_FILE, TRIALS_FILE

    directory.mkdir(parents=True, exist_ok=True)
    figure = sweep_figure(result.trials, result.sweep.keys, grid=result.sweep.search == "grid")
    write_atomic(directory / FIGURE_FILE, lambda tmp: figure.savefig(tmp, format="png", dpi=150))
    write_csv(directory / SUMMARY_FILE, result.summary, made_by)
    write_csv(directory / TRIALS_FILE, result.trials, made_by)
    return [directory / name for name in (TRIALS_FILE, SUMMARY_FILE, FIGURE_FILE)]


def summary_table(result):
    """The summary, best mean score first: values, seeds, score mean ± sd [min, max], runs
    that beat PD-only."""
    from rich.table import Table

    keys = result.sweep.keys
    table = Table(title="sweep: validation score (force + translation ratio; PD-only = 2)")
    for heading in ("trial", *keys, "seeds", "score mean", "sd", "min", "max", "beat PD"):
        table.add_column(heading, justify="right", overflow="fold")
    for row in result.summary.to_dict("records"):
        table.add_row(
            f"{int(row['trial']):03d}",
            *(f"{row[key]:.4g}" if isinstance(row[key], float) else str(row[key]) for key in keys),
            str(row["seeds"]),
            *(f"{row[f'score_{name}']:.3f}" for name in ("mean", "std", "min", "max")),
            f"{row['beats_pd']}/{row['seeds']}",
        )
    return table

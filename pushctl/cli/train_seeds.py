"""``pushctl train --seeds``: checks the options and every seed's run directory, runs the
seeds as Ray tasks (:mod:`pushctl.runs.seeds`) and shows their progress with rich."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from pushctl.cli.warm import note_if_cold
from pushctl.control.gains import load_gains
from pushctl.distributed.engine import session
from pushctl.errors import ConfigError
from pushctl.files.output_guard import hold, is_ours, occupied
from pushctl.files.provenance import provenance_line
from pushctl.rl.presets import load_preset
from pushctl.rl.train import CHECKPOINT, CURVE, LAST_POLICY, POLICY, VALIDATION, Trainer
from pushctl.rl.warm_up import compile_kernels
from pushctl.runs.seeds import (
    TIMING,
    JobResult,
    SeedStatus,
    TrainJob,
    parse_seeds,
    run_jobs,
    seed_dir,
)

LOG_EVERY = 25
"""Episodes between a seed's plain progress lines when the output is not a terminal."""


def prepare_seed_jobs(
    preset: str | None,
    seeds_text: str,
    seed: int | None,
    out: Path | None,
    episodes: int | None,
    resume: bool,
    force: bool,
    command: str,
) -> list[TrainJob]:
    """One job per seed of ``seeds_text``, into ``OUT/seed-K/``; ConfigError (one line) for
    a clash of options, a bad seed list or episode count, an unknown preset, or a seed
    directory that holds a run while neither --resume nor --force is given. Nothing is
    written, except that --force removes the seeds' old run files once every check passed.

    With --resume a seed continues from its checkpoint, or starts if it has none yet (an
    interrupted ``make reproduce-tables`` may have stopped before a seed's first one)."""
    if seed is not None:
        raise ConfigError("--seed and --seeds exclude each other: give one seed or a list")
    if resume and force:
        raise ConfigError("--resume and --force exclude each other: continue, or start over")
    if episodes is not None and episodes < 1:
        raise ConfigError(f"--episodes must be an integer >= 1, got {episodes}")
    seeds = parse_seeds(seeds_text)
    name = preset or "quick"
    root = out if out is not None else Path("runs") / f"{name}-seeds"
    if root.exists() and not root.is_dir():
        raise ConfigError(f"--out {root} is a file; give a directory")
    chosen = load_preset(name)
    gains = load_gains()
    directories = [seed_dir(root, s).absolute() for s in seeds]
    hold("--out", root, directory=True)  # one command at a time, until this one ends
    for directory in directories:
        if not directory.is_file():
            hold("--out", directory, directory=True)
        _check_seed_directory(directory, resume, force)
    if force:
        for directory in directories:
            for stale in (CHECKPOINT, CURVE, POLICY, LAST_POLICY, VALIDATION):
                (directory / stale).unlink(missing_ok=True)
    return [
        TrainJob(
            preset=chosen,
            seed=s,
            out=directory,
            episodes=episodes,
            made_by=provenance_line(command, f"seed {s} (training stream)"),
            gains=gains,
            check_preset=preset is not None or not resume,
        )
        for s, directory in zip(seeds, directories, strict=True)
    ]


def _check_seed_directory(directory: Path, resume: bool, force: bool) -> None:
    if directory.exists() and not directory.is_dir():
        raise ConfigError(f"{directory} is a file; a seed's run needs a directory")
    if not occupied(directory) or force:
        return
    if not resume:
        raise ConfigError(
            f"{directory} already holds a run; pass --resume to continue it "
            "or --force to start over"
        )
    kept = {entry.name for entry in directory.iterdir()} - {TIMING}
    if not (directory / CHECKPOINT).is_file() and any(not is_ours(name) for name in kept):
        raise ConfigError(
            f"{directory} holds files but no checkpoint to resume; "
            "pass --force to start that seed over"
        )


def run_jobs_with_progress(
    jobs: list[TrainJob],
    address: str | None,
    console: Console,
    finish: Callable[[Trainer], Any] | None = None,
) -> list[tuple[JobResult, Any]]:
    """:func:`~pushctl.runs.seeds.run_jobs` with one progress bar per job, after
    numba's kernels are compiled in this process (:mod:`pushctl.rl.warm_up`)."""
    columns = (
        TextColumn("[bold]{task.fields[label]}"),
        MofNCompleteColumn(),
        BarColumn(),
        TextColumn("{task.fields[rates]}"),
        TimeElapsedColumn(),
    )
    logged: dict[str, int] = {}
    if jobs:  # the seeds' processes (one seed's learner and collectors too) would each
        # compile the kernels, all at once; with the cache filled this takes a second
        first = jobs[0]
        note_if_cold(console)
        compile_kernels(first.preset.env, first.gains, first.preset.ddpg.hidden)
    # Ray first: a cluster that does not answer is a one-line error, with no display drawn
    live = console.is_terminal  # else plain lines: a live bar's last frame wraps in a log
    with session(address), Progress(*columns, console=console, disable=not live) as progress:
        bars = {
            job.name: progress.add_task(
                "train", total=job.episodes or job.preset.train.episodes, label=job.name, rates=""
            )
            for job in jobs
        }

        def show(status: dict[str, SeedStatus]) -> None:
            for key, now in status.items():
                progress.update(bars[key], completed=now.done, total=now.total, rates=now.rates)
                due = now.done // LOG_EVERY > logged.get(key, 0) // LOG_EVERY
                if not console.is_terminal and (due or now.done == now.total):
                    if logged.get(key) != now.done:
                        console.print(
                            f"{key} episode {now.done}/{now.total}  {now.rates}",
                            highlight=False,
                            soft_wrap=True,
                        )
                logged[key] = now.done

        return run_jobs(jobs, address, on_progress=show, finish=finish)


def seeds_table(results: list[JobResult]) -> Table:
    """Per seed: episodes, env steps, gradient updates, wall time and run directory."""
    table = Table(title="training runs")
    for heading in ("seed", "episodes", "env steps", "updates", "wall time", "directory"):
        table.add_column(heading, justify="left" if heading == "directory" else "right")
    for r in results:
        table.add_row(
            str(r.seed),
            str(r.episodes),
            f"{r.env_steps:,}",
            f"{r.updates:,}",
            f"{r.seconds:,.0f} s",
            str(r.out.relative_to(Path.cwd()) if r.out.is_relative_to(Path.cwd()) else r.out),
        )
    return table

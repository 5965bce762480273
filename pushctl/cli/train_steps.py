"""``pushctl train``: checks its options, builds or resumes a :class:`~pushctl.rl.train.Trainer`,
and shows its progress with rich."""

from __future__ import annotations

from collections import deque
from pathlib import Path

from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.table import Table

from pushctl.errors import ConfigError
from pushctl.files.output_guard import hold, occupied
from pushctl.rl.presets import load_preset
from pushctl.rl.train import CHECKPOINT, CURVE, LAST_POLICY, POLICY, VALIDATION, Trainer
from pushctl.rl.train import Progress as TrainProgress

RECENT = 20
"""Episodes averaged for the progress line's recent errors."""
LOG_EVERY = 25
"""Episodes between the plain progress lines printed when the output is not a terminal
(a log file or a pipe, where a live display would show nothing until the end)."""


def prepare_trainer(
    preset: str | None,
    seed: int | None,
    out: Path | None,
    resume: bool,
    force: bool,
    trust_undigested: bool = False,
) -> Trainer:
    """A new or resumed trainer for the options; ConfigError (one line) for an unknown
    preset, a clash of --resume and --force, an occupied output directory, or a checkpoint
    that is missing, corrupt or made with another preset or seed. Nothing is written."""
    if resume and force:
        raise ConfigError("--resume and --force exclude each other: continue, or start over")
    if seed is not None and seed < 0:
        raise ConfigError(f"--seed must be an integer >= 0, got {seed}")
    name = preset or "quick"
    directory = out if out is not None else Path("runs") / f"{name}-seed{seed or 0}"
    if directory.exists() and not directory.is_dir():
        raise ConfigError(f"--out {directory} is a file; give a directory")
    hold("--out", directory, directory=True)  # one command at a time, until this one ends
    if resume:
        trainer = Trainer.resume(directory, trust=trust_undigested)
        saved = trainer.preset.name, trainer.seed
        if (preset is not None and preset != saved[0]) or (seed is not None and seed != saved[1]):
            raise ConfigError(
                f"checkpoint {directory / CHECKPOINT} is incompatible: it was made with preset "
                f"{saved[0]!r} and seed {saved[1]}; resume without --preset/--seed or with those"
            )
        return trainer
    chosen = load_preset(name)
    if occupied(directory) and not force:
        raise ConfigError(
            f"{directory} already holds a run; pass --resume to continue it "
            "or --force to start over"
        )
    if force:
        for stale in (CHECKPOINT, CURVE, POLICY, LAST_POLICY, VALIDATION):
            (directory / stale).unlink(missing_ok=True)
    return Trainer.start(chosen, seed or 0, directory)


def run_with_progress(trainer: Trainer, episodes: int, made_by: str, console: Console) -> None:
    """Train to ``episodes`` with a live progress display."""
    recent: deque[TrainProgress] = deque(maxlen=RECENT)
    columns = (
        TextColumn("[bold]episode"),
        MofNCompleteColumn(),
        BarColumn(),
        TextColumn("{task.fields[rates]}"),
        TextColumn("{task.fields[errors]}"),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
    )
    # not a terminal (a log, a pipe): no live bars, whose last frame would wrap mid-field
    with Progress(*columns, console=console, disable=not console.is_terminal) as progress:
        task = progress.add_task(
            "train", total=episodes, completed=trainer.next_episode, rates="", errors=""
        )

        def show(update: TrainProgress) -> None:
            recent.append(update)
            rates = f"{update.env_steps_per_s:,.0f} steps/s {update.updates_per_s:,.1f} upd/s"
            errors = _recent_errors(recent)
            progress.update(task, completed=update.episodes_done, rates=rates, errors=errors)
            done = update.episodes_done
            if not console.is_terminal and (done % LOG_EVERY == 0 or done == episodes):
                console.print(
                    f"episode {done}/{episodes}  {update.elapsed:,.0f} s  {rates}  {errors}",
                    highlight=False,
                    soft_wrap=True,
                )

        trainer.run(episodes, on_episode=show, made_by=made_by)


def _recent_errors(recent: deque[TrainProgress]) -> str:
    """Mean force and torque errors of the recent episodes, RL (with exploration) and PD."""

    def mean(kind: str, name: str) -> float:
        values = [getattr(u.record, kind)[name] for u in recent if getattr(u.record, kind)]
        return sum(values) / len(values) if values else float("nan")

    return (
        f"|F| rl {1e3 * mean('rl', 'force_error'):.2f} pd {1e3 * mean('pd', 'force_error'):.2f} mN"
        f"  |τ| rl {1e3 * mean('rl', 'torque_error'):.3f} pd {1e3 * mean('pd', 'torque_error'):.3f}"
        " mN·m"
    )


def policy_line(run: Path) -> str:
    """``policy RUN/policy.pt: what it holds`` (:mod:`pushctl.cli.policy_kind`)."""
    from pushctl.cli.policy_kind import describe_policy, read_validation
    from pushctl.rl.policy import load_policy

    path = Path(run) / POLICY
    return f"policy {path}: {describe_policy(load_policy(path), read_validation(path))}"


def summary_table(trainer: Trainer) -> Table:
    """Episodes, experience and the last episodes' errors, RL against PD-only."""
    curve = trainer.curve()
    table = Table(title=f"training run {trainer.out}")
    table.add_column("")
    table.add_column("value", justify="right")
    table.add_row("episodes", f"{trainer.next_episode}")
    table.add_row("env steps", f"{trainer.agent.env_steps:,}")
    table.add_row("gradient updates", f"{trainer.agent.n_updates:,}")
    last = curve.tail(100)
    for name, unit, scale in (
        ("force_n_error", "mN", 1e3),
        ("force_t_error", "mN", 1e3),
        ("torque_error", "mN·m", 1e3),
        ("translation_error_pct", "%", 1.0),
    ):
        rl, pd = last[f"rl_{name}"].mean(), last[f"pd_{name}"].mean()
        table.add_row(
            f"{name}, last {len(last)} episodes (RL with noise / PD)",
            f"{scale * rl:.4g} / {scale * pd:.4g} {unit}",
        )
    return table

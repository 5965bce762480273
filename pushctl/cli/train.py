"""``pushctl train``: train the residual policy (one seed, or several on Ray with
``--seeds``); its steps are in :mod:`pushctl.cli.train_steps` and :mod:`pushctl.cli.train_seeds`."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from pushctl.cli.common import (
    console,
    fail,
    fail_ray,
    fail_write,
    interrupted,
    invocation,
)
from pushctl.errors import PushctlError

app = typer.Typer()


@app.command()
def train(
    ctx: typer.Context,
    preset: Annotated[
        str | None, typer.Option(help="quick, paper, or a preset .toml file (default: quick)")
    ] = None,
    episodes: Annotated[
        int | None,
        typer.Option(help="episodes in all, counting resumed ones (default: the preset's)"),
    ] = None,
    seed: Annotated[int | None, typer.Option(help="seed of every random draw (default: 0)")] = None,
    out: Annotated[
        Path | None, typer.Option(help="run directory (default: runs/PRESET-seedS)")
    ] = None,
    resume: Annotated[bool, typer.Option("--resume", help="continue the run in --out")] = False,
    force: Annotated[bool, typer.Option("--force", help="start over in an occupied --out")] = False,
    seeds: Annotated[
        str | None,
        typer.Option(help="several seeds, e.g. 0,1,2 or 0-4: one Ray task each, --out/seed-K"),
    ] = None,
    address: Annotated[
        str | None, typer.Option(help="Ray cluster to join (default: RAY_ADDRESS, else local)")
    ] = None,
) -> None:
    """Train the residual policy (DDPG, eq. 17 reward) on randomised pushes; write the
    checkpoint, the training curves (Fig. 5) and the policy to the run directory."""
    if seeds is not None:
        return _train_seeds(ctx, preset, episodes, seed, out, resume, force, seeds, address)
    if address is not None:
        fail(PushctlError("--address needs --seeds (one run's collectors follow RAY_ADDRESS)"))
    from pushctl.cli.train_steps import prepare_trainer, run_with_progress, summary_table
    from pushctl.provenance import provenance_line
    from pushctl.rl.train import CURVE, POLICY

    try:
        trainer = prepare_trainer(preset, seed, out, resume, force)
        total = episodes if episodes is not None else trainer.preset.train.episodes
        if total < 1:
            raise PushctlError(f"--episodes must be an integer >= 1, got {total}")
    except PushctlError as error:
        fail(error)
    if trainer.finished(total):
        console.print(f"{trainer.out} already has {trainer.next_episode} episodes; nothing to do")
        return
    try:
        made_by = provenance_line(invocation(ctx), f"seed {trainer.seed} (training stream)")
        run_with_progress(trainer, total, made_by, console)
    except KeyboardInterrupt:
        interrupted(resume_advice(trainer.out))
    except (OSError, PushctlError) as error:
        fail_write(error)
    console.print(summary_table(trainer))
    console.print(f"wrote {trainer.out / CURVE} and {trainer.out / POLICY}")


def resume_advice(directory: Path) -> str:
    """What an interrupted run kept and how to continue it: ``--resume`` from its last
    checkpoint, or, stopped before its first one, the same command again (nothing kept)."""
    from pushctl.rl.train import CHECKPOINT

    if (directory / CHECKPOINT).is_file():
        return f"`pushctl train --resume --out {directory}` continues from the last checkpoint"
    return (
        f"stopped before the first checkpoint, nothing kept in {directory}; run the same "
        "command again to start over"
    )


def _train_seeds(ctx, preset, episodes, seed, out, resume, force, seeds, address) -> None:
    """``pushctl train --seeds``: :mod:`pushctl.cli.train_seeds`."""
    from pushctl.cli.train_seeds import prepare_seed_jobs, run_jobs_with_progress, seeds_table

    try:
        command = invocation(ctx)
        jobs = prepare_seed_jobs(preset, seeds, seed, out, episodes, resume, force, command)
        results = [r for r, _ in run_jobs_with_progress(jobs, address, console)]
    except PushctlError as error:
        fail(error)
    except KeyboardInterrupt:
        root = out if out is not None else f"runs/{preset or 'quick'}-seeds"
        interrupted(
            f"`pushctl train --seeds {seeds} --resume --out {root}` continues "
            "each seed from its last checkpoint (a seed with none starts over)"
        )
    except OSError as error:
        fail_write(error)
    except Exception as error:  # Ray's own failures: a killed Ray process, a lost node
        fail_ray(error)
    console.print(seeds_table(results))

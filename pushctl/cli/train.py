"""``pushctl train``: train the residual policy (one seed, in this process unless
``--workers`` asks for collector processes on Ray; or several seeds on Ray with
``--seeds``); its steps are in :mod:`pushctl.cli.train_steps` and
:mod:`pushctl.cli.train_seeds`."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from pushctl.cli.common import (
    Command,
    console,
    error_console,
    fail,
    fail_ray,
    fail_write,
    interrupted,
    invocation,
)
from pushctl.errors import PushctlError
from pushctl.ranges import check_range

app = typer.Typer()


@app.command(cls=Command)
def train(
    ctx: typer.Context,
    preset: Annotated[
        str | None,
        typer.Option(help="quick, paper, or a preset .toml file", show_default="quick"),
    ] = None,
    episodes: Annotated[
        int | None,
        typer.Option(
            help="episodes in all, counting resumed ones",
            show_default="the preset's; on --resume, the run's own",
        ),
    ] = None,
    seed: Annotated[
        int | None,
        typer.Option(help="the run's seed, which every random draw flows from", show_default="0"),
    ] = None,
    out: Annotated[
        Path | None,
        typer.Option(help="run directory", show_default="runs/PRESET-seedS, runs/PRESET-seeds"),
    ] = None,
    resume: Annotated[bool, typer.Option("--resume", help="continue the run in --out")] = False,
    force: Annotated[bool, typer.Option("--force", help="start over in an occupied --out")] = False,
    trust_undigested: Annotated[
        bool,
        typer.Option(
            "--trust-undigested",
            help="resume from a checkpoint without its digest (an edit to it goes unseen)",
        ),
    ] = False,
    seeds: Annotated[
        str | None,
        typer.Option(
            help="several runs' seeds, e.g. 0,1,2 or 0-4: one Ray task each, --out/seed-K"
        ),
    ] = None,
    address: Annotated[
        str | None,
        typer.Option(help="Ray cluster to join", show_default="RAY_ADDRESS, else a local one"),
    ] = None,
    algo: Annotated[
        str, typer.Option(help="ddpg, or sb3-sac: stable-baselines3's SAC on the same env")
    ] = "ddpg",
    workers: Annotated[
        int,
        typer.Option(
            help="one run's collector processes, 0-8, on Ray beside the learner; 0: every "
            "episode in this process, no Ray (the same bytes either way)"
        ),
    ] = 0,
) -> None:
    """Train the residual policy (DDPG, eq. 17 reward) on randomised pushes; write the
    checkpoint, the training curves (Fig. 5) and the policy to the run directory."""
    if algo not in ("ddpg", "sb3-sac"):
        fail(PushctlError(f"--algo must be ddpg or sb3-sac, got {algo!r}"))
    from pushctl.cli.names import check_train_options

    try:  # every path (one run, several seeds, sb3-sac), before the core is imported
        if episodes is not None:
            check_range("training episodes", episodes, "--episodes: ")
        check_train_options(preset, seed, out, resume, force)
    except PushctlError as error:
        fail(error)
    if algo == "sb3-sac":
        return _train_sac(ctx, preset, episodes, seed, out, resume, force, seeds)
    if seeds is not None:
        if workers:
            fail(
                PushctlError("--workers is for one seed's run; --seeds share the cores as Ray says")
            )
        return _train_seeds(ctx, preset, episodes, seed, out, resume, force, seeds, address)
    if address is not None:
        fail(PushctlError("--address needs --seeds (one run's collectors follow RAY_ADDRESS)"))
    if not 0 <= workers <= 8:
        fail(PushctlError(f"--workers must be an integer in 0..8, got {workers}"))
    from pushctl.cli.train_steps import (
        policy_line,
        prepare_trainer,
        run_with_progress,
        summary_table,
    )
    from pushctl.cli.warm import note_if_cold
    from pushctl.files.provenance import provenance_line
    from pushctl.rl.train import CURVE, POLICY

    try:
        trainer = prepare_trainer(preset, seed, out, resume, force, trust_undigested)
        trainer.collectors = workers  # no result depends on it (pushctl.rl.train)
        total = trainer.target(episodes)  # a resumed run: its own target unless asked
        check_range("training episodes", total, "--episodes: ")
    except PushctlError as error:
        fail(error)
    if trainer.finished(total):
        console.print(f"{trainer.out} already has {trainer.next_episode} episodes; nothing to do")
        return
    try:
        made_by = provenance_line(invocation(ctx), f"seed {trainer.seed} (training stream)")
        note_if_cold(error_console)
        run_with_progress(trainer, total, made_by, console)
    except KeyboardInterrupt:
        interrupted(resume_advice(trainer.out, total))
    except (OSError, PushctlError) as error:
        fail_write(error)
    console.print(summary_table(trainer))
    console.print(f"wrote {trainer.out / CURVE} and {trainer.out / POLICY}")
    try:
        console.print(policy_line(trainer.out), soft_wrap=True, highlight=False, markup=False)
    except PushctlError as error:
        fail(error)


def resume_advice(directory: Path, episodes: int) -> str:
    """What an interrupted run kept and how to continue it: ``--resume`` from its last
    checkpoint to the ``episodes`` it was asked for, or, stopped before its first one, the
    same command again (nothing kept)."""
    import shlex

    from pushctl.rl.train import CHECKPOINT

    if (directory / CHECKPOINT).is_file():
        return (
            f"`pushctl train --resume --episodes {episodes} --out {shlex.quote(str(directory))}` "
            "continues from the last checkpoint"
        )
    return (
        f"stopped before the first checkpoint, nothing kept in {directory}; run the same "
        "command again to start over"
    )


def _train_seeds(ctx, preset, episodes, seed, out, resume, force, seeds, address) -> None:
    """``pushctl train --seeds``: :mod:`pushctl.cli.train_seeds`."""
    from pushctl.cli.train_seeds import prepare_seed_jobs, run_jobs_with_progress, seeds_table
    from pushctl.cli.train_steps import policy_line

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
    try:
        for result in results:
            console.print(policy_line(result.out), soft_wrap=True, highlight=False, markup=False)
    except PushctlError as error:
        fail(error)


def _train_sac(ctx, preset, episodes, seed, out, resume, force, seeds) -> None:
    """``pushctl train --algo sb3-sac``: :func:`pushctl.rl.sb3.train_sac` (one seed, no
    resume)."""
    from pushctl.files.output_guard import hold, occupied
    from pushctl.files.provenance import provenance_line
    from pushctl.rl.presets import load_preset
    from pushctl.rl.sb3 import MODEL, train_sac

    try:
        if resume or seeds is not None:
            raise PushctlError("--algo sb3-sac trains one seed from the start: no --resume/--seeds")
        if episodes is not None:
            check_range("training episodes", episodes, "--episodes: ")
        if seed is not None and seed < 0:
            raise PushctlError(f"--seed must be an integer >= 0, got {seed}")
        name, chosen_seed = preset or "quick", seed or 0
        chosen = load_preset(name)
        directory = out if out is not None else Path("runs") / f"{name}-sac-seed{chosen_seed}"
        hold("--out", directory, directory=True)  # one command at a time, until this one ends
        if force:  # only what such a run writes; anything else still stops it
            for stale in (MODEL, "policy.pt", "policy_last.pt", "validation.csv"):
                (directory / stale).unlink(missing_ok=True)
        if occupied(directory):
            raise PushctlError(f"{directory} already holds a run; --force starts over")
        made_by = provenance_line(invocation(ctx), f"seed {chosen_seed} (training stream)")
        row = train_sac(chosen, chosen_seed, directory, made_by, episodes, log=console.print)
    except PushctlError as error:
        fail(error)
    except OSError as error:
        fail_write(error)
    verdict = "kept" if row["kept"] else "not kept: policy.pt is the law"
    console.print(
        f"sb3-sac against the law on {row['pushes']} validation pushes: translation "
        f"{row['translation_diff']:+.4f} [{row['translation_diff_low']:+.4f}, "
        f"{row['translation_diff_high']:+.4f}], angle {row['angle_diff']:+.4f} "
        f"[{row['angle_diff_low']:+.4f}, {row['angle_diff_high']:+.4f}] points; {verdict}"
    )
    console.print(f"wrote {directory}")

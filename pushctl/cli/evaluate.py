"""``pushctl evaluate``: paired trials of the controllers on held-out scenarios; its
steps are in :mod:`pushctl.cli.evaluate_steps`."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from pushctl.cli.common import (
    FORCE_HELP,
    PUSHER_DEFAULT,
    PUSHER_HELP,
    Command,
    console,
    controller_help,
    error_console,
    fail,
    fail_write,
    interrupted,
    invocation,
    renamed_option,
    take_renamed,
)
from pushctl.controllers import paper_controllers
from pushctl.errors import PushctlError
from pushctl.output_guard import refuse_occupied_dir

app = typer.Typer()
PAPER = ", ".join(paper_controllers())
"""What ``--controller all`` runs: the paper's comparison."""


@app.command(cls=Command)
def evaluate(
    ctx: typer.Context,
    object_name: Annotated[
        str, typer.Option("--object", help="cube, wedge, all, or a TOML object file")
    ] = "all",
    pusher: Annotated[
        Path | None,
        typer.Option(help=PUSHER_HELP, show_default=PUSHER_DEFAULT),
    ] = None,
    profile: Annotated[str, typer.Option(help="constant, trapezoid, chirp or all")] = "all",
    trials: Annotated[int, typer.Option(help="trials per object × profile")] = 50,
    controller: Annotated[
        str,
        typer.Option(help=controller_help(f"all (the paper's: {PAPER}), or several: pd,feedback")),
    ] = "all",
    plant: Annotated[
        str,
        typer.Option(
            help="sim, proxy (the reality proxy), mujoco (MuJoCo, docs/mujoco.md), "
            "both (sim and proxy) or all"
        ),
    ] = "both",
    policy: Annotated[
        list[Path] | None,
        typer.Option(
            metavar="<path>",
            help="residual policy; repeat for several training seeds, each adding its own "
            "rl rows (docs/several-seeds.md)",
            show_default="results/training/policy.pt, shipped",
        ),
    ] = None,
    scenario_block: Annotated[
        int, typer.Option(help="block S of scenarios: trial i pushes scenario S×100000 + i")
    ] = 0,
    stream: Annotated[
        str,
        typer.Option(
            help="evaluation (the held-out targets) or tuning (to look around without "
            "touching them: other pushers, shapes)"
        ),
    ] = "evaluation",
    workers: Annotated[int, typer.Option(help="processes running trials, 1-8")] = 1,
    out: Annotated[Path, typer.Option(help="output directory")] = Path("runs/evaluation"),
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
    seed: Annotated[int | None, renamed_option("--seed")] = None,
) -> None:
    """Paired trials, PD-only, feedback and RL-assisted (or any registered controller) on the
    same held-out targets and plants; write trials.csv (one row per trial and controller)
    and steps.csv (per-step means) to --out."""
    from pushctl.cli.evaluate_steps import (
        gains_provenance,
        policy_kinds,
        policy_provenance,
        prepare,
        run_with_progress,
        summary_table,
    )
    from pushctl.cli.warm import note_if_cold
    from pushctl.evaluation.evaluate import STEPS_FILE, TRIALS_FILE, write_evaluation
    from pushctl.provenance import provenance_line

    scenario_block = take_renamed(ctx, "--scenario-block", scenario_block, "--seed", seed)
    try:
        spec, trained, policy_path = prepare(
            object_name,
            profile,
            trials,
            controller,
            plant,
            policy,
            scenario_block,
            workers,
            out,
            pusher,
            stream,
        )
        refuse_occupied_dir("--out", out, force)
        first = spec.scenario_seed(0)
        extra = f"scenario seeds {first}-{first + spec.trials - 1} ({spec.stream} stream)"
        if trained is not None:
            extra += "; " + policy_provenance(trained, policy_path)
            for line in policy_kinds(trained, policy_path):
                console.print(line, soft_wrap=True, highlight=False, markup=False)
        extra += gains_provenance(spec.controllers)
        made_by = provenance_line(invocation(ctx), extra)
        note_if_cold(error_console)
        evaluation = run_with_progress(spec, trained, workers, console)
        write_evaluation(out, evaluation, made_by)
    except PushctlError as error:
        fail(error)
    except KeyboardInterrupt:
        interrupted("nothing written")
    except OSError as error:
        fail_write(error)
    console.print(summary_table(evaluation))
    console.print(f"wrote {out / TRIALS_FILE} and {out / STEPS_FILE}")

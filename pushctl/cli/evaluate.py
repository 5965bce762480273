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
    resume: Annotated[
        bool,
        typer.Option(
            "--resume", help="continue an interrupted evaluation in --out from its kept trials"
        ),
    ] = False,
    trust_undigested: Annotated[
        bool,
        typer.Option(
            "--trust-undigested",
            help="run a policy file without its digest (an edit to it goes unseen)",
        ),
    ] = False,
    seed: Annotated[int | None, renamed_option("--seed")] = None,
) -> None:
    """Paired trials, PD-only, feedback and RL-assisted (or any registered controller) on the
    same held-out targets and plants; write trials.csv (one row per trial and controller)
    and steps.csv (per-step means) to --out."""
    from pushctl.cli.names import check_evaluate_options

    scenario_block = take_renamed(ctx, "--scenario-block", scenario_block, "--seed", seed)
    try:  # before the core is imported: a typo costs no time
        check_evaluate_options(
            object_name, profile, trials, controller, plant, scenario_block, stream, workers, out
        )
    except PushctlError as error:
        fail(error)
    from pushctl.cli.evaluate_steps import (
        PARTIAL_FILE,
        Keeper,
        gains_provenance,
        open_out,
        policy_kinds,
        policy_provenance,
        prepare,
        read_kept,
        run_with_progress,
        summary_table,
    )
    from pushctl.cli.warm import note_if_cold
    from pushctl.evaluation.evaluate import STEPS_FILE, TRIALS_FILE, write_evaluation
    from pushctl.files.provenance import provenance_line

    keeper = None
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
            trust_undigested,
        )
        kept = open_out(out, force, resume)
        first = spec.scenario_seed(0)
        extra = f"scenario seeds {first}-{first + spec.trials - 1} ({spec.stream} stream)"
        if trained is not None:
            extra += "; " + policy_provenance(trained, policy_path)
            for line in policy_kinds(trained, policy_path):
                console.print(line, soft_wrap=True, highlight=False, markup=False)
        extra += gains_provenance(spec.controllers)
        # a resumed run's line is the interrupted one's: the same bytes as one run through
        made_by = provenance_line(invocation(ctx).replace(" --resume", ""), extra)
        start = None if kept is None else read_kept(kept, made_by, trust_undigested)
        keeper = Keeper(out / PARTIAL_FILE, made_by, len(spec.jobs()), start)
        note_if_cold(error_console)
        evaluation = run_with_progress(spec, trained, workers, console, start, keeper)
        write_evaluation(out, evaluation, made_by)
        (out / PARTIAL_FILE).unlink(missing_ok=True)
    except PushctlError as error:
        fail(error)
    except KeyboardInterrupt:
        interrupted(_kept_advice(keeper, out))
    except OSError as error:
        fail_write(error)
    console.print(summary_table(evaluation))
    console.print(f"wrote {out / TRIALS_FILE} and {out / STEPS_FILE}")


def _kept_advice(keeper, out: Path) -> str:  # noqa: ANN001 (imported late)
    """What a stopped evaluation kept (its trials so far, written once more now) and how to
    continue it."""
    try:
        done = keeper.save() if keeper is not None else 0
    except (OSError, PushctlError):
        done = 0
    if not done:
        return "nothing written"
    return (
        f"{done} of {keeper.jobs} trials kept in {out}; the same command with --resume "
        "continues from them"
    )

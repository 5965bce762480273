"""The ``pushctl`` command line. Each command parses, validates, calls the core, renders.

Commands: ``pushctl info``, ``plan``, ``simulate``, ``tune-pd``, ``tune-feedback``
(:mod:`pushctl.cli_tune_feedback`), ``train`` (:mod:`pushctl.cli_train`; ``--seeds``:
:mod:`pushctl.cli_seeds`), ``evaluate`` (:mod:`pushctl.cli_evaluate`), ``report``
(:mod:`pushctl.cli_report`) and ``sweep`` (:mod:`pushctl.cli_sweep`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console
from rich.table import Table

from pushctl.errors import PushctlError
from pushctl.output_guard import refuse_existing_files, refuse_occupied_dir

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Multi-point object pushing with a redundant arm: simulate, plan, train, evaluate.",
)
console = Console()
FORCE_HELP = "overwrite existing results in the output path"
error_console = Console(stderr=True, soft_wrap=True)


def _fail(error: PushctlError) -> None:
    """One line on stderr, exit code 2, no traceback."""
    error_console.print(f"error: {error}", markup=False, highlight=False)
    raise typer.Exit(code=2)


def _fail_write(error: OSError) -> None:
    """:func:`_fail` for a file that could not be written."""
    _fail(PushctlError(f"cannot write {error.filename}: {error.strerror}"))


@app.callback()
def _main() -> None:
    """pushctl: multi-point object pushing experiments."""


@app.command()
def info(
    object_name: Annotated[
        str, typer.Option("--object", help="cube, wedge, or a TOML object file")
    ] = "cube",
    arm: Annotated[str, typer.Option(help="kinova-gen2-7dof, kinova-j2s6s200 or panda")] = (
        "kinova-gen2-7dof"
    ),
) -> None:
    """Show the model of an object and an arm: mass properties, supports, ready pose."""
    from pushctl.arm import ArmConfig, load_arm
    from pushctl.config import PusherConfig
    from pushctl.objects import resolve_object

    try:
        spec = resolve_object(object_name)
        model = load_arm(ArmConfig(name=arm, pusher=PusherConfig(mass=spec.pusher_mass)))
    except PushctlError as error:
        _fail(error)
    table = Table(title=f"object {spec.name!r}", show_header=False)
    table.add_row("mass", f"{spec.mass:.4g} kg")
    table.add_row("I_z about the centre of mass", f"{spec.inertia_z:.4e} kg·m²")
    table.add_row("centre of mass height", f"{1e3 * spec.com_height:.2f} mm")
    table.add_row("centre of mass to pushed face", f"{1e3 * spec.face_offset:.2f} mm")
    for point, load in zip(np.asarray(spec.support_points), spec.support_loads, strict=True):
        table.add_row(
            "support point (x, y) / load",
            f"({1e3 * point[0] + 0.0:.1f}, {1e3 * point[1] + 0.0:.1f}) mm / {load:.4f} N",
        )
    table.add_row("pusher mass (Table II)", f"{spec.pusher_mass:.3g} kg")
    console.print(table)
    arm_table = Table(title=f"arm {model.name!r}", show_header=False)
    arm_table.add_row("joints (nq, nv)", f"{model.nq}, {model.nv}")
    arm_table.add_row("armature", ", ".join(f"{a:.4g}" for a in model.armature) + " kg·m²")
    arm_table.add_row("damping", ", ".join(f"{d:.4g}" for d in model.damping) + " N·m·s/rad")
    arm_table.add_row("ready q", ", ".join(f"{q:.4f}" for q in model.q_ready) + " rad")
    position = ", ".join(f"{x:.3f}" for x in model.ready_pusher_position)
    arm_table.add_row("ready pusher position", f"({position}) m")
    jacobian = model.pusher_jacobian(model.q_ready)
    mass = model.compute(model.q_ready, np.zeros(model.nv)).M
    arm_table.add_row("cond J (pusher, ready)", f"{np.linalg.cond(jacobian):.1f}")
    arm_table.add_row(
        "smallest eigenvalue of M (ready)", f"{np.linalg.eigvalsh(mass)[0]:.4f} kg·m²"
    )
    console.print(arm_table)


@app.command()
def plan(
    ctx: typer.Context,
    goal: Annotated[str, typer.Option(help="goal pose x,y,theta_deg [m, m, deg]")],
    object_name: Annotated[
        str, typer.Option("--object", help="cube, wedge, or a TOML object file")
    ] = "cube",
    profile: Annotated[str, typer.Option(help="constant, trapezoid or chirp")] = "constant",
    start: Annotated[
        str | None,
        typer.Option(help="start pose x,y,theta_deg; default: in front of the ready pose"),
    ] = None,
    duration: Annotated[float, typer.Option(help="push duration [s]")] = 20.0,
    dt: Annotated[float, typer.Option(help="control step [s]")] = 0.01,
    mu_contact: Annotated[float, typer.Option(help="prong-object friction μ_c")] = 0.4,
    mu_ground: Annotated[float, typer.Option(help="object-table friction μ_g")] = 0.3,
    arm: Annotated[str, typer.Option(help="kinova-gen2-7dof, kinova-j2s6s200 or panda")] = (
        "kinova-gen2-7dof"
    ),
    out: Annotated[Path | None, typer.Option(help="write the plan as CSV here")] = None,
    plot: Annotated[Path | None, typer.Option(help="save a figure (.png, .pdf, .svg)")] = None,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
) -> None:
    """Plan a push: ICR arc, angular profile, prong forces; check the arm can follow it."""
    from pushctl.arm import ArmConfig, load_arm
    from pushctl.cli_plan import PLOT_SUFFIXES, check_output, parse_pose, summary_table
    from pushctl.config import PusherConfig
    from pushctl.objects import resolve_object
    from pushctl.planning import ForceSettings, make_plan
    from pushctl.planning.profiles import make_profile
    from pushctl.provenance import provenance_line, write_csv

    try:
        check_output("--out", out, (".csv",))
        check_output("--plot", plot, PLOT_SUFFIXES)
        refuse_existing_files("--out/--plot", (out, plot), force)
        goal_pose = parse_pose("--goal", goal)
        start_pose = None if start is None else parse_pose("--start", start)
        timing = make_profile(profile)
        settings = ForceSettings(mu_contact=mu_contact, mu_ground=mu_ground)
        spec = resolve_object(object_name)
        model = load_arm(ArmConfig(name=arm, pusher=PusherConfig(mass=spec.pusher_mass)))
        result = make_plan(
            spec,
            goal_pose,
            start=start_pose,
            profile=timing,
            duration=duration,
            dt=dt,
            forces=settings,
            arm=model,
        )
        console.print(summary_table(result))
        result.raise_if_infeasible()
    except PushctlError as error:
        _fail(error)
    figure = None
    if plot is not None:
        from pushctl.report import plan_figure

        figure = plan_figure(result)
    try:
        if out is not None:
            write_csv(out, result.to_frame(), provenance_line(_invocation(ctx)))
            console.print(f"wrote {out}")
        if plot is not None and figure is not None:
            from pushctl.provenance import write_atomic

            write_atomic(plot, lambda tmp: figure.savefig(tmp, format=plot.suffix[1:], dpi=150))
            console.print(f"wrote {plot}")
    except OSError as error:
        _fail_write(error)


@app.command()
def simulate(
    ctx: typer.Context,
    object_name: Annotated[
        str, typer.Option("--object", help="cube, wedge, or a TOML object file")
    ] = "cube",
    profile: Annotated[str, typer.Option(help="constant, trapezoid or chirp")] = "constant",
    goal: Annotated[
        str | None, typer.Option(help="goal pose x,y,theta_deg [m, m, deg]; or use --seed")
    ] = None,
    seed: Annotated[
        int | None,
        typer.Option(help="draw the goal (and with --randomize the plant) from this seed"),
    ] = None,
    controller: Annotated[
        str, typer.Option(help="pd (PD-only), feedback (PD + PI on the pose) or rl (PD + policy)")
    ] = "pd",
    policy: Annotated[
        Path | None,
        typer.Option(help="rl's policy (default: the shipped results/training/policy.pt)"),
    ] = None,
    randomize: Annotated[
        bool,
        typer.Option(
            "--randomize", help="draw μ_g, μ_c, masses and plant unknowns from the plant's ranges"
        ),
    ] = False,
    plant: Annotated[
        str, typer.Option(help="sim, proxy (the reality proxy) or mujoco (docs/mujoco.md)")
    ] = "sim",
    mu_ground: Annotated[float | None, typer.Option(help="plant's object-table μ_g")] = None,
    mu_contact: Annotated[float | None, typer.Option(help="plant's prong-object μ_c")] = None,
    object_mass: Annotated[float | None, typer.Option(help="plant's object mass [kg]")] = None,
    duration: Annotated[float, typer.Option(help="push duration [s]")] = 20.0,
    gains: Annotated[
        Path | None, typer.Option(help="PD gains file; default experiments/pd_gains.toml")
    ] = None,
    arm: Annotated[str, typer.Option(help="kinova-gen2-7dof, kinova-j2s6s200 or panda")] = (
        "kinova-gen2-7dof"
    ),
    out: Annotated[Path | None, typer.Option(help="write the trace as CSV here")] = None,
    plot: Annotated[Path | None, typer.Option(help="save a figure (.png, .pdf, .svg)")] = None,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
) -> None:
    """Run one push with a controller: approach, push, metrics, trace and figure."""
    from pushctl.cli_plan import PLOT_SUFFIXES, check_output, parse_pose
    from pushctl.cli_simulate import (
        check_controller,
        check_plant,
        metrics_table,
        push,
        scenario_table,
        simulate_scenario,
    )
    from pushctl.control import load_gains
    from pushctl.episode.metrics import compute_metrics

    try:
        check_output("--out", out, (".csv",))
        check_output("--plot", plot, PLOT_SUFFIXES)
        refuse_existing_files("--out/--plot", (out, plot), force)
        check_controller(controller)
        check_plant(plant)
        goal_pose = None if goal is None else parse_pose("--goal", goal)
        pd_gains = load_gains(gains)
        overrides = {"mu_ground": mu_ground, "mu_contact": mu_contact, "object_mass": object_mass}
        scenario, redrawn = simulate_scenario(
            object_name, profile, goal_pose, seed, randomize, overrides, duration, arm, plant
        )
        trace, made = push(scenario, controller, pd_gains, policy, plant)
        console.print(scenario_table(scenario, made.trajectory.start, redrawn))
        metrics = compute_metrics(trace)
    except PushctlError as error:
        _fail(error)
    console.print(metrics_table(metrics))
    figure = None
    if plot is not None:
        from pushctl.report import trace_figure

        figure = trace_figure(trace)
    command = _invocation(ctx)
    extra = f"seed {seed}" if seed is not None else "no seed"
    _write_outputs(command, out, trace.to_frame() if out else None, plot, figure, extra)


@app.command("tune-pd")
def tune_pd_command(
    ctx: typer.Context,
    seed: Annotated[int, typer.Option(help="seed of the tuning set (tuning stream)")] = 0,
    per_case: Annotated[int, typer.Option(help="scenarios per object × profile")] = 2,
    objects: Annotated[str, typer.Option(help="comma-separated objects")] = "cube,wedge",
    profiles: Annotated[str, typer.Option(help="comma-separated profiles")] = (
        "constant,trapezoid,chirp"
    ),
    duration: Annotated[float, typer.Option(help="push duration [s]")] = 20.0,
    max_rounds: Annotated[int, typer.Option(help="refinement sweeps after the grid")] = 6,
    out: Annotated[
        Path | None, typer.Option(help="gains file to write; default experiments/pd_gains.toml")
    ] = None,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
) -> None:
    """Search the PD gains on a tuning set disjoint from evaluation; write the gains file."""
    from pushctl.cli_plan import check_output
    from pushctl.cli_simulate import check_profile, tuning_record
    from pushctl.control.gains import DEFAULT_GAINS_FILE
    from pushctl.evaluation.tune_pd import best_candidate, tune_pd, tuning_scenarios
    from pushctl.objects import resolve_object

    target = out if out is not None else DEFAULT_GAINS_FILE
    try:
        check_output("--out", target, (".toml",))
        refuse_existing_files("--out", (target,), force)
        object_names = tuple(name for name in objects.split(",") if name)
        profile_names = tuple(name for name in profiles.split(",") if name)
        for name in object_names:
            resolve_object(name)
        for name in profile_names:
            check_profile(name)
        if not object_names or not profile_names:
            raise PushctlError("--objects and --profiles each need at least one name")
        if per_case < 1:
            raise PushctlError(f"--per-case must be an integer >= 1, got {per_case}")
        if max_rounds < 0:
            raise PushctlError(f"--max-rounds must be >= 0, got {max_rounds}")
        with console.status("drawing the tuning set"):
            scenarios, redrawn = tuning_scenarios(
                seed, object_names, profile_names, per_case, duration
            )
        with console.status("grid search") as status:

            def report(candidate) -> None:
                g = candidate.gains
                status.update(
                    f"K_p {g.kp:.4g}, K_v {g.kv:.4g}, K_x {g.kx_linear:.4g}: "
                    f"{candidate.objective:.4f} % tracking error"
                )

            candidates = tune_pd(scenarios, max_rounds=max_rounds, progress=report)
    except PushctlError as error:
        _fail(error)
    best = best_candidate(candidates)
    table = Table(title=f"PD gain search: {len(scenarios)} tuning episodes, best 10")
    for column in ("K_p", "K_v", "K_x", "translation %", "angle %", "objective"):
        table.add_column(column, justify="right")
    for candidate in sorted(candidates, key=lambda c: c.objective)[:10]:
        g = candidate.gains
        table.add_row(
            f"{g.kp:.4g}",
            f"{g.kv:.4g}",
            f"{g.kx_linear:.4g}",
            f"{candidate.translation_error_pct:.4f}",
            f"{candidate.angle_error_pct:.4f}",
            f"{candidate.objective:.4f}",
        )
    console.print(table)
    text = tuning_record(
        best, candidates, seed, per_case, object_names, profile_names, duration, redrawn,
        _invocation(ctx),
    )  # fmt: skip
    _write_text(target, text)


@app.command("tune-feedback")
def tune_feedback_command(
    ctx: typer.Context,
    seed: Annotated[int, typer.Option(help="first scenario seed of the tuning set")] = 0,
    per_case: Annotated[int, typer.Option(help="scenarios per object × profile")] = 2,
    duration: Annotated[float, typer.Option(help="push duration [s]")] = 20.0,
    out: Annotated[
        Path | None,
        typer.Option(help="gains file to write; default experiments/feedback_gains.toml"),
    ] = None,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
) -> None:
    """Search the feedback baseline's gains (k, k_i) on the tuning stream; write the file."""
    from pushctl.cli_plan import check_output
    from pushctl.cli_tune_feedback import run_search
    from pushctl.control.feedback import DEFAULT_FEEDBACK_FILE

    try:
        check_output("--out", out, (".toml",))
        refuse_existing_files("--out", (out if out is not None else DEFAULT_FEEDBACK_FILE,), force)
        target, text, table = run_search(seed, per_case, duration, out, _invocation(ctx), console)
    except PushctlError as error:
        _fail(error)
    console.print(table)
    _write_text(target, text)


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
        _fail(PushctlError("--address needs --seeds (one run's collectors follow RAY_ADDRESS)"))
    from pushctl.cli_train import prepare_trainer, run_with_progress, summary_table
    from pushctl.provenance import provenance_line
    from pushctl.rl.train import CURVE, POLICY

    try:
        trainer = prepare_trainer(preset, seed, out, resume, force)
        total = episodes if episodes is not None else trainer.preset.train.episodes
        if total < 1:
            raise PushctlError(f"--episodes must be an integer >= 1, got {total}")
    except PushctlError as error:
        _fail(error)
    if trainer.next_episode >= total:
        console.print(f"{trainer.out} already has {trainer.next_episode} episodes; nothing to do")
        return
    try:
        made_by = provenance_line(_invocation(ctx), f"seed {trainer.seed} (training stream)")
        run_with_progress(trainer, total, made_by, console)
    except KeyboardInterrupt:
        error_console.print(
            f"interrupted: `pushctl train --resume --out {trainer.out}` continues "
            "from the last checkpoint"
        )
        raise typer.Exit(code=130) from None
    except OSError as error:
        _fail_write(error)
    console.print(summary_table(trainer))
    console.print(f"wrote {trainer.out / CURVE} and {trainer.out / POLICY}")


def _train_seeds(ctx, preset, episodes, seed, out, resume, force, seeds, address) -> None:
    """``pushctl train --seeds``: :mod:`pushctl.cli_seeds`."""
    from pushctl.cli_seeds import prepare_seed_jobs, run_jobs_with_progress, seeds_table

    try:
        command = _invocation(ctx)
        jobs = prepare_seed_jobs(preset, seeds, seed, out, episodes, resume, force, command)
        results = [r for r, _ in run_jobs_with_progress(jobs, address, console)]
    except PushctlError as error:
        _fail(error)
    except KeyboardInterrupt:
        root = out if out is not None else f"runs/{preset or 'quick'}-seeds"
        error_console.print(
            f"interrupted: `pushctl train --seeds {seeds} --resume --out {root}` continues "
            "each seed from its last checkpoint"
        )
        raise typer.Exit(code=130) from None
    except OSError as error:
        _fail_write(error)
    console.print(seeds_table(results))


@app.command()
def evaluate(
    ctx: typer.Context,
    object_name: Annotated[str, typer.Option("--object", help="cube, wedge or all")] = "all",
    profile: Annotated[str, typer.Option(help="constant, trapezoid, chirp or all")] = "all",
    trials: Annotated[int, typer.Option(help="trials per object × profile")] = 50,
    controller: Annotated[
        str, typer.Option(help="pd (PD-only), feedback (PD + PI on the pose), rl or all")
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
            help="residual policy (default: the shipped results/training/policy.pt); repeat "
            "for several training seeds, each adding its own rl rows (docs/several-seeds.md)"
        ),
    ] = None,
    seed: Annotated[
        int, typer.Option(help="evaluation seed: trial i pushes scenario S×100000 + i")
    ] = 0,
    workers: Annotated[int, typer.Option(help="processes running trials, 1-8")] = 1,
    out: Annotated[Path, typer.Option(help="output directory")] = Path("results/evaluation"),
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
) -> None:
    """Paired trials, PD-only, feedback and RL-assisted on the same held-out targets and
    plants; write trials.csv (one row per trial and controller) and steps.csv (per-step
    means) to --out."""
    from pushctl.cli_evaluate import (
        policy_provenance,
        prepare,
        run_with_progress,
        summary_table,
    )
    from pushctl.evaluation.evaluate import STEPS_FILE, TRIALS_FILE, write_evaluation
    from pushctl.provenance import provenance_line

    try:
        spec, trained, policy_path = prepare(
            object_name, profile, trials, controller, plant, policy, seed, workers, out
        )
        refuse_occupied_dir("--out", out, force)
        first = spec.scenario_seed(0)
        extra = f"scenario seeds {first}-{first + spec.trials - 1} (evaluation stream)"
        if trained is not None:
            extra += "; " + policy_provenance(trained, policy_path)
        if "feedback" in spec.controllers:
            from pushctl.control.feedback import DEFAULT_FEEDBACK_FILE, load_feedback_gains

            law = load_feedback_gains()
            extra += (
                f"; feedback k {law.k:g} /s, k_i {law.k_i:g} /s² ({DEFAULT_FEEDBACK_FILE.name})"
            )
        # --workers changes no byte of the results, so the files do not record it either
        command = _invocation(ctx).replace(f" --workers {workers}", "")
        made_by = provenance_line(command, extra)
        evaluation = run_with_progress(spec, trained, workers, console)
        write_evaluation(out, evaluation, made_by)
    except PushctlError as error:
        _fail(error)
    except KeyboardInterrupt:
        error_console.print("interrupted: nothing written")
        raise typer.Exit(code=130) from None
    except OSError as error:
        _fail_write(error)
    console.print(summary_table(evaluation))
    console.print(f"wrote {out / TRIALS_FILE} and {out / STEPS_FILE}")


@app.command()
def report(
    ctx: typer.Context,
    in_dir: Annotated[
        Path,
        typer.Option(
            "--in", help="results directory: evaluation/{trials,steps}.csv, training/curve.csv"
        ),
    ] = Path("results"),
    out: Annotated[Path, typer.Option(help="directory for the tables and figures")] = Path(
        "results"
    ),
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False,
) -> None:
    """Tables III and IV (CSV and Markdown, beside the paper's values) and Figs. 5, 6 and 8
    from the evaluation and training CSVs."""
    from pushctl.cli_report import (
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
            made = make_report(in_dir, _invocation(ctx))
        written = write_report(made, out)
    except PushctlError as error:
        _fail(error)
    except OSError as error:
        _fail_write(error)
    console.print(counts_table(made))
    for path in written:
        console.print(f"wrote {path}")


def _write_text(path: Path, text: str) -> None:
    from pushctl.provenance import write_atomic

    def write(tmp: Path) -> None:
        tmp.write_text(text)

    try:
        write_atomic(path, write)
    except OSError as error:
        _fail_write(error)
    console.print(f"wrote {path}")


def _write_outputs(
    command: str, out: Path | None, frame, plot: Path | None, figure, extra: str
) -> None:
    """The figure, then the CSV (under its provenance line), each written atomically; the
    CSV's temporary file is renamed only once the figure is in place, so a failure leaves
    either both new files or no new CSV."""
    from pushctl.provenance import provenance_line, write_atomic, write_csv

    def save_figure() -> None:
        if plot is not None and figure is not None:
            write_atomic(plot, lambda tmp: figure.savefig(tmp, format=plot.suffix[1:], dpi=150))
            console.print(f"wrote {plot}")

    try:
        if out is not None and frame is not None:
            write_csv(out, frame, provenance_line(command, extra), before_rename=save_figure)
            console.print(f"wrote {out}")
        else:
            save_figure()
    except OSError as error:
        _fail_write(error)


def _invocation(context: typer.Context) -> str:
    """The running command with every option's effective value (defaults included, unset
    options left out), for provenance lines: ``pushctl simulate --object cube …``."""
    import shlex

    parts = ["pushctl", context.info_name or ""]
    for param in context.command.params:
        value = context.params.get(param.name or "")
        # --force changes no byte of the results, so the files do not record it either
        if value is None or value is False or not param.opts or param.name == "force":
            continue
        if isinstance(value, (list, tuple)):  # a repeated option (evaluate's --policy)
            parts += [part for one in value for part in (param.opts[0], str(one))]
            continue
        parts += [param.opts[0]] if value is True else [param.opts[0], str(value)]
    return shlex.join(parts)


def _register_sweep() -> None:
    from pushctl.cli_sweep import sweep  # its own module: the command is long

    app.command()(sweep)


_register_sweep()


if __name__ == "__main__":
    app()

"""``pushctl evaluate``: checks its options, runs the paired trials with a progress display,
and prints the summary table."""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from rich import box
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

from pushctl.arm.pusher_file import resolve_pusher
from pushctl.cli.policy_kind import describe_policy, read_validation
from pushctl.controllers import controller_names, entries, paper_controllers
from pushctl.episode.ranges import DEFAULT_PLANTS, PLANTS
from pushctl.errors import ConfigError, PushctlError
from pushctl.evaluation.evaluate import (
    DEFAULT_POLICY,
    Evaluation,
    check_workers,
    evaluate,
    load_evaluation_policy,
    policy_seeds,
    summary,
)
from pushctl.evaluation.trials import TrialResult, TrialSpec
from pushctl.files.output_guard import hold, refuse_occupied_dir
from pushctl.objects import OBJECT_NAMES
from pushctl.planning import PROFILE_NAMES
from pushctl.rl.checkpoint import load_checked, save_checked
from pushctl.rl.policy import TrainedPolicy

LOG_LINES = 20
"""Plain progress lines printed over a run when the output is not a terminal (a log file or
a pipe, where a live display would show nothing until the end)."""

SUMMARY_COLUMNS = (
    ("translation_error_pct", "transl.\n%", 1.0),
    ("angle_error_pct", "angle\n%", 1.0),
    ("force_error", "force\nmN", 1e3),
    ("torque_error", "torque\nmN·m", 1e3),
    ("slip_fraction", "slip\n%", 100.0),
    ("contact_loss_fraction", "lost\n%", 100.0),
)
"""Summary columns: metric, heading, scale from the metric's unit (slip and lost: % of the
push steps with a prong slipping, with a prong out of contact)."""


def choose(
    option: str,
    value: str,
    names: tuple[str, ...],
    every: str,
    everything: tuple[str, ...] | None = None,
) -> tuple[str, ...]:
    """The names ``value`` selects: one of ``names``, several comma-separated (in the order
    given; ``pd,feedback``), or ``everything`` (default: all of ``names``) for ``every``."""
    if value == every:
        return names if everything is None else everything
    chosen = tuple(value.split(","))
    if not all(name in names for name in chosen):
        raise ConfigError(
            f"unknown {option} {value!r}; accepted: {', '.join(names)} or {every} "
            "(or several, comma-separated)"
        )
    return chosen


def choose_plants(value: str) -> tuple[str, ...]:
    """The plants ``--plant`` selects: one of PLANTS, ``both`` (sim and proxy) or ``all``."""
    if value == "both":
        return DEFAULT_PLANTS
    if value == "all":
        return PLANTS
    if value not in PLANTS:
        raise ConfigError(f"unknown --plant {value!r}; accepted: {', '.join(PLANTS)}, both or all")
    return (value,)


def prepare(
    object_name: str,
    profile: str,
    trials: int,
    controller: str,
    plant: str,
    policy: Path | list[Path] | None,
    seed: int,
    workers: int,
    out: Path,
    pusher: Path | None = None,
    stream: str = "evaluation",
    trust_undigested: bool = False,
) -> tuple[TrialSpec, TrainedPolicy | list[TrainedPolicy] | None, Path | list[Path]]:
    """The trial spec, the policy (None when RL does not run: PD-only and feedback need no
    file) and its path, from the options; ConfigError (one line) for anything that cannot run
    or whose results could not be written. Nothing is written. Several ``--policy`` paths
    (a list of two or more) give a list of policies and of paths, checked by
    :func:`~pushctl.evaluation.evaluate.policy_seeds`."""
    if seed < 0:  # the spec's own check names the option's old spelling
        raise ConfigError(f"--scenario-block must be an integer >= 0, got {seed}")
    objects = (
        (object_name,)
        if object_name.lower().endswith(".toml")  # a TOML object file (TrialSpec reads it)
        else choose("--object", object_name, OBJECT_NAMES, "all")
    )
    spec = TrialSpec(
        objects=objects,
        profiles=choose("--profile", profile, PROFILE_NAMES, "all"),
        plants=choose_plants(plant),
        controllers=choose(
            "--controller", controller, controller_names(), "all", paper_controllers()
        ),
        trials=trials,
        seed=seed,
        pusher=resolve_pusher(pusher),
        stream=stream,
    )
    check_workers(workers)
    check_out(out)
    if isinstance(policy, list) and len(policy) > 1:
        return spec, *_prepare_several(spec, policy, trust_undigested)
    if isinstance(policy, list):
        policy = policy[0] if policy else None
    policy_path = policy if policy is not None else DEFAULT_POLICY
    loaded = (
        load_evaluation_policy(policy_path, trust_undigested=trust_undigested)
        if needs_policy(spec)
        else None
    )
    load_controller_gains(spec)
    if policy_path.is_absolute() and policy_path.is_relative_to(Path.cwd()):
        policy_path = policy_path.relative_to(Path.cwd())  # as the provenance line shows it
    return spec, loaded, policy_path


def needs_policy(spec: TrialSpec) -> bool:
    """Whether a controller of ``spec`` pushes with a policy file (``rl``)."""
    return any(entry.needs_policy for entry in entries(spec.controllers))


def load_controller_gains(spec: TrialSpec) -> dict[str, object]:
    """The gains of ``spec``'s controllers that have a file of their own (the feedback
    law's): a missing or bad file fails here, before any trial."""
    return {
        entry.name: entry.load_gains()
        for entry in entries(spec.controllers)
        if entry.load_gains is not None
    }


def gains_provenance(controllers: tuple[str, ...]) -> str:
    """The provenance fields naming the gains of ``controllers`` that have their own."""
    return "".join(
        f"; {entry.describe_gains(entry.load_gains())}"
        for entry in entries(controllers)
        if entry.load_gains is not None and entry.describe_gains is not None
    )


def _prepare_several(
    spec: TrialSpec, paths: list[Path], trust_undigested: bool
) -> tuple[list[TrainedPolicy] | None, list[Path]]:
    """Several ``--policy`` files: each loaded and checked (a file named twice, seeds or
    settings that cannot share an evaluation: ConfigError), paths as the provenance shows
    them."""
    shown = [_shown(path) for path in paths]
    if len({path.resolve() for path in paths}) < len(paths):
        raise ConfigError("--policy names one file twice; give each policy once")
    load_controller_gains(spec)
    if not needs_policy(spec):
        return None, shown
    loaded = [load_evaluation_policy(p, trust_undigested=trust_undigested) for p in paths]
    policy_seeds(loaded)
    return loaded, shown


def _shown(path: Path) -> Path:
    """``path`` relative to the working directory when it lies below it."""
    if path.is_absolute() and path.is_relative_to(Path.cwd()):
        return path.relative_to(Path.cwd())
    return path


def _pairs(
    trained: TrainedPolicy | list[TrainedPolicy], path: Path | list[Path]
) -> list[tuple[TrainedPolicy, Path]]:
    if isinstance(trained, list):
        assert isinstance(path, list)
        return list(zip(trained, path, strict=True))
    assert not isinstance(path, list)
    return [(trained, path)]


def policy_kinds(
    trained: TrainedPolicy | list[TrainedPolicy], path: Path | list[Path]
) -> list[str]:
    """``policy PATH: what it holds`` for each evaluated policy file
    (:func:`~pushctl.cli.policy_kind.describe_policy`, with its run's validation.csv)."""
    return [
        f"policy {where}: {describe_policy(one, read_validation(where))}"
        for one, where in _pairs(trained, path)
    ]


def policy_provenance(trained: TrainedPolicy | list[TrainedPolicy], path: Path | list[Path]) -> str:
    """The provenance field naming the evaluated policy file(s) and their own ``made by``."""
    pairs = _pairs(trained, path)
    named = [f"policy {where}, {one.made_by.removeprefix('# ')}" for one, where in pairs]
    return "; ".join(named)


def check_out(out: Path) -> None:
    """ConfigError unless ``out`` is, or can be made, a writable directory: checked before
    the trials run, not after."""
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out} is a file; give a directory")
    existing = out
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        raise ConfigError(f"--out {out}: {existing} is a file, not a directory")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise ConfigError(f"--out {out}: cannot write in {existing}")


PARTIAL_FILE = ".evaluation.partial.pt"
"""The trials an interrupted evaluation kept, in its output directory (``--resume``)."""
KEEP_EVERY = 10.0
"""Seconds between two writes of the kept trials (and one when the command is stopped)."""


def open_out(out: Path, force: bool, resume: bool) -> Path | None:
    """Hold ``out`` for this command and check it: the kept trials file to resume from
    (``resume``), else None once ``out`` is free to write (an interrupted evaluation there
    asks for --resume or --force). ConfigError (one line) otherwise."""
    if resume and force:
        raise ConfigError("--resume and --force exclude each other: continue, or start over")
    hold("--out", out, directory=True)
    kept = out / PARTIAL_FILE
    if resume:
        if not kept.is_file():
            raise ConfigError(f"{out} holds no interrupted evaluation; run without --resume")
        return kept
    if kept.is_file() and not force:
        raise ConfigError(
            f"{out} holds an interrupted evaluation; pass --resume to continue it or --force "
            "to start over"
        )
    kept.unlink(missing_ok=True)
    refuse_occupied_dir("--out", out, force)
    return None


def read_kept(kept: Path, made_by: str, trust_undigested: bool) -> dict[str, Any]:
    """The trials ``kept`` holds; ConfigError unless the same evaluation (``made_by``) kept
    them."""
    state = load_checked(kept, "kept trials file", trust_undigested=trust_undigested)
    if state.pop("made_by", None) != made_by:
        raise ConfigError(
            f"{kept} was kept by an evaluation with other options; resume with the options it "
            "started with, or pass --force to start over"
        )
    return state


class Keeper:
    """Writes what an evaluation gathered to its kept trials file every :data:`KEEP_EVERY`
    seconds, and once more when asked (:meth:`save`, when the command is stopped)."""

    def __init__(
        self, path: Path, made_by: str, jobs: int, start: dict[str, Any] | None = None
    ) -> None:
        self.path, self.made_by, self.jobs = path, made_by, jobs
        self.snapshot: Callable[[], dict[str, Any]] | None = None
        self.saved = time.monotonic()
        self.kept = 0 if start is None else int(start.get("done", 0))
        """Trials in the file now (a resumed run's, until it writes its own)."""

    def __call__(self, snapshot: Callable[[], dict[str, Any]]) -> None:
        self.snapshot = snapshot
        if time.monotonic() - self.saved >= KEEP_EVERY:
            try:
                self.save()
            except (OSError, PushctlError):  # a full disk: the trials go on, kept next time
                self.saved = time.monotonic()

    def save(self) -> int:
        """Write the trials gathered so far; the number kept (0: none, nothing written)."""
        if self.snapshot is not None:
            state = self.snapshot()
            save_checked(self.path, {"made_by": self.made_by, **state})
            self.saved, self.kept = time.monotonic(), int(state["done"])
        return self.kept


def run_with_progress(
    spec: TrialSpec,
    policy: TrainedPolicy | list[TrainedPolicy] | None,
    workers: int,
    console: Console,
    start: dict[str, Any] | None = None,
    keep: Keeper | None = None,
) -> Evaluation:
    """:func:`~pushctl.evaluation.evaluate.evaluate` with a live progress display (episodes
    done, the running mean force error of each controller, the ETA), from the trials
    ``start`` holds, handing its state to ``keep``."""
    extra = len(policy) - 1 if isinstance(policy, list) and needs_policy(spec) else 0
    per_job = len(spec.controllers) + extra  # each further policy pushes every trial
    total = spec.n_episodes // len(spec.controllers) * per_job
    force_sums = dict.fromkeys(spec.controllers, 0.0)
    by_policy = {entry.name for entry in entries(spec.controllers) if entry.needs_policy}
    columns = (
        TextColumn("[bold]episode"),
        MofNCompleteColumn(),
        BarColumn(),
        TextColumn("{task.fields[cell]}"),
        TextColumn("{task.fields[errors]}"),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
    )
    every = max(1, total // (per_job * LOG_LINES))
    # not a terminal (a log, a pipe): no live bar, whose last frame would wrap mid-field
    first = 0 if start is None else int(start.get("done", 0))
    with Progress(*columns, console=console, disable=not console.is_terminal) as progress:
        task = progress.add_task(
            "evaluate", total=total, completed=first * per_job, cell="", errors=""
        )

        def show(result: TrialResult, done: int, jobs: int) -> None:
            for row in result.rows:  # rl: the sum over policies, shown per policy below
                share = 1.0 / (1 + extra) if row["controller"] in by_policy else 1.0
                force_sums[row["controller"]] += share * row["force_error"]
            job = result.job
            cell = f"{job.object} {job.profile} {job.plant}"
            errors = "  ".join(
                f"|F| {name} {1e3 * total_force / (done - first):.2f} mN"
                for name, total_force in force_sums.items()
            )
            progress.update(task, completed=done * per_job, cell=cell, errors=errors)
            if not console.is_terminal and (done % every == 0 or done == jobs):
                elapsed = progress.tasks[0].elapsed or 0.0
                console.print(
                    f"episode {done * per_job}/{total}  {elapsed:,.0f} s  {cell}  {errors}",
                    highlight=False,
                    soft_wrap=True,
                )

        return evaluate(spec, policy, workers=workers, on_trial=show, start=start, keep=keep)


def summary_table(evaluation: Evaluation) -> Table:
    """Per object × profile × plant, one row per controller: the mean of each summary metric
    over the trials; the caption counts the goals redrawn."""
    spec = evaluation.spec
    means = summary(evaluation.trials)
    targets = len(spec.objects) * len(spec.profiles) * spec.trials
    table = Table(
        title=f"means over {spec.trials} trials per object × profile",
        caption=f"goals redrawn as infeasible: {evaluation.redrawn} of {targets} targets",
        box=box.SIMPLE_HEAD,
        show_edge=False,
        pad_edge=False,
        collapse_padding=True,
    )
    for heading in ("object", "profile", "plant", ""):
        table.add_column(heading)
    for _, heading, _ in SUMMARY_COLUMNS:
        table.add_column(heading, justify="right")
    for (obj, profile, plant), row in means.iterrows():
        for i, name in enumerate(spec.controllers):
            labels = (str(obj), str(profile), str(plant)) if i == 0 else ("", "", "")
            cells = [
                _number(scale * float(row[(metric, name)])) for metric, _, scale in SUMMARY_COLUMNS
            ]
            last = i == len(spec.controllers) - 1
            table.add_row(*labels, name.upper(), *cells, end_section=last)
    return table


def _number(value: float) -> str:
    """At most 6 characters: 3 significant digits from 0.01 up, a short exponent below."""
    if np.isnan(value):
        return "–"
    if value == 0.0 or abs(value) >= 0.01:
        return f"{value:.3g}" if abs(value) < 1e3 else f"{value:.0f}"
    return f"{value:.1e}".replace("e-0", "e-")

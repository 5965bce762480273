"""``make reproduce-tables``: train, evaluate, report (and bench), timed, with a manifest.

Run as ``python -m pushctl.cli.reproduce [--quick]``. Each step is the ``pushctl`` command a
user would type, run as a subprocess with its own output on the terminal:

1. ``pushctl train --preset paper --seeds 0,1,2 --out runs/paper``: one Ray task per seed
   into ``runs/paper/seed-K/`` (``--resume`` when a seed's directory holds a checkpoint, so
   an interrupted reproduction continues, and a finished run is not trained again);
2. each run's ``policy.pt``, ``policy_last.pt``, ``curve.csv`` and ``validation.csv`` copied
   to ``results/training/seed-K/``, and the first seed's also to ``results/training/`` (the
   shipped default policy of ``pushctl evaluate`` and ``simulate``, and Fig. 5's curve);
3. ``pushctl evaluate`` of every seed's ``results/training/seed-K/policy.pt`` in one run
   (``--policy`` repeated: PD-only and feedback once per trial, ``rl`` rows per seed; 50
   trials per object × profile, every controller, the plants sim, proxy and mujoco, 2
   workers) into ``results/evaluation/``; the report then gives each cell's mean over the
   seeds with its interval across them (docs/several-seeds.md); its ``steps.csv`` is then
   compressed to ``steps.csv.gz`` beside it (:func:`compress_steps`), the form ``results/``
   ships, so the shipped copy is always the one this run made;
4. ``pushctl report`` (tables, ``tables.md``, figures) into ``results/``;
5. ``python -m pushctl.bench`` into ``results/bench.csv``.

``--seeds 0`` (``make reproduce-tables SEEDS=0``): other training seeds, e.g. one.
``--quick``: the ``quick`` preset, 4 trials, no bench, everything under ``results-quick/``
and ``runs/quick`` (the committed ``results/`` stays as it is). The manifest
``provenance.md`` records each step's command, exit code and wall time, the git commit,
the seeds and the date; it is written atomically before the first step ("running"), after
each step, and at the end, also when a step fails (then naming it). Its budgets table sets
each stage's wall time (training per seed, evaluation, report, the whole run) beside issue
15's budgets on this machine and says which were met (:func:`budgets`); when the bench ran,
a line sets MuJoCo's step on this machine beside its time on the machine the budgets were
set on (:func:`_machine_speed_lines`).

Nothing it did not make is overwritten: the steps overwrite the results directory's files
(``--force``) only when that directory is absent, empty, or holds a manifest of an earlier
``make reproduce-tables`` (the shipped ``results/`` does, so a clean clone reproduces into
it). Anything else is refused with one line naming ``--force``. A training run directory
with a checkpoint is resumed; one without a checkpoint but with files is started over only
if the manifest names it as this reproduction's run (stopped before its first checkpoint).
"""

from __future__ import annotations

import argparse
import csv
import gzip
import shutil
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from datetime import datetime, timezone
from pathlib import Path

import pushctl
from pushctl.evaluation.columns import STEPS_FILE
from pushctl.machine import machine_description, usable_cores
from pushctl.provenance import git_commit, write_atomic

SEED = 0
"""The evaluation's seed."""
SEEDS = (0, 1, 2)
"""The training seeds (issue 16: three seeds of the paper preset)."""
MANIFEST = "provenance.md"
TRAINING_FILES = ("policy.pt", "policy_last.pt", "curve.csv", "validation.csv")
TRAINING_BUDGET = 20 * 60.0
"""Issue 15's budget for one training run of the ``paper`` preset on this machine [s]."""
EVALUATION_BUDGET = 3 * 60.0 / 1200
"""Issue 15's budget for the evaluation, 3 min for its 1200 episodes, per episode [s]."""
BUDGET_MACHINE_MJ_STEP = 10.4
"""MuJoCo's step of the arm pushing the cube on the machine issue 15's budgets were set on
(its table, 2026-11-23) [µs]: the manifest sets this run's own beside it."""
MJ_STEP_ROW = "world step arm+cube [mujoco mj_step alone]"
"""The bench row (:mod:`pushctl.bench.engines`) with MuJoCo's step alone [µs]."""
TOTAL_BUDGETS = {1: 30 * 60.0, 3: 60 * 60.0}
"""The whole ``make reproduce-tables`` by training seeds [s] (other counts: interpolated):
60 min with issue 16's three seeds, 30 min with one (the project's figures, which replaced
issue 15's 45 min for one seed)."""


@dataclass(frozen=True)
class Setup:
    """Where and how much: the training preset and run directory, the evaluation's trials
    per object × profile, the results directory, and whether to run the bench."""

    preset: str
    run: Path
    trials: int
    results: Path
    bench: bool
    force: bool = False
    seeds: tuple[int, ...] = SEEDS


FULL = Setup("paper", Path("runs/paper"), 50, Path("results"), bench=True)
QUICK = Setup("quick", Path("runs/quick"), 4, Path("results-quick"), bench=False)


@dataclass(frozen=True)
class StepRecord:
    """One step: its name, the command (as typed), exit code and wall time [s]."""

    name: str
    command: str
    returncode: int
    seconds: float


def steps(setup: Setup) -> list[tuple[str, list[str]]]:
    """The (name, argv) of each subprocess step; copying the training files is done in
    between by :func:`reproduce` itself. Every step but ``train`` overwrites (``--force``):
    :func:`check_owned` has made sure the results directory is this command's."""
    pushctl_cli = [sys.executable, "-m", "pushctl.cli"]
    resume = _train_mode(setup)
    seeds = ",".join(str(seed) for seed in setup.seeds)
    listed: list[tuple[str, list[str]]] = [
        (
            "train",
            [*pushctl_cli, "train", "--preset", setup.preset, "--seeds", seeds]
            + ["--out", str(setup.run), *resume],
        ),
        (
            "evaluate",
            [*pushctl_cli, "evaluate", "--trials", str(setup.trials), "--workers", "2"]
            + ["--plant", "all"]  # sim, proxy and mujoco (docs/mujoco.md)
            + ["--seed", str(SEED)]
            + [part for seed in setup.seeds for part in ("--policy", str(_policy(setup, seed)))]
            + ["--out", str(setup.results / "evaluation"), "--force"],
        ),
        (
            "report",
            [*pushctl_cli, "report", "--in", str(setup.results), "--out", str(setup.results)]
            + ["--force"],
        ),
    ]
    if setup.bench:
        bench = [sys.executable, "-m", "pushctl.bench", "--profile"]
        listed.append(("bench", [*bench, "--out", str(setup.results / "bench.csv"), "--force"]))
    return listed


def _policy(setup: Setup, seed: int) -> Path:
    """A training seed's policy as the evaluation reads it (copied by step 2)."""
    return setup.results / "training" / f"seed-{seed}" / "policy.pt"


def _train_mode(setup: Setup) -> list[str]:
    """``--resume`` when any seed's run has a checkpoint (seeds without one then start);
    ``--force`` for a run directory holding files but no checkpoint that this reproduction
    started (its manifest names it) or when the user passed ``--force``; nothing for a fresh
    run."""
    if any(checkpoint.is_file() for checkpoint in _checkpoints(setup)):
        return ["--resume"]
    occupied = setup.run.is_dir() and any(setup.run.iterdir())
    if occupied and (setup.force or _run_line(setup) in _own_manifest(setup)):
        return ["--force"]
    return []


def _run_line(setup: Setup) -> str:
    return f"- training run directory: `{setup.run}`"


def _own_manifest(setup: Setup) -> str:
    """The text of the results directory's manifest if an earlier ``make reproduce-tables``
    wrote it, else ''."""
    path = setup.results / MANIFEST
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError):
        return ""
    return text if text.startswith(f"# How `{setup.results}/` was made") else ""


def check_owned(setup: Setup) -> str | None:
    """Why this reproduction may not write into ``setup.results`` (one line naming
    ``--force``), or None when it may: the directory is absent or empty, holds a manifest
    of an earlier reproduction, or ``setup.force`` is set."""
    results = setup.results
    if setup.force or not results.exists():
        return None
    if not results.is_dir():
        return f"{results} is a file; give a directory"
    if not any(results.iterdir()) or _own_manifest(setup):
        return None
    return (
        f"{results} holds files that no earlier `make reproduce-tables` made (no {MANIFEST} "
        "of one); pass --force (make reproduce-tables FORCE=1) to overwrite them"
    )


def reproduce(setup: Setup) -> list[StepRecord]:
    """Run every step in order, stopping at the first that fails; write the manifest."""
    started = datetime.now(timezone.utc)
    records: list[StepRecord] = []
    listed = steps(setup)
    # The manifest first: it marks results/ and the run directory as this command's, so a
    # reproduction stopped anywhere resumes into them.
    write_manifest(setup, records, started, running=True)
    for name, argv in listed:
        clock = time.perf_counter()
        returncode = subprocess.run(argv, check=False).returncode
        records.append(StepRecord(name, _typed(argv), returncode, time.perf_counter() - clock))
        if returncode != 0:
            break
        if name == "train":
            copy_training(setup)
        if name == "evaluate":
            compress_steps(setup)
        write_manifest(setup, records, started, running=True)
    write_manifest(setup, records, started)
    return records


def seed_run(setup: Setup, seed: int) -> Path:
    """A training seed's run directory (:mod:`pushctl.distributed.seeds`' layout)."""
    return setup.run / f"seed-{seed}"


def _checkpoints(setup: Setup) -> list[Path]:
    return [seed_run(setup, seed) / "checkpoint.pt" for seed in setup.seeds]


def copy_training(setup: Setup) -> None:
    """Each seed's policy and curves into ``results/training/seed-K/``, the first seed's
    also into ``results/training/`` (each file copied atomically)."""
    training = setup.results / "training"
    targets = [(training / f"seed-{seed}", seed) for seed in setup.seeds]
    targets.append((training, setup.seeds[0]))  # the evaluated policy, Fig. 5's curve
    for target, seed in targets:
        target.mkdir(parents=True, exist_ok=True)
        for name in TRAINING_FILES:
            write_atomic(target / name, _copier(seed_run(setup, seed) / name))


def _copier(source: Path) -> Callable[[Path], object]:
    return lambda tmp: shutil.copyfile(source, tmp)


def compress_steps(setup: Setup) -> Path:
    """``results/evaluation/steps.csv`` gzip-compressed to ``steps.csv.gz`` beside it
    (atomically), the form the shipped ``results/`` keeps (11 MB → 3.5) and ``pushctl report``
    reads when ``steps.csv`` is absent (a clean clone). The same bytes for the same input: no
    name or time in the gzip header. Returns the compressed file's path.

    Written by the reproduction itself because a copy compressed by hand once fell behind:
    the ``results/`` of 1d7a74e shipped the ``steps.csv.gz`` of the run before it."""
    source = setup.results / "evaluation" / STEPS_FILE
    target = source.with_name(source.name + ".gz")
    write_atomic(target, lambda tmp: _gzip(source, tmp))
    return target


def _gzip(source: Path, target: Path) -> None:
    with source.open("rb") as raw, target.open("wb") as out:
        with gzip.GzipFile(filename="", mode="wb", fileobj=out, mtime=0) as packed:
            shutil.copyfileobj(raw, packed)


def _commands(setup: Setup) -> tuple[str, str]:
    """The ``make`` line and the module line that give ``setup``, for the manifest."""
    quick = setup.results == QUICK.results
    default = QUICK if quick else FULL
    seeds = ",".join(map(str, setup.seeds))
    flags = [
        ("QUICK=1", "--quick", quick),
        (f"PRESET={setup.preset}", f"--preset {setup.preset}", setup.preset != default.preset),
        (f"SEEDS={seeds}", f"--seeds {seeds}", setup.seeds != SEEDS),
        ("FORCE=1", "--force", setup.force),
    ]
    make = " ".join(["make reproduce-tables", *(m for m, _, on in flags if on)])
    module = " ".join(["python -m pushctl.cli.reproduce", *(a for _, a, on in flags if on)])
    return make, module


def write_manifest(
    setup: Setup, records: list[StepRecord], started: datetime, running: bool = False
) -> None:
    total = sum(r.seconds for r in records)
    failed = [r for r in records if r.returncode != 0]
    outcome = "failed at " + failed[0].name if failed else "all steps succeeded"
    make, module = _commands(setup)
    lines = [
        f"# How `{setup.results}/` was made",
        "",
        f"- command: `{make}` (`{module}`)",
        f"- pushctl {pushctl.__version__}, commit {git_commit()}",
        f"- seeds: training {','.join(map(str, setup.seeds))} (training stream; "
        f"`{setup.results}/training/seed-K/`), evaluation {SEED} (evaluation stream) of "
        f"every training seed's policy",
        f"- started {started.strftime('%Y-%m-%d %H:%M:%S')} UTC; wall time {_minutes(total)}",
        f"- machine: {machine_description()} (the bytes repeat on a machine of this kind: "
        "docs/reproducibility.md)",
        f"- outcome: {'running (or stopped)' if running else outcome}",
        _run_line(setup),
        "",
        "| step | command | exit | wall time |",
        "|---|---|---|---|",
        *(
            f"| {r.name} | `{r.command}` | {r.returncode} | {_minutes(r.seconds)} |"
            for r in records
        ),
        "",
        *_budget_lines(setup, records),
        "A `train` step that finds its run finished trains nothing and takes seconds; each",
        "seed's own training wall time (summed over every session that trained it, a stopped",
        "one up to its last episode) is in its run directory's `timing.json`, which the",
        "budgets above read.",
        "",
    ]
    setup.results.mkdir(parents=True, exist_ok=True)
    write_atomic(setup.results / MANIFEST, lambda tmp: tmp.write_text("\n".join(lines)))


@dataclass(frozen=True)
class Budget:
    """A stage's wall time [s] (None: not recorded) beside its budget [s] (None: the issue
    sets none), with what the budget is based on."""

    stage: str
    seconds: float | None
    budget: float | None
    basis: str

    @property
    def met(self) -> bool | None:
        if self.seconds is None or self.budget is None:
            return None
        return self.seconds <= self.budget


def budgets(setup: Setup, records: list[StepRecord]) -> list[Budget]:
    """Each stage's wall time beside issue 15's budget: training per seed (its own wall
    time, :data:`~pushctl.distributed.seeds.TIMING`; the seeds train side by side, which
    the basis says, as the budget is for one run alone), the evaluation (3 min per 1200
    episodes, scaled to the episodes it ran), the report, and the whole run (30 min with
    one training seed, 60 min with three). A run whose ``train`` step resumed has its
    whole-run time for this invocation only: the basis says so."""
    from pushctl.distributed.seeds import TIMING, read_timing  # Ray only when reporting

    took = {record.name: record.seconds for record in records}
    rows = []
    other = "" if setup.preset == "paper" else f"; this run: preset {setup.preset}"
    shared = ""
    if len(setup.seeds) > 1:  # the budget is for one run alone; say how these ran
        shared = f"; here {len(setup.seeds)} seeds at once on {usable_cores()} cores"
    for seed in setup.seeds:
        timing = read_timing(seed_run(setup, seed) / TIMING)
        seconds = None if timing is None else float(timing["seconds"])
        basis = f"the paper preset, one seed{other}{shared}"
        rows.append(Budget(f"training, seed {seed}", seconds, TRAINING_BUDGET, basis))
    episodes = _evaluated_episodes(setup.results / "evaluation" / "trials.csv")
    if episodes:
        budget, basis = EVALUATION_BUDGET * episodes, f"3 min per 1200 episodes; {episodes} run"
    else:
        budget, basis = None, "no trials.csv to count its episodes"
    rows.append(Budget("evaluation", took.get("evaluate"), budget, basis))
    rows.append(Budget("report", took.get("report"), None, "the issue sets none"))
    count = len(setup.seeds)
    total = TOTAL_BUDGETS.get(count)
    basis = f"{count} training seed{'s' if count > 1 else ''}"
    if total is None:  # between (or beyond) the two points, on their line
        total = TOTAL_BUDGETS[1] + (TOTAL_BUDGETS[3] - TOTAL_BUDGETS[1]) / 2 * (count - 1)
        basis += " (interpolated from 30 min for 1, 60 min for 3)"
    if any(r.name == "train" and "--resume" in r.command.split() for r in records):
        basis += "; this invocation only: its training resumed earlier sessions' runs"
    rows.append(Budget("whole run", sum(took.values()) if records else None, total, basis))
    return rows


def _evaluated_episodes(trials: Path) -> int:
    """Rows (one push each) of an evaluation's ``trials.csv``, 0 if there is none."""
    try:
        lines = trials.read_text().splitlines()
    except (OSError, UnicodeDecodeError):
        return 0
    rows = [line for line in lines if line and not line.startswith("#")]
    return max(len(rows) - 1, 0)  # the header


def _budget_lines(setup: Setup, records: list[StepRecord]) -> list[str]:
    rows = budgets(setup, records)
    verdicts = [row for row in rows if row.met is not None]
    missed = [row.stage for row in verdicts if not row.met]
    summary = f"{len(verdicts) - len(missed)} of {len(verdicts)} budgets met"
    summary += f"; missed: {', '.join(missed)}" if missed else ""
    word = {True: "yes", False: "**no**", None: "—"}
    return [
        "## Budgets (issue 15, this machine)",
        "",
        "| stage | wall time | budget | met | budget for |",
        "|---|---|---|---|---|",
        *(
            f"| {row.stage} | {_maybe_minutes(row.seconds)} | {_maybe_minutes(row.budget)} "
            f"| {word[row.met]} | {row.basis} |"
            for row in rows
        ),
        "",
        f"- {summary}",
        *_machine_speed_lines(setup, records),
        "",
    ]


def _machine_speed_lines(setup: Setup, records: list[StepRecord]) -> list[str]:
    """The machine's speed beside that of the machine the budgets were set on, as MuJoCo's
    step alone in this run's bench (none if the bench did not run and succeed here)."""
    if not any(r.name == "bench" and r.returncode == 0 for r in records):
        return []
    step = _bench_value(setup.results / "bench.csv", MJ_STEP_ROW)
    if step is None:
        return []
    return [
        f"- this machine's speed: MuJoCo's `mj_step` alone took {step:.1f} µs in this run's "
        f"bench, {BUDGET_MACHINE_MJ_STEP} µs on the machine the budgets were set on (issue "
        f"15, 2026-11-23): {step / BUDGET_MACHINE_MJ_STEP:.1f} times as long. The budgets "
        "above are not scaled by it; the machine's speed also swings between and within "
        "runs (docs/reproducibility-and-speed.md)."
    ]


def _bench_value(bench: Path, name: str) -> float | None:
    """The value of the row ``name`` of a bench CSV (``# made by:`` line, then name, value,
    unit, note), None if the file or the row is missing or unreadable."""
    try:
        lines = [line for line in bench.read_text().splitlines() if not line.startswith("#")]
    except (OSError, UnicodeDecodeError):
        return None
    for row in csv.DictReader(lines):
        if row.get("name") == name:
            try:
                return float(row["value"])
            except (TypeError, ValueError):
                return None
    return None


def _maybe_minutes(seconds: float | None) -> str:
    return "—" if seconds is None else _minutes(seconds)


def _typed(argv: list[str]) -> str:
    """``argv`` as a user types it: ``pushctl …`` / ``python -m …``."""
    if argv[1:3] == ["-m", "pushctl.cli"]:
        return " ".join(["pushctl", *argv[3:]])
    return " ".join(["python", *argv[1:]])


def _minutes(seconds: float) -> str:
    return f"{int(seconds // 60)} min {seconds % 60:04.1f} s"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m pushctl.cli.reproduce")
    parser.add_argument("--quick", action="store_true", help="quick preset, few trials")
    parser.add_argument(
        "--force", action="store_true", help="overwrite a results directory it did not make"
    )
    parser.add_argument("--seeds", default=None, help="training seeds, e.g. 0,1,2 or 0-2 or 0")
    parser.add_argument(
        "--preset", default=None, help="training preset (default: paper; quick with --quick)"
    )
    args = parser.parse_args(argv)
    setup = QUICK if args.quick else FULL
    if args.preset is not None:  # its own run directory: runs of two presets never mix
        setup = replace(setup, preset=args.preset, run=Path("runs") / Path(args.preset).stem)
    if args.force:
        setup = replace(setup, force=True)
    if args.seeds is not None:
        from pushctl.distributed.seeds import parse_seeds
        from pushctl.errors import ConfigError

        try:
            setup = replace(setup, seeds=parse_seeds(args.seeds))
        except ConfigError as error:
            print(f"reproduce-tables: {error}", file=sys.stderr)
            return 2
    refusal = check_owned(setup)
    if refusal is not None:
        print(f"reproduce-tables: {refusal}", file=sys.stderr)
        return 2
    records = reproduce(setup)
    failed = [r for r in records if r.returncode != 0]
    if failed:
        print(
            f"reproduce-tables: step {failed[0].name} failed: {failed[0].command}", file=sys.stderr
        )
        return failed[0].returncode
    total = _minutes(sum(r.seconds for r in records))
    print(f"reproduce-tables: done in {total}; see {setup.results / MANIFEST}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

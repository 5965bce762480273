"""The manifest ``results/provenance.md`` of ``pushctl reproduce`` (``make
reproduce-tables``): each step's command, exit code and wall time, the git commit, the seeds
and the date, and each stage's wall time with how it ran (the seeds side by side, the
pushes evaluated): it reports timings and grades none of them.

It is written atomically before the first step ("running"), after each step, and at the end,
also when a step fails (then naming it). When the bench ran, a line gives MuJoCo's step on
this machine, a measure of its speed (:func:`machine_speed_lines`).
"""

from __future__ import annotations

import csv
import re
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

from pushctl.files.provenance import git_commit, write_atomic
from pushctl.machine import machine_description, usable_cores
from pushctl.reproduce.plan import (
    FULL,
    MANIFEST,
    QUICK,
    SEED,
    Setup,
    StepRecord,
    run_line,
    seed_run,
)
from pushctl.version import VERSION

MJ_STEP_ROW = "world step arm+cube [mujoco mj_step alone]"
"""The bench row (``benchmarks/engines.py``) with MuJoCo's step alone [µs]."""


def commands(setup: Setup) -> tuple[str, str]:
    """The ``make`` line and the ``pushctl`` line that give ``setup``, for the manifest."""
    quick = setup.results == QUICK.results
    default = QUICK if quick else FULL
    seeds = ",".join(map(str, setup.seeds))
    flags = [
        ("QUICK=1", "--quick", quick),
        (f"PRESET={setup.preset}", f"--preset {setup.preset}", setup.preset != default.preset),
        (f"SEEDS={seeds}", f"--seeds {seeds}", setup.seeds != default.seeds),
        ("FORCE=1", "--force", setup.force),
    ]
    make = " ".join(["make reproduce-tables", *(m for m, _, on in flags if on)])
    command = " ".join(["pushctl reproduce", *(a for _, a, on in flags if on)])
    return make, command


def write_manifest(
    setup: Setup, records: list[StepRecord], started: datetime, running: bool = False
) -> None:
    total = sum(r.seconds for r in records)
    failed = [r for r in records if r.returncode != 0]
    outcome = "failed at " + failed[0].name if failed else "all steps succeeded"
    make, command = commands(setup)
    lines = [
        f"# How `{setup.results}/` was made",
        "",
        f"- command: `{make}` (`{command}`)",
        f"- pushctl {VERSION}, commit {git_commit()}",
        f"- seeds: training {','.join(map(str, setup.seeds))} (training stream; "
        f"`{setup.results}/training/seed-K/`), evaluation {SEED} (evaluation stream) of "
        f"every training seed's policy",
        f"- started {started.strftime('%Y-%m-%d %H:%M:%S')} UTC; wall time {minutes(total)}",
        f"- machine: {machine_description()} (the bytes repeat on a machine of this kind: "
        "docs/reproducibility.md)",
        f"- outcome: {'running (or stopped)' if running else outcome}",
        run_line(setup),
        *training_commit_lines(setup),
        "",
        "| step | command | exit | wall time |",
        "|---|---|---|---|",
        *(f"| {r.name} | `{r.command}` | {r.returncode} | {minutes(r.seconds)} |" for r in records),
        "",
        *timing_lines(setup, records),
        "A `train` step that finds its run finished trains nothing and takes seconds; each",
        "seed's own training wall time (summed over every session that trained it, a stopped",
        "one up to its last episode) is in its run directory's `timing.json`, which the",
        "timings above read.",
        "",
    ]
    setup.results.mkdir(parents=True, exist_ok=True)
    write_atomic(setup.results / MANIFEST, lambda tmp: tmp.write_text("\n".join(lines)))


def training_commit_lines(setup: Setup) -> list[str]:
    """The line naming the commit(s) each seed's training was made at, read from the first
    line of its ``curve.csv`` in ``results/training/seed-K/``: a resumed run that was
    already finished keeps the commit that trained it. No line before the curves exist."""
    commits: dict[str, list[int]] = {}
    for seed in setup.seeds:
        curve = setup.results / "training" / f"seed-{seed}" / "curve.csv"
        if not curve.exists():
            return []
        with curve.open() as lines:
            found = re.search(r"commit ([0-9a-f]{7,}(?:-dirty)?|unknown)", lines.readline())
        commits.setdefault(found.group(1) if found else "unknown", []).append(seed)
    made = "; ".join(
        f"commit {commit} (seeds {','.join(map(str, seeds))})" for commit, seeds in commits.items()
    )
    return [f"- training made at: {made}"]


@dataclass(frozen=True)
class Timing:
    """A stage's wall time [s] (None: not recorded) and how it ran."""

    stage: str
    seconds: float | None
    note: str


def timings(setup: Setup, records: list[StepRecord]) -> list[Timing]:
    """Each stage's wall time: training per seed (its own wall time,
    :data:`~pushctl.runs.seeds.TIMING`, with the seeds that trained side by side),
    the evaluation (with the pushes it ran), the report, and the whole run (this invocation
    only when its ``train`` step resumed earlier runs)."""
    from pushctl.runs.seeds import TIMING, read_timing  # Ray only when reporting

    took = {record.name: record.seconds for record in records}
    rows = []
    shared = ""
    if len(setup.seeds) > 1:
        shared = f"; {len(setup.seeds)} seeds at once on {usable_cores()} cores"
    for seed in setup.seeds:
        timing = read_timing(seed_run(setup, seed) / TIMING)
        seconds = None if timing is None else float(timing["seconds"])
        rows.append(Timing(f"training, seed {seed}", seconds, f"preset {setup.preset}{shared}"))
    episodes = _evaluated_episodes(setup.results / "evaluation" / "trials.csv")
    rows.append(
        Timing("evaluation", took.get("evaluate"), f"{episodes} pushes" if episodes else "")
    )
    rows.append(Timing("report", took.get("report"), ""))
    note = f"{len(setup.seeds)} training seed{'s' if len(setup.seeds) > 1 else ''}"
    if any(r.name == "train" and "--resume" in r.command.split() for r in records):
        note += "; this invocation only: its training resumed earlier runs"
    rows.append(Timing("whole run", sum(took.values()) if records else None, note))
    return rows


def _evaluated_episodes(trials: Path) -> int:
    """Rows (one push each) of an evaluation's ``trials.csv``, 0 if there is none."""
    try:
        lines = trials.read_text().splitlines()
    except (OSError, UnicodeDecodeError):
        return 0
    rows = [line for line in lines if line and not line.startswith("#")]
    return max(len(rows) - 1, 0)  # the header


def timing_lines(setup: Setup, records: list[StepRecord]) -> list[str]:
    return [
        "## Timings (this machine)",
        "",
        "| stage | wall time | how it ran |",
        "|---|---|---|",
        *(
            f"| {row.stage} | {_maybe_minutes(row.seconds)} | {row.note} |"
            for row in timings(setup, records)
        ),
        "",
        *machine_speed_lines(setup, records),
        "",
    ]


def machine_speed_lines(setup: Setup, records: list[StepRecord]) -> list[str]:
    """The machine's speed as MuJoCo's step alone in this run's bench (none if the bench
    did not run and succeed here)."""
    if not any(r.name == "bench" and r.returncode == 0 for r in records):
        return []
    step = bench_value(setup.results / "bench.csv", MJ_STEP_ROW)
    if step is None:
        return []
    return [
        f"- this machine's speed: MuJoCo's `mj_step` alone took {step:.1f} µs in this run's "
        "bench; the speed also swings between and within runs with the machine's load "
        "(docs/performance.md)."
    ]


def bench_value(bench: Path, name: str) -> float | None:
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
    return "—" if seconds is None else minutes(seconds)


def minutes(seconds: float) -> str:
    return f"{int(seconds // 60)} min {seconds % 60:04.1f} s"

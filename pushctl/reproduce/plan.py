"""What ``pushctl reproduce`` (``make reproduce-tables``) runs, and where: the setup, each
step's command line, and whether it may write into the results directory.

Each step is the ``pushctl`` command a user would type, run as a subprocess:

1. ``pushctl train --preset paper --seeds 0,1,2 --out runs/paper``: one Ray task per seed
   into ``runs/paper/seed-K/`` (``--resume`` when a seed's directory holds a checkpoint, so
   an interrupted reproduction continues, and a finished run is not trained again);
2. ``pushctl evaluate`` of every seed's ``results/training/seed-K/policy.pt`` in one run
   (``--policy`` repeated: PD-only and feedback once per trial, ``rl`` rows per seed; 50
   trials per object × profile, every controller, the plants sim, proxy and mujoco, 2
   workers) into ``results/evaluation/``;
3. ``pushctl report`` (tables, ``tables.md``, figures) into ``results/``;
4. the bench (``python -m benchmarks.suite``, run from the checkout's root) into
   ``results/bench.csv``, when the checkout's ``benchmarks/`` is there.

Between them :mod:`pushctl.reproduce.steps` copies the training files and compresses
the evaluation's steps. Nothing it did not make is overwritten (:func:`check_owned`).
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

from pushctl.files.output_guard import occupied

SEED = 0
"""The evaluation's seed."""
SEEDS = (0, 1, 2)
"""The training seeds: three seeds of the paper preset."""
MANIFEST = "provenance.md"
TRAINING_FILES = ("policy.pt", "policy_last.pt", "curve.csv", "validation.csv")
BENCH = Path("benchmarks") / "suite.py"
"""The bench's entry in the checkout (not installed): run when it is there."""


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


FULL = Setup(
    "experiments/train_paper_v1.toml",
    Path("runs/train_paper_v1"),
    50,
    Path("results"),
    bench=True,
    seeds=(0, 1, 2, 3, 4),
)
"""What the shipped ``results/`` are: the Push-v1 preset on five seeds (wall times:
docs/performance.md)."""
QUICK = Setup("quick", Path("runs/quick"), 4, Path("results-quick"), bench=False)


@dataclass(frozen=True)
class StepRecord:
    """One step: its name, the command (as typed), exit code and wall time [s]."""

    name: str
    command: str
    returncode: int
    seconds: float


def steps(setup: Setup) -> list[tuple[str, list[str]]]:
    """The (name, argv) of each subprocess step. Every step but ``train`` overwrites
    (``--force``): :func:`check_owned` has made sure the results directory is this
    command's."""
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
            + ["--scenario-block", str(SEED)]
            + [part for seed in setup.seeds for part in ("--policy", str(_policy(setup, seed)))]
            + ["--out", str(setup.results / "evaluation"), "--force"],
        ),
        (
            "report",
            [*pushctl_cli, "report", "--in", str(setup.results), "--out", str(setup.results)]
            + ["--force"],
        ),
    ]
    if setup.bench and BENCH.is_file():
        bench = [sys.executable, "-m", "benchmarks.suite", "--profile"]
        listed.append(("bench", [*bench, "--out", str(setup.results / "bench.csv"), "--force"]))
    return listed


def _policy(setup: Setup, seed: int) -> Path:
    """A training seed's policy as the evaluation reads it (copied after training)."""
    return setup.results / "training" / f"seed-{seed}" / "policy.pt"


def seed_run(setup: Setup, seed: int) -> Path:
    """A training seed's run directory (:mod:`pushctl.runs.seeds`' layout)."""
    return setup.run / f"seed-{seed}"


def _checkpoints(setup: Setup) -> list[Path]:
    return [seed_run(setup, seed) / "checkpoint.pt" for seed in setup.seeds]


def _train_mode(setup: Setup) -> list[str]:
    """``--resume`` when any seed's run has a checkpoint (seeds without one then start);
    ``--force`` for a run directory holding files but no checkpoint that this reproduction
    started (its manifest names it) or when the user passed ``--force``; nothing for a fresh
    run."""
    if any(checkpoint.is_file() for checkpoint in _checkpoints(setup)):
        return ["--resume"]
    occupied = setup.run.is_dir() and any(setup.run.iterdir())
    if occupied and (setup.force or run_line(setup) in own_manifest(setup)):
        return ["--force"]
    return []


def run_line(setup: Setup) -> str:
    """The manifest's line naming the training run directory."""
    return f"- training run directory: `{setup.run}`"


def own_manifest(setup: Setup) -> str:
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
    if not occupied(results) or own_manifest(setup):  # its own lock file is no result
        return None
    return (
        f"{results} holds files that no earlier `make reproduce-tables` made (no {MANIFEST} "
        "of one); pass --force (make reproduce-tables FORCE=1) to overwrite them"
    )

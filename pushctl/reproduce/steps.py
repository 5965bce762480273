"""The work of ``pushctl reproduce`` (``make reproduce-tables``): run each step of
:mod:`pushctl.reproduce.plan` in order, timed, with the manifest
(:mod:`pushctl.reproduce.manifest`) written before, between and after.

Between the steps it copies each training seed's ``policy.pt``, ``policy_last.pt``,
``curve.csv`` and ``validation.csv`` to ``results/training/seed-K/`` (the first seed's also
to ``results/training/``: the shipped default policy of ``pushctl evaluate`` and
``simulate``, and Fig. 5's curve), and compresses the evaluation's ``steps.csv`` to
``steps.csv.gz``, the form ``results/`` ships, so the shipped copy is always the one this run
made.
"""

from __future__ import annotations

import gzip
import shutil
import subprocess
import time
from collections.abc import Callable
from dataclasses import replace
from datetime import datetime, timezone
from pathlib import Path

from pushctl.evaluation.columns import STEPS_FILE
from pushctl.files.provenance import write_atomic
from pushctl.reproduce.manifest import write_manifest
from pushctl.reproduce.plan import (
    FULL,
    QUICK,
    TRAINING_FILES,
    Setup,
    StepRecord,
    seed_run,
    steps,
)


def choose_setup(quick: bool, force: bool, seeds: str | None, preset: str | None) -> Setup:
    """The setup the options ask for; ConfigError (one line) for bad seeds."""
    setup = QUICK if quick else FULL
    if preset is not None:  # its own run directory: runs of two presets never mix
        setup = replace(setup, preset=preset, run=Path("runs") / Path(preset).stem)
    if force:
        setup = replace(setup, force=True)
    if seeds is not None:
        from pushctl.runs.seeds import parse_seeds

        setup = replace(setup, seeds=parse_seeds(seeds))
    return setup


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
        records.append(StepRecord(name, typed(argv), returncode, time.perf_counter() - clock))
        if returncode != 0:
            break
        if name == "train":
            copy_training(setup)
        if name == "evaluate":
            compress_steps(setup)
        write_manifest(setup, records, started, running=True)
    write_manifest(setup, records, started)
    return records


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

    Written by the reproduction itself, so that the shipped copy cannot fall behind the run
    that made the other results."""
    source = setup.results / "evaluation" / STEPS_FILE
    target = source.with_name(source.name + ".gz")
    write_atomic(target, lambda tmp: _gzip(source, tmp))
    return target


def _gzip(source: Path, target: Path) -> None:
    with source.open("rb") as raw, target.open("wb") as out:
        with gzip.GzipFile(filename="", mode="wb", fileobj=out, mtime=0) as packed:
            shutil.copyfileobj(raw, packed)


def typed(argv: list[str]) -> str:
    """``argv`` as a user types it: ``pushctl …`` / ``python -m …``."""
    if argv[1:3] == ["-m", "pushctl.cli"]:
        return " ".join(["pushctl", *argv[3:]])
    return " ".join(["python", *argv[1:]])

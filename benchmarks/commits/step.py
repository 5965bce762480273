"""The world step, cold MLCP solves and environment steps of this tree against another
commit's, side by side in one run.

Run as ``python -m benchmarks.compare_commits step --against REV [--repeats 5] [--out FILE]
[--force]`` (the commit must be in this checkout's git history). Timings on a shared machine
drift by tens of percent from minute to minute, so a speed claim is a ratio measured side by
side: the reference commit's ``pushctl/`` (and ``experiments/``) is unpacked with ``git
archive`` into a temporary directory, and each repeat runs one fresh child process per tree,
alternating which goes first, pinned to one core (``taskset -c 0`` where it exists). Each
child times, on the same inputs:

- ``world step``: the arm pushing the cube at 1 cm/s (:func:`benchmarks.suite._pushing_world`),
  median of 2000 steps [µs]; and the same on other scenes, median of 400 steps (20 cm of
  pushing at 5 cm/s): the cube at 5 cm/s, the wedge at 1 and 5 cm/s, and the free arm
  holding itself up under its own gravity torque, the cube far away (no prong contact);
- ``cold MLCP``: ``solve_box_mlcp`` on the cold-path problems (the warm active set failed)
  recorded from random-action ``Push-v0`` steps in this tree, median over problems of each
  problem's median of 5 solves [µs]; ``…, ProxQP path of the reference``: the same over the
  problems the reference solved with its ProxQP fixed point;
- ``env step, zero residual`` and ``env step, random actions``: ``Push-v0`` steps on one
  wedge chirp push, median [µs];
- ``unknowns: …``: the training environment with the plant unknowns on (the ``sim`` plant),
  ``action_repeat`` 10 and the offset observed, on three 6 s pushes (scenario seeds 0-2 of
  the training stream, cube and wedge), mean time per push step [µs]: ``gate shut`` (zero
  actions), ``gate open`` (random actions every step) and ``feedback law`` (the feedback
  actor, as the evaluation pushes); ``unknowns: controller terms`` the median of
  :meth:`Episode.controller_terms` on a mounted pusher whose plate centre agrees with the
  nominal one to the bit (scenario seed 0) and ``…, own g`` one where it does not (seed 3)
  [µs]. NaN where the reference tree lacks these settings.

The table gives the median over repeats of each tree, and as the ratio the median over repeats
of each pair's this / reference (:func:`paired_ratio`).
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import shutil
import statistics
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from rich.console import Console
from rich.table import Table

import pushctl
from pushctl import native
from pushctl.errors import ConfigError
from pushctl.files.output_guard import refuse_existing_files
from pushctl.files.provenance import git_commit, provenance_line, write_csv

ROOT = Path(__file__).resolve().parents[2]
"""This checkout's root (its ``benchmarks`` package)."""

METRICS = (
    "world step",
    "world step, cube at 5 cm/s",
    "world step, wedge at 1 cm/s",
    "world step, wedge at 5 cm/s",
    "world step, free arm",
    "cold MLCP",
    "cold MLCP, ProxQP path of the reference",
    "env step, zero residual",
    "env step, random actions",
    "unknowns: env step, gate shut",
    "unknowns: env step, gate open",
    "unknowns: feedback law push",
    "unknowns: controller terms",
    "unknowns: controller terms, own g",
)

_CHILD = (Path(__file__).with_name("step_child.py")).read_text()
"""The child's script (:mod:`benchmarks.commits.step_child`), run with ``python -c``."""


BUILD_NATIVE = "from pushctl.native.build import build; print(build(optional=True))"


def record_cold_problems(steps: int = 1500, seed: int = 0) -> list[tuple]:
    """The MLCPs of the steps where a warm active set failed (some solve of the step was
    not a verified warm start, so the cold path ran) during ``steps`` random-action
    ``Push-v0`` steps of this tree: (D, b, lo, hi, findex, mu, warm_start) each, the step's
    first problem (:meth:`StepSolver.problem`) with the guess the step started from."""
    from pushctl.contact.step_solver import StepSolver
    from pushctl.task.env import PushEnv
    from pushctl.task.env_config import EnvConfig

    recorded: list[tuple] = []
    solve = StepSolver.solve

    def record(self: StepSolver, state: tuple, prongs: tuple[int, ...]):
        same = prongs == self.last_prongs and self.last_p is not None
        guess = self.last_p.copy() if same else None  # type: ignore[union-attr]
        problem = self.problem(state, prongs)
        solves, warm = self.stats.solves, self.stats.warm_starts
        solved = solve(self, state, prongs)
        if self.stats.warm_starts - warm < self.stats.solves - solves:
            recorded.append(
                (problem.D, problem.b, problem.lo, problem.hi, problem.findex, problem.mu, guess)
            )
        return solved

    StepSolver.solve = record  # type: ignore[method-assign]
    try:
        env = PushEnv(EnvConfig(duration=6.0, gate_threshold=0.0))
        rng = np.random.default_rng(seed)
        env.reset(seed=seed)
        for i in range(steps):
            _, _, terminated, truncated, _ = env.step(rng.uniform(-1, 1, 3).astype(np.float32))
            if terminated or truncated:
                env.reset(seed=seed + i + 1)
    finally:
        StepSolver.solve = solve  # type: ignore[method-assign]
    return recorded


def unpack(commit: str, into: Path) -> Path:
    """``pushctl/`` and ``experiments/`` of ``commit`` under ``into``, with its compiled
    library where it has one (:func:`build_native`); ConfigError if this is not a git
    checkout or the commit is unknown."""
    root = Path(pushctl.__file__).resolve().parent.parent
    archive = into / "reference.tar"
    done = subprocess.run(
        ["git", "-C", str(root), "archive", "-o", str(archive), commit, "pushctl", "experiments"],
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode != 0:
        message = done.stderr.strip().splitlines()[-1] if done.stderr.strip() else "git failed"
        raise ConfigError(f"--against {commit}: cannot unpack it from {root}: {message}")
    tree = into / "reference"
    with tarfile.open(archive) as tar:
        tar.extractall(tree, filter="data")
    build_native(tree)
    return tree


def build_native(tree: Path) -> None:
    """Give an unpacked tree that has pushctl's compiled library among its sources
    (:mod:`pushctl.native`) the library it would run with: ``git archive``
    leaves the built library out, and without it the tree would run the Python bindings,
    slower, and lose every comparison it is timed in. This tree's library is copied where
    the tree's sources are the same (its stamp then matches); otherwise its own build
    compiles them (about 45 s). A build that fails leaves the tree on the bindings, which
    the build's one line says."""
    if not (tree / "pushctl" / "native" / "build.py").is_file():
        return  # before the library: the bindings are what that commit ran
    target = tree / "pushctl" / "native" / "lib"
    if native.LIBRARY.exists() and native.STAMP.exists():
        target.mkdir(parents=True, exist_ok=True)
        shutil.copy2(native.LIBRARY, target / native.LIBRARY.name)
        shutil.copy2(native.STAMP, target / native.STAMP.name)
    subprocess.run(  # does nothing if the copied stamp matches the tree's sources
        [sys.executable, "-c", BUILD_NATIVE],
        env={**os.environ, "PYTHONPATH": str(tree)},
        cwd=tree,
        check=False,
    )


def run_child(tree: Path, problems: Path, core: int = 0) -> dict[str, Any]:
    """One child process timing the tree at ``tree`` (its ``pushctl`` first on the path,
    this checkout's ``benchmarks`` after it: both trees time the same scenes), pinned to
    ``core``."""
    pin = ["taskset", "-c", str(core)] if shutil.which("taskset") else []
    env = {**os.environ, "PYTHONPATH": os.pathsep.join((str(tree), str(ROOT)))}
    done = subprocess.run(
        [*pin, sys.executable, "-c", _CHILD, str(problems)],
        capture_output=True,
        text=True,
        env=env,
        check=False,
        cwd=tree,
    )
    if done.returncode != 0:
        raise RuntimeError(f"timing child in {tree} failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def compare(against: str, repeats: int, core: int = 0) -> tuple[pd.DataFrame, int]:
    """Median [µs] of each metric per tree over ``repeats`` interleaved pairs of children,
    and the ratio; also the number of cold problems timed."""
    this_tree = Path(pushctl.__file__).resolve().parent.parent
    with tempfile.TemporaryDirectory(prefix="pushctl-bench-") as scratch:
        scratch_dir = Path(scratch)
        reference = unpack(against, scratch_dir)
        problems = record_cold_problems()
        problems_file = scratch_dir / "problems.pkl"
        problems_file.write_bytes(pickle.dumps(problems))
        samples: dict[str, list[dict[str, Any]]] = {"this": [], "reference": []}
        for k in range(repeats):
            order = ("reference", "this") if k % 2 == 0 else ("this", "reference")
            for name in order:
                tree = reference if name == "reference" else this_tree
                samples[name].append(run_child(tree, problems_file, core))
    proxqp = [i for i, m in enumerate(samples["reference"][0]["methods"]) if m.startswith("proxqp")]
    for sample in (*samples["this"], *samples["reference"]):
        each = sample["cold_each"]
        subset = [each[i] for i in proxqp] or [float("nan")]
        sample["cold MLCP, ProxQP path of the reference"] = 1e6 * statistics.median(subset)
    rows = []
    for metric in METRICS:
        this = [s[metric] for s in samples["this"]]
        reference_values = [s[metric] for s in samples["reference"]]
        rows.append(
            {
                "name": metric,
                "this_us": statistics.median(this),
                "reference_us": statistics.median(reference_values),
                "ratio": paired_ratio(this, reference_values),
                "note": f"medians of {repeats} interleaved child processes per tree, one core; "
                "ratio: the median of each pair's",
            }
        )
    return pd.DataFrame(rows), len(problems)


def paired_ratio(this: list[float], reference: list[float]) -> float:
    """The median over repeats of this / reference, each pair run one after the other.

    The machine's speed drifts over minutes (on a shared machine the ratio of the two trees'
    medians can stray by a third for code the two trees share); a pair's two children see
    about the same machine, so the drift cancels in their ratio."""
    return statistics.median(ours / theirs for ours, theirs in zip(this, reference, strict=True))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m benchmarks.compare_commits step", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--against", required=True, help="reference commit (git)")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--core", type=int, default=0, help="the core the children run on")
    parser.add_argument("--out", type=Path, default=None, help="also write the table as CSV")
    parser.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    args = parser.parse_args(argv)
    try:
        refuse_existing_files("--out", (args.out,), args.force)
        if args.repeats < 1:
            raise ConfigError(f"--repeats must be an integer >= 1, got {args.repeats}")
        cores = os.cpu_count() or 1
        if not 0 <= args.core < cores:
            raise ConfigError(f"--core must be a core of this machine, 0-{cores - 1}")
        frame, n_problems = compare(args.against, args.repeats, args.core)
    except ConfigError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    table = Table(title=f"this tree ({git_commit()}) against {args.against}, side by side")
    for column in ("what", "this [µs]", f"{args.against} [µs]", "ratio"):
        table.add_column(column, justify="left" if column == "what" else "right")
    for row in frame.itertuples():
        table.add_row(row.name, f"{row.this_us:.1f}", f"{row.reference_us:.1f}", f"{row.ratio:.2f}")
    Console().print(table)
    print(f"cold MLCP: {n_problems} problems recorded from random-action Push-v0 steps")
    print(f"this tree's arm terms: {native.status()}")
    if args.out is not None:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        extra = f"against {args.against}; {n_problems} cold problems; arm terms: "
        extra += native.status()
        write_csv(args.out, frame, provenance_line(extra=extra), float_format="%.4g")
    return 0

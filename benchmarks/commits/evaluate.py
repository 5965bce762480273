"""``pushctl evaluate`` of this tree against a reference commit, side by side, and the two
trees' outputs compared byte for byte.

Run as ``python -m benchmarks.compare_commits evaluate --against REV [--repeats 3]
[--trials 1] [--workers 2] [--out FILE] [--force]``. The evaluation is ``make
reproduce-tables``'s in shape (every controller, the plants sim, proxy and mujoco, the three
shipped training seeds' policies, evaluation seed 0) with fewer trials. The reference
commit's ``pushctl/`` and ``experiments/`` are unpacked with ``git archive``
(:func:`~benchmarks.commits.step.unpack`); both trees read the same policy files, this
checkout's ``results/training/seed-K/policy.pt``. Each tree first runs the evaluation once
untimed (numba compiles its kernels into a fresh tree's cache), then ``repeats`` timed runs
per tree alternate which tree goes first. A run is the whole command in a fresh process
(Ray's start included), on every core with ``--workers`` > 1, else pinned to one core
(``taskset -c 0`` where it exists).

The table gives the median wall time of each tree [s], the ratio this / reference, and
whether every run's ``trials.csv`` and ``steps.csv`` equal the reference's first run's to
the byte (after their ``# made by:`` line, which names the tree's commit), in the
reference's columns: a column this tree adds is left out of the comparison, every value the
reference wrote is compared as the text it wrote.
"""

from __future__ import annotations

import io
import statistics
import sys
import tempfile
from pathlib import Path

import pandas as pd

import pushctl
from benchmarks.commits import trees
from benchmarks.commits.step import unpack
from benchmarks.commits.trees import run_in_tree, show_and_write, side_by_side_parser
from pushctl.errors import ConfigError
from pushctl.files.output_guard import refuse_existing_files

SEEDS = (0, 1, 2)
"""The shipped training seeds whose policies are evaluated, as ``make reproduce-tables`` does."""
OUTPUTS = ("trials.csv", "steps.csv")


def command(trials: int, workers: int, out: Path, policies: list[Path]) -> list[str]:
    """The ``pushctl evaluate`` command line timed (without the interpreter)."""
    chosen = [part for path in policies for part in ("--policy", str(path))]
    return [
        "-m", "pushctl.cli", "evaluate", "--trials", str(trials), "--workers", str(workers),
        "--plant", "all", "--seed", "0", *chosen, "--out", str(out), "--force",
    ]  # fmt: skip


def run(tree: Path, args: list[str], workers: int) -> float:
    """Wall time [s] of ``python args`` in ``tree`` (:func:`run_in_tree`), pinned to one
    core with one worker."""
    return run_in_tree(tree, args, pin=workers == 1)[0]


def body(directory: Path) -> tuple[bytes, ...]:
    """The outputs' bytes after their first (``# made by:``) line."""
    return trees.body(directory, OUTPUTS)


def same_outputs(result: tuple[bytes, ...], expected: tuple[bytes, ...]) -> bool:
    """Whether each CSV body of ``result`` (:func:`body`) equals ``expected``'s to the byte,
    or, where this tree wrote more columns, in ``expected``'s columns, value for value as
    text."""
    for mine, theirs in zip(result, expected, strict=True):
        if mine == theirs:
            continue
        ours, reference = (
            pd.read_csv(io.BytesIO(text), dtype=str, keep_default_na=False)
            for text in (mine, theirs)
        )
        columns = list(reference.columns)
        if not set(columns) <= set(ours.columns) or not ours[columns].equals(reference):
            return False
    return True


def compare(against: str, repeats: int, trials: int, workers: int) -> pd.DataFrame:
    """One row per tree: median, min and max wall time [s] over ``repeats`` interleaved
    runs, and whether all its outputs equal the reference's to the byte."""
    this_tree = Path(pushctl.__file__).resolve().parent.parent
    policies = [this_tree / "results" / "training" / f"seed-{s}" / "policy.pt" for s in SEEDS]
    missing = [str(path) for path in policies if not path.is_file()]
    if missing:
        raise ConfigError(f"no policy file {missing[0]}; the shipped results/training/ is needed")
    with tempfile.TemporaryDirectory(prefix="pushctl-bench-evaluate-") as scratch:
        scratch_dir = Path(scratch)
        trees = {"this": this_tree, "reference": unpack(against, scratch_dir)}
        times: dict[str, list[float]] = {"this": [], "reference": []}
        outputs: dict[str, list[tuple[bytes, ...]]] = {"this": [], "reference": []}
        for name, tree in trees.items():  # untimed: numba's cache of a fresh tree
            run(tree, command(trials, workers, scratch_dir / f"warm-{name}", policies), workers)
        for k in range(repeats):
            order = ("reference", "this") if k % 2 == 0 else ("this", "reference")
            for name in order:
                out = scratch_dir / f"{name}-{k}"
                args = command(trials, workers, out, policies)
                times[name].append(run(trees[name], args, workers))
                outputs[name].append(body(out))
    expected = outputs["reference"][0]
    return pd.DataFrame(
        [
            {
                "tree": name if name == "this" else f"reference {against}",
                "median_s": statistics.median(times[name]),
                "min_s": min(times[name]),
                "max_s": max(times[name]),
                "ratio": statistics.median(times[name]) / statistics.median(times["reference"]),
                "identical": all(same_outputs(result, expected) for result in outputs[name]),
                "note": f"{repeats} interleaved runs, {trials} trial(s) per cell, "
                f"{workers} worker(s)",
            }
            for name in ("this", "reference")
        ]
    )


def main(argv: list[str] | None = None) -> int:
    parser = side_by_side_parser("evaluate", __doc__, repeats=3)
    parser.add_argument("--trials", type=int, default=1, help="trials per object × profile")
    parser.add_argument("--workers", type=int, default=2, help="pushctl evaluate --workers")
    args = parser.parse_args(argv)
    try:
        refuse_existing_files("--out", (args.out,), args.force)
        for option, value, low in (("repeats", args.repeats, 1), ("trials", args.trials, 1)):
            if value < low:
                raise ConfigError(f"--{option} must be an integer >= {low}, got {value}")
        if not 1 <= args.workers <= 8:
            raise ConfigError(f"--workers must be an integer in 1 … 8, got {args.workers}")
        frame = compare(args.against, args.repeats, args.trials, args.workers)
    except ConfigError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    show_and_write(frame, "pushctl evaluate", args.against, args.out, OUTPUTS)
    return 0

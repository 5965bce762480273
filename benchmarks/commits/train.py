"""``pushctl train`` of this tree against a reference commit, side by side, and the two trees'
outputs compared byte for byte.

Run as ``python -m benchmarks.compare_commits train --against REV [--repeats 3] [--out FILE]
[--force]``. The run is the ``paper`` preset shortened (:data:`OVERRIDES`: 40 episodes, a
10-episode warm-up, validation every 20 episodes on 12 pushes), so it holds every part of a
``paper`` episode's cost in about the same shares: the warm-up's law and the actor's
episodes, the DDPG updates, the PD-only curve pushes and the validations. It runs in one
process pinned to one core (``workers`` 0), as each seed of ``make reproduce-tables``
trains on this 2-core machine (three seeds, one process each:
:func:`~pushctl.runs.seeds.core_plan`), so its time is the core time a seed needs
and does not swing with the other core's load. The reference commit's ``pushctl/`` and
``experiments/`` are unpacked with ``git archive``; both trees read one preset file written
from this tree's ``pushctl/defaults/train_paper.toml``. Each tree first runs once untimed
(numba's cache of a fresh tree), then ``repeats`` timed runs per tree alternate which tree
goes first; a run is the whole command in a fresh process.

The table gives each tree's CPU time [s] (median, min, max; the machine is shared, and a
run's wall time holds the time it waited for its core while its CPU time does not), its
median wall time, the CPU-time ratio this / reference, and whether every run's
``curve.csv`` and ``validation.csv`` equal the reference's first run's to the byte after
their ``# made by:`` line.
"""

from __future__ import annotations

import re
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

OVERRIDES = {
    "episodes": "40",
    "checkpoint_every": "20",
    "validate_every": "20",
    "validation_per_cell": "2",
    "warmup_steps": "2000",
    "critic_burn_in": "200",
    "workers": "0",
}
"""The ``paper`` preset's values replaced for the timed run (key = value, one line each)."""
OUTPUTS = ("curve.csv", "validation.csv")


def bench_preset(paper: str) -> str:
    """The text of the ``paper`` preset file ``paper`` with :data:`OVERRIDES` (comments
    after a replaced value dropped); ConfigError unless each key is on exactly one line."""
    for key, value in OVERRIDES.items():
        paper, found = re.subn(rf"(?m)^{key} = .*$", f"{key} = {value}", paper)
        if found != 1:
            raise ConfigError(f"the paper preset has {found} lines setting {key!r}, not one")
    return paper


def command(preset: Path, out: Path) -> list[str]:
    """The ``pushctl train`` command line timed (without the interpreter)."""
    return ["-m", "pushctl.cli", "train", "--preset", str(preset), "--seed", "0", "--out", str(out)]


def run(tree: Path, args: list[str]) -> tuple[float, float]:
    """Wall time and CPU time [s] of ``python args`` in ``tree`` on core 0
    (:func:`~benchmarks.commits.trees.run_in_tree`). With ``workers`` 0 the run is that one
    process (no Ray), so its CPU time is the run's core time even while other work shares
    the core."""
    return run_in_tree(tree, args, pin=True)


def body(directory: Path) -> tuple[bytes, ...]:
    """The outputs' bytes after their first (``# made by:``) line."""
    return trees.body(directory, OUTPUTS)


def compare(against: str, repeats: int) -> pd.DataFrame:
    """One row per tree: median, min and max CPU time [s] over ``repeats`` interleaved runs,
    the median wall time [s], the CPU-time ratio this / reference, and whether all its
    outputs equal the reference's to the byte."""
    this_tree = Path(pushctl.__file__).resolve().parent.parent
    with tempfile.TemporaryDirectory(prefix="pushctl-bench-train-") as scratch:
        scratch_dir = Path(scratch)
        preset = scratch_dir / "bench_paper.toml"
        paper = (this_tree / "pushctl" / "defaults" / "train_paper.toml").read_text()
        preset.write_text(bench_preset(paper))
        trees = {"this": this_tree, "reference": unpack(against, scratch_dir)}
        times: dict[str, list[tuple[float, float]]] = {"this": [], "reference": []}
        outputs: dict[str, list[tuple[bytes, ...]]] = {"this": [], "reference": []}
        for name, tree in trees.items():  # untimed: numba's cache of a fresh tree
            run(tree, command(preset, scratch_dir / f"warm-{name}"))
        for k in range(repeats):
            order = ("reference", "this") if k % 2 == 0 else ("this", "reference")
            for name in order:
                out = scratch_dir / f"{name}-{k}"
                times[name].append(run(trees[name], command(preset, out)))
                outputs[name].append(body(out))
    expected = outputs["reference"][0]
    cpu = {name: [c for _, c in runs] for name, runs in times.items()}
    note = f"{repeats} interleaved runs, one core; paper preset with {OVERRIDES}"
    return pd.DataFrame(
        [
            {
                "tree": name if name == "this" else f"reference {against}",
                "cpu_median_s": statistics.median(cpu[name]),
                "cpu_min_s": min(cpu[name]),
                "cpu_max_s": max(cpu[name]),
                "wall_median_s": statistics.median(wall for wall, _ in times[name]),
                "ratio": statistics.median(cpu[name]) / statistics.median(cpu["reference"]),
                "identical": all(result == expected for result in outputs[name]),
                "note": note,
            }
            for name in ("this", "reference")
        ]
    )


def main(argv: list[str] | None = None) -> int:
    args = side_by_side_parser("train", __doc__, repeats=3).parse_args(argv)
    try:
        refuse_existing_files("--out", (args.out,), args.force)
        if args.repeats < 1:
            raise ConfigError(f"--repeats must be an integer >= 1, got {args.repeats}")
        frame = compare(args.against, args.repeats)
    except ConfigError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    show_and_write(frame, "pushctl train", args.against, args.out, OUTPUTS)
    return 0

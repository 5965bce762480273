"""What the side-by-side command benches (:mod:`benchmarks.commits.evaluate`,
:mod:`benchmarks.commits.train`) share: a ``pushctl`` command run in a fresh process with one
source tree's package first on the path, and the table they print and write."""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd

from pushctl.files.provenance import git_commit, provenance_line, write_csv


def side_by_side_parser(what: str, doc: str | None, repeats: int) -> argparse.ArgumentParser:
    """The arguments every side-by-side bench takes (``--against``, ``--repeats``, ``--out``,
    ``--force``) for ``python -m benchmarks.compare_commits what``, described by ``doc``'s
    first line; a bench adds its own."""
    parser = argparse.ArgumentParser(
        prog=f"python -m benchmarks.compare_commits {what}",
        description=(doc or "").splitlines()[0],
    )
    parser.add_argument("--against", required=True, help="reference commit (git)")
    parser.add_argument("--repeats", type=int, default=repeats)
    parser.add_argument("--out", type=Path, default=None, help="also write the table as CSV")
    parser.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    return parser


def run_in_tree(tree: Path, args: list[str], pin: bool) -> tuple[float, float]:
    """Wall time and CPU time (user + system) [s] of ``python args`` run in ``tree`` with
    its ``pushctl`` first on the path (Ray workers it starts inherit the path); ``pin``: on
    core 0 (``taskset``, where it exists). The CPU time is of the process and the children
    it waited for: not Ray's workers, which Ray's own daemon starts. RuntimeError with the
    end of its stderr if it fails."""
    pinned = ["taskset", "-c", "0"] if pin and shutil.which("taskset") else []
    env = {**os.environ, "PYTHONPATH": str(tree)}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(
        [*pinned, sys.executable, *args], capture_output=True, text=True, env=env, cwd=tree
    )
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(args[:3])} in {tree} failed:\n{done.stderr[-2000:]}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def body(directory: Path, names: tuple[str, ...]) -> tuple[bytes, ...]:
    """The bytes of the files ``names`` in ``directory`` after their first (``# made by:``)
    line, which names the tree's commit."""
    return tuple((directory / name).read_bytes().split(b"\n", 1)[1] for name in names)


def show_and_write(
    frame: pd.DataFrame, command: str, against: str, out: Path | None, outputs: tuple[str, ...]
) -> None:
    """Print the side-by-side table of ``command`` (e.g. ``pushctl train``), write it to
    ``out`` (None: only print) with its provenance, and say when an output differed."""
    print(f"{command}, this tree ({git_commit()}) against {against}:")
    print(frame.to_string(index=False, float_format=lambda v: f"{v:.2f}"))
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
        write_csv(out, frame, provenance_line(extra=f"against {against}"))
    if not frame["identical"].all():  # a timing, not a check: other commits may differ
        print(f"the outputs differ from {against}'s ({' or '.join(outputs)})")

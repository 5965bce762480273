"""The slip loop's length: what fewer friction re-solves per step buy in speed and cost in
physics, side by side in one process (docs/performance.md).

Run as ``python -m benchmarks.slip_loop [--pushes 12] [--iterations 6,2,1]
[--env training|push-v0] [--out FILE] [--force]``. A step whose ground friction directions
move is solved again, at most ``WorldConfig.slip_iterations`` times (default 6, what
``results/`` was made with); a step not settled by then keeps its first solution. In the
training environment most re-solves are spent on steps that never settle.

This bench pushes an environment once per setting, the settings interleaved push by push,
on one core (pinned): ``--env training``, the training environment with the plant unknowns
(``EnvConfig(action_repeat=10, observe_offset=True)``, the ``sim`` plant), or ``--env
push-v0``, ``pushctl/Push-v0`` on its defaults (a new action every 10 ms step: the acting
step the bench times); training-stream scenario seeds 0…N−1. It pushes with the gate
``shut`` (zero actions: the base law alone) and ``open`` (uniform random actions every
decision, prongs slipping). The world's setting is changed after each reset, so the
approach and the re-landing are the same in every run and only the push differs.

Per setting and gate it reports: push-step time [µs] (median of the pushes) and the median
of each push's time over the default's; MLCP solves and steps kept unsettled per push step;
the push's metrics (``compute_metrics``: mean translation error [% of the arc], mean angle
error [deg]) averaged over the pushes; and the mean distance between each push's final
object position and the default's [mm]. ``chaos`` is the default again with the object
nudged 1 nm along x before the push: how far a push moves from a change in the last bits
alone, the scale against which the settings' distances are read.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from benchmarks.engines import pinned_to_one_core
from pushctl.contact.world import MAX_SLIP_ITERATIONS
from pushctl.episode.metrics import compute_metrics
from pushctl.errors import ConfigError
from pushctl.files.output_guard import refuse_existing_files
from pushctl.files.provenance import provenance_line, write_csv
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig

GATES = {"shut": 1.0, "open": 0.0}
"""Gate thresholds [m] of the two ways of pushing (1 m: never opens; 0: always open)."""
CHAOS = "chaos"
"""The default setting with the object nudged by :data:`NUDGE` before the push."""
NUDGE = 1e-9
"""[m] along x: far below anything physical, so the push differs from the default's only
by how the dynamics amplify a change in the last bits."""


def push_once(env: PushEnv, seed: int, iterations: int, nudge: float, gate: str) -> dict:
    """One push of scenario ``seed`` with at most ``iterations`` re-solves per step (the
    reset with the default); returns its time, counts, metrics and final position."""
    env.reset(seed=seed)
    episode = env.episode
    assert episode is not None
    world = episode.world
    world.config = replace(world.config, slip_iterations=iterations)  # type: ignore[union-attr]
    world.object_pose[0] += nudge  # the world's own state, before any push step reads it
    stats = world.stats  # type: ignore[union-attr]
    solves, unsettled = stats.solves, stats.slip_unsettled
    rng = np.random.default_rng(seed)
    zero = np.zeros(3, dtype=np.float32)
    start = time.perf_counter()
    while not episode.done:
        env.step(rng.uniform(-1, 1, 3).astype(np.float32) if gate == "open" else zero)
    elapsed = time.perf_counter() - start
    metrics = compute_metrics(episode.trace())
    steps = episode.n_steps
    return {
        "us": 1e6 * elapsed / steps,
        "solves": (stats.solves - solves) / steps,
        "unsettled": (stats.slip_unsettled - unsettled) / steps,
        "translation_pct": metrics.translation_error_pct,
        "angle_deg": metrics.angle_error_deg,
        "final": np.array(world.object_pose[:2], dtype=float),
    }


ENVIRONMENTS = {
    "training": EnvConfig(action_repeat=10, observe_offset=True),
    "push-v0": EnvConfig(),
}
"""``--env``'s environments (their gates set by :data:`GATES`)."""


def study(pushes: int, settings: list[int], environment: str = "training") -> pd.DataFrame:
    """The table described in the module docstring, for ``environment`` (a key of
    :data:`ENVIRONMENTS`)."""
    names: list[str | int] = [MAX_SLIP_ITERATIONS, CHAOS]
    names += [k for k in settings if k != MAX_SLIP_ITERATIONS]
    rows = []
    with pinned_to_one_core():
        for gate, threshold in GATES.items():
            env = PushEnv(replace(ENVIRONMENTS[environment], gate_threshold=threshold))
            push_once(env, pushes, MAX_SLIP_ITERATIONS, 0.0, gate)  # numba's caches, untimed
            runs: dict[str | int, list[dict]] = {name: [] for name in names}
            for seed in range(pushes):
                order = names if seed % 2 == 0 else names[::-1]
                for name in order:
                    iterations = MAX_SLIP_ITERATIONS if name == CHAOS else int(name)
                    nudge = NUDGE if name == CHAOS else 0.0
                    runs[name].append(push_once(env, seed, iterations, nudge, gate))
            rows += _summarise(gate, runs, runs[MAX_SLIP_ITERATIONS])
    return pd.DataFrame(rows)


def _summarise(gate: str, runs: dict[str | int, list[dict]], default: list[dict]) -> list[dict]:
    """One row per setting: medians of times and their ratio to the default's, means of
    the rest over the pushes."""
    rows = []
    for name, pushes in runs.items():
        ratios = [run["us"] / base["us"] for run, base in zip(pushes, default, strict=True)]
        moved = [np.linalg.norm(run["final"] - base["final"]) for run, base in
                 zip(pushes, default, strict=True)]  # fmt: skip
        rows.append({
            "gate": gate,
            "slip_iterations": name,
            "push_step_us": statistics.median(run["us"] for run in pushes),
            "time_ratio": statistics.median(ratios),
            "solves_per_step": statistics.fmean(run["solves"] for run in pushes),
            "unsettled_per_step": statistics.fmean(run["unsettled"] for run in pushes),
            "translation_error_pct": _mean(run["translation_pct"] for run in pushes),
            "angle_error_deg": _mean(run["angle_deg"] for run in pushes),
            "final_distance_mm": 1e3 * statistics.fmean(moved),
            "pushes": len(pushes),
        })  # fmt: skip
    return rows


def _mean(values) -> float:
    finite = [v for v in values if math.isfinite(v)]
    return statistics.fmean(finite) if finite else math.nan


def main(argv: list[str] | None = None) -> int:
    doc = (__doc__ or "").splitlines()[0]
    parser = argparse.ArgumentParser(prog="python -m benchmarks.slip_loop", description=doc)
    parser.add_argument("--pushes", type=int, default=12, help="scenario seeds 0…N−1")
    parser.add_argument("--iterations", default="6,2,1", help="settings of slip_iterations")
    parser.add_argument("--env", default="training", help="training or push-v0")
    parser.add_argument("--out", type=Path, default=None, help="also write the table as CSV")
    parser.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    args = parser.parse_args(argv)
    parts = args.iterations.split(",")
    if args.pushes < 1 or not all(part.strip().isdigit() for part in parts):
        print(
            f"error: --pushes must be an integer >= 1 and --iterations integers >= 0 separated "
            f"by commas (e.g. 6,2,1), got {args.pushes} and {args.iterations!r}",
            file=sys.stderr,
        )
        return 2
    if args.env not in ENVIRONMENTS:
        print(f"error: --env must be one of {', '.join(ENVIRONMENTS)}, got {args.env!r}",
              file=sys.stderr)  # fmt: skip
        return 2
    settings = [int(part) for part in parts]
    try:
        refuse_existing_files("--out", [args.out], args.force)
    except ConfigError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    table = study(args.pushes, settings, args.env)
    with pd.option_context("display.width", 160, "display.max_columns", 20):
        print(table.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    if args.out is not None:
        command = f"python -m benchmarks.slip_loop --pushes {args.pushes} " \
            f"--iterations {args.iterations} --env {args.env}"  # fmt: skip
        write_csv(args.out, table, provenance_line(command))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

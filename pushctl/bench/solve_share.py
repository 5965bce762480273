"""The contact solve's share of an acting step and of a zero-residual step, and how much
faster it would have to be for issue 15's item 1 (an acting step ≤ 1.3 × a zero-residual
one) with everything else as it is (docs/reproducibility-and-speed.md, twenty-third pass).

Run as ``python -m pushctl.bench.solve_share [--repeats 5] [--drawn] [--out FILE]
[--force]``.
``bench.rl``'s item-1 row on ``Push-v0``'s defaults, taken apart: the cube chirp of
``bench.rl``'s :data:`~pushctl.bench.rl.OPTIONS`, a decision every push step, the gate held
open, pushed with zero actions and with uniform random actions (each repeat's from its own
seed), on one core (pinned). Each repeat pushes four times, alternating the two ways: once
plainly (the step's time) and once with the world's contact solve timed (its time), the
same actions, so the same push to the bit. The contact solve is what
``SubstepSolver._substep`` hands the MLCP to: the compiled step (the warm and cold loops of
the friction boxes) and the step in parts (a new contact set, ProxQP's continuations).
With ``--drawn``, ``bench.rl``'s row over ``Push-v0``'s own scenarios instead: its defaults
all through, the gate's too, repeat r pushing the scenario ``reset(seed=r)`` draws.

Per way, medians over the repeats of each push's [µs per push step]: the step (the plain
push), the step with its solve timed, the contact solve, the rest (the timed push's step
less its solve); and the solves per step. Then, per repeat (its zero-residual push beside
its acting one, as ``bench.rl`` pairs them), medians over the repeats of:

- ``ratio``: acting step / zero-residual step, plain pushes (``bench.rl``'s row);
- ``ratio_solve_free``: the same were the contact solve to cost nothing either way (the
  timed pushes' rests);
- ``solve_cut_needed``: the fraction x of the contact solve's time, cut on both ways alike,
  that brings the timed pushes' ratio to 1.3: ``(T_a − x S_a) = 1.3 (T_z − x S_z)``
  (infinite where no cut does: ``unreachable`` counts those repeats); and
  ``solve_speedup_needed`` = 1 / (1 − x) of the median x.

The split is taken within each timed push, not between two pushes: this machine's speed
moves between pushes by more than the differences sought.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from pushctl.bench.engines import pinned_to_one_core
from pushctl.bench.rl import OPTIONS
from pushctl.control.gains import load_gains
from pushctl.errors import ConfigError
from pushctl.output_guard import refuse_existing_files
from pushctl.provenance import provenance_line, write_csv
from pushctl.rl.env import PushEnv
from pushctl.rl.env_config import EnvConfig

TARGET = 1.3
"""Issue 15's item 1: an acting step costs at most this times a zero-residual step."""
SOLVE_METHODS = ("solve",)
"""The method of the world's step solver that makes a step's contact solve."""
WAYS = ("zero", "acting")


class SolveClock:
    """Times the contact solve of one world: each of :data:`SOLVE_METHODS` wrapped on the
    instance (an instance attribute shadows the class's method), its time summed in
    ``seconds``. :meth:`remove` takes the wrappers off again."""

    def __init__(self, world: Any) -> None:
        world = world.solver
        self.world, self.seconds = world, 0.0
        for name in SOLVE_METHODS:
            setattr(world, name, self._timed(getattr(world, name)))

    def _timed(self, method: Callable[..., Any]) -> Callable[..., Any]:
        clock = time.perf_counter

        def timed(*args: Any) -> Any:
            start = clock()
            try:
                return method(*args)
            finally:
                self.seconds += clock() - start

        return timed

    def remove(self) -> None:
        for name in SOLVE_METHODS:
            delattr(self.world, name)


def push(
    env: PushEnv, act: Callable[[], np.ndarray], clocked: bool, seed: int | None = None
) -> dict[str, float]:
    """One push with the actions ``act()`` (reset not timed), of the
    :data:`~pushctl.bench.rl.OPTIONS` scenario or, with a ``seed``, of the one
    ``env.reset(seed=seed)`` draws: its step [µs per push step], with ``clocked`` also the
    contact solve's, and its solves per step."""
    if seed is None:
        env.reset(options=OPTIONS)
    else:
        env.reset(seed=seed)
    episode = env.episode
    assert episode is not None
    world = episode.world
    clock = SolveClock(world) if clocked else None
    solves = world.stats.solves
    start = time.perf_counter()
    while not episode.done:
        env.step(act())
    elapsed = time.perf_counter() - start
    if clock is not None:
        clock.remove()
    steps = episode.n_steps
    return {
        "step_us": 1e6 * elapsed / steps,
        "solve_us": math.nan if clock is None else 1e6 * clock.seconds / steps,
        "solves_per_step": (world.stats.solves - solves) / steps,
    }


def study(repeats: int, drawn: bool = False) -> pd.DataFrame:
    """The table of the module docstring: one row per way, then one of the figures drawn
    from them (see :func:`summarise`); ``drawn``: over ``Push-v0``'s own scenarios."""
    config = EnvConfig() if drawn else EnvConfig(gate_threshold=0.0)  # Push-v0's; gate open
    env = PushEnv(config, load_gains())
    zero = np.zeros(3)

    def actions(way: str, seed: int) -> Callable[[], np.ndarray]:
        if way == "zero":
            return lambda: zero
        rng = np.random.default_rng(seed)
        return lambda: rng.uniform(-1.0, 1.0, 3)

    runs: dict[str, list[dict[str, float]]] = {way: [] for way in WAYS}
    with pinned_to_one_core():
        for way in WAYS:  # numba loads the cold path's kernels at its first use: untimed
            push(env, actions(way, repeats), clocked=False, seed=repeats if drawn else None)
        for repeat in range(repeats):
            order = WAYS if repeat % 2 == 0 else WAYS[::-1]
            seed = repeat if drawn else None
            for way in order:
                plain = push(env, actions(way, repeat), clocked=False, seed=seed)
                timed = push(env, actions(way, repeat), clocked=True, seed=seed)
                runs[way].append({
                    "step_us": plain["step_us"],
                    "clocked_step_us": timed["step_us"],
                    "solve_us": timed["solve_us"],
                    "solves_per_step": timed["solves_per_step"],
                })  # fmt: skip
    return summarise(runs)


def summarise(runs: dict[str, list[dict[str, float]]]) -> pd.DataFrame:
    """Per way the medians over its pushes of the plain and the timed step, the contact
    solve and the timed step less it (``rest_us``), and the mean solves per step; then the
    figures of the module docstring, from each repeat's pair of pushes."""
    rows = []
    for way in WAYS:
        pushes = runs[way]
        rows.append({
            "way": way,
            "step_us": statistics.median(run["step_us"] for run in pushes),
            "clocked_step_us": statistics.median(run["clocked_step_us"] for run in pushes),
            "solve_us": statistics.median(run["solve_us"] for run in pushes),
            "rest_us": statistics.median(_rest(run) for run in pushes),
            "solves_per_step": statistics.fmean(run["solves_per_step"] for run in pushes),
            "pushes": len(pushes),
        })  # fmt: skip
    pairs = list(zip(runs["zero"], runs["acting"], strict=True))
    cuts = [
        solve_cut_needed(a["clocked_step_us"], a["solve_us"], z["clocked_step_us"], z["solve_us"])
        for z, a in pairs
    ]
    cuts = [math.inf if math.isnan(cut) else cut for cut in cuts]
    cut = statistics.median(cuts)
    figures = {
        "ratio": statistics.median(a["step_us"] / z["step_us"] for z, a in pairs),
        "ratio_solve_free": statistics.median(_rest(a) / _rest(z) for z, a in pairs),
        "solve_cut_needed": cut,
        "solve_speedup_needed": 1.0 / (1.0 - cut) if cut < 1.0 else math.inf,
        "unreachable": sum(math.isinf(cut) for cut in cuts),
    }
    return pd.concat([pd.DataFrame(rows), pd.DataFrame([{"way": "figures", **figures}])])


def _rest(run: dict[str, float]) -> float:
    """A timed push's step less its contact solve [µs per push step]."""
    return run["clocked_step_us"] - run["solve_us"]


def solve_cut_needed(step_a: float, solve_a: float, step_z: float, solve_z: float) -> float:
    """The fraction x of the contact solve's time, cut on both ways alike, at which the
    acting step ``step_a − x solve_a`` is :data:`TARGET` times the zero-residual step
    ``step_z − x solve_z`` [µs]: 0 if already within it, NaN if no x in [0, 1) does."""
    over = step_a - TARGET * step_z
    if over <= 0.0:
        return 0.0
    lever = solve_a - TARGET * solve_z
    x = over / lever if lever > 0.0 else math.inf
    return x if x < 1.0 else math.nan


def main(argv: list[str] | None = None) -> int:
    doc = (__doc__ or "").splitlines()[0]
    parser = argparse.ArgumentParser(prog="python -m pushctl.bench.solve_share", description=doc)
    parser.add_argument("--repeats", type=int, default=5, help="pushes each way, each made twice")
    parser.add_argument("--drawn", action="store_true", help="Push-v0's own scenarios")
    parser.add_argument("--out", type=Path, default=None, help="also write the table as CSV")
    parser.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    args = parser.parse_args(argv)
    if args.repeats < 1:
        print(f"error: --repeats must be an integer >= 1, got {args.repeats}", file=sys.stderr)
        return 2
    try:
        refuse_existing_files("--out", [args.out], args.force)
    except ConfigError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    table = study(args.repeats, args.drawn)
    with pd.option_context("display.width", 160, "display.max_columns", 20):
        print(table.to_string(index=False, float_format=lambda v: f"{v:.4g}", na_rep=""))
    if args.out is not None:
        drawn = " --drawn" if args.drawn else ""
        command = f"python -m pushctl.bench.solve_share --repeats {args.repeats}{drawn}"
        write_csv(args.out, table, provenance_line(command))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""``make bench``'s side-by-side timing: this tree against a reference commit, in one run.

Run as ``python -m pushctl.bench.compare [--against 551bcac] [--repeats 5] [--out FILE]
[--force]``. Timings on a shared machine drift by tens of percent from minute to minute, so
a speed claim is a ratio measured side by side: the reference commit's ``pushctl/`` (and
``experiments/``) is unpacked with ``git archive`` into a temporary directory, and each
repeat runs one fresh child process per tree, alternating which goes first, pinned to one
core (``taskset -c 0`` where it exists). Each child times, on the same inputs:

- ``world step``: the arm pushing the cube at 1 cm/s (:func:`pushctl.bench.suite._pushing_world`),
  median of 2000 steps [µs] (issue 15's item 2); and the same on other scenes, median of
  400 steps (20 cm of pushing at 5 cm/s): the cube at 5 cm/s, the wedge at 1 and 5 cm/s,
  and the free arm holding itself up under its own gravity torque, the cube far away (no
  prong contact);
- ``cold MLCP``: ``solve_box_mlcp`` on the cold-path problems (the warm active set failed)
  recorded from random-action ``Push-v0`` steps in this tree, median over problems of each
  problem's median of 5 solves [µs];
- ``cold MLCP, ProxQP path of the reference``: the same over the problems the reference
  solved with its ProxQP fixed point (the ~400 µs path of issue 15);
- ``env step, zero residual`` and ``env step, random actions``: ``Push-v0`` steps on one
  wedge chirp push, median [µs];
- ``unknowns: …``: the training environment with the plant unknowns on (the default ``sim``
  plant: the pusher's mounting error, the friction field), ``action_repeat`` 10 and the
  offset observed, on the same three 6 s pushes (scenario seeds 0-2 of the training
  stream, cube and wedge), mean time per push step [µs]: ``gate shut`` (zero actions),
  ``gate open`` (random actions every step) and ``feedback law`` (``finish_with_policy``
  with the feedback actor, as the evaluation pushes); ``unknowns: controller terms`` the
  median of :meth:`Episode.controller_terms` on a mounted pusher whose plate centre agrees
  with the nominal one to the bit (scenario seed 0) and ``…, own g`` one where it does not
  (seed 3) [µs]. NaN where the reference tree lacks these settings.

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
from pushctl.output_guard import refuse_existing_files
from pushctl.provenance import git_commit, provenance_line, write_csv

REFERENCE = "551bcac"
"""The commit issue 15 measures against."""

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

_CHILD = r"""
import json, pickle, statistics, sys, time
import numpy as np
try:  # the reference tree may predate pushctl/bench/ (a module then)
    from pushctl.bench.suite import _pushing_world
except ImportError:
    from pushctl.bench import _pushing_world
import pushctl
from pushctl.contact.mlcp import solve_box_mlcp
from pushctl.rl.env import PushEnv
from pushctl.rl.env_config import EnvConfig

def median_us(samples):
    return 1e6 * statistics.median(samples)

def world_steps(world, torque, kv, n=2000):
    # n steps' times [s], the torque computed outside each
    steps = []
    for _ in range(n):
        tau = torque()
        start = time.perf_counter()
        world.step(tau, implicit_kv=kv)
        steps.append(time.perf_counter() - start)
    return steps

def free_arm():
    # the arm alone, the cube far away: the arm holds itself up under its own g(q)
    world = pushctl.make_world(object="cube")
    world.reset(object_pose=(3.0, 3.0, 0.0))
    return world, world.gravity_torque, 5.0

steps = world_steps(*_pushing_world("cube"))
scenes = {
    "world step, cube at 5 cm/s": _pushing_world("cube", 0.05),
    "world step, wedge at 1 cm/s": _pushing_world("wedge", 0.01),
    "world step, wedge at 5 cm/s": _pushing_world("wedge", 0.05),
    "world step, free arm": free_arm(),
}
# 400 steps each: 20 cm of pushing at 5 cm/s, as the bench's 2000 steps at 1 cm/s
scene_us = {name: median_us(world_steps(*scene, n=400)) for name, scene in scenes.items()}

with open(sys.argv[1], "rb") as handle:
    problems = pickle.load(handle)
for D, b, lo, hi, findex, mu, warm in problems:  # warm-up (and numba's first calls)
    solve_box_mlcp(D, b, lo, hi, findex, mu, warm_start=warm, validate=False)
cold, methods = [], []
for D, b, lo, hi, findex, mu, warm in problems:
    times = []
    for _ in range(5):
        start = time.perf_counter()
        result = solve_box_mlcp(D, b, lo, hi, findex, mu, warm_start=warm, validate=False)
        times.append(time.perf_counter() - start)
    cold.append(statistics.median(times))
    methods.append(result.method)

def env_steps(random):
    env = PushEnv(EnvConfig(duration=6.0, gate_threshold=0.0))
    env.reset(seed=3, options={"object": "wedge", "profile": "chirp"})
    rng = np.random.default_rng(0)
    times = []
    for _ in range(600):
        action = rng.uniform(-1, 1, 3) if random else np.zeros(3)
        start = time.perf_counter()
        env.step(action.astype(np.float32))
        times.append(time.perf_counter() - start)
    return times

def unknowns_push_us(mode):
    # mean time per push step [us] of three training pushes with the plant unknowns
    try:
        from pushctl.control.feedback import load_feedback_gains
        from pushctl.rl.feedback_actor import FeedbackActor
        from pushctl.rl.policy import finish_with_policy
        gate = {"shut": {"gate_threshold": 1.0}, "open": {"gate_threshold": 0.0}}.get(mode, {})
        config = EnvConfig(action_repeat=10, observe_offset=True, duration=6.0, **gate)
    except (ImportError, TypeError):
        return float("nan")
    env = PushEnv(config)
    rng = np.random.default_rng(0)
    zero = np.zeros(3, dtype=np.float32)
    total, steps = 0.0, 0
    for seed, obj in ((0, "wedge"), (1, "cube"), (2, "wedge")):
        env.reset(options={"object": obj, "profile": "chirp", "scenario_seed": seed})
        episode = env.episode
        start = time.perf_counter()
        if mode == "feedback":
            finish_with_policy(env, FeedbackActor(env, load_feedback_gains()))
        else:
            while not episode.done:
                action = rng.uniform(-1, 1, 3).astype(np.float32) if mode == "open" else zero
                env.step(action)
        total += time.perf_counter() - start
        steps += episode.n_steps
    return 1e6 * total / steps

def controller_terms_us(seed):
    # median of Episode.controller_terms [us] on a mounted pusher (scenario seed)
    try:
        env = PushEnv(EnvConfig(duration=2.0))
    except TypeError:
        return float("nan")
    env.reset(options={"object": "cube", "profile": "chirp", "scenario_seed": seed})
    episode = env.episode
    # a reference tree before the controller's own arm model (551bcac) has no such terms
    if getattr(episode, "controller_arm", episode.world.arm) is episode.world.arm:
        return float("nan")
    times = []
    for _ in range(2000):
        start = time.perf_counter()
        episode.controller_terms()
        times.append(time.perf_counter() - start)
    return median_us(times)

env_steps(True)  # warm-up
unknowns_push_us("shut")
print(json.dumps({
    "world step": median_us(steps),
    **scene_us,
    "cold MLCP": median_us(cold),
    "cold_each": cold,
    "methods": methods,
    "env step, zero residual": median_us(env_steps(False)),
    "env step, random actions": median_us(env_steps(True)),
    "unknowns: env step, gate shut": unknowns_push_us("shut"),
    "unknowns: env step, gate open": unknowns_push_us("open"),
    "unknowns: feedback law push": unknowns_push_us("feedback"),
    "unknowns: controller terms": controller_terms_us(0),
    "unknowns: controller terms, own g": controller_terms_us(3),
}))
"""


def record_cold_problems(steps: int = 1500, seed: int = 0) -> list[tuple]:
    """The MLCPs whose warm active set failed (the ones that reach the cold path, which
    :func:`solve_box_mlcp` times) during ``steps`` random-action ``Push-v0`` steps of this
    tree: (D, b, lo, hi, findex, mu, warm_start) each."""
    import pushctl.contact.substep as world_module  # where the world step calls the solver
    from pushctl.contact.cold_step import HELD
    from pushctl.contact.kernels import assemble
    from pushctl.rl.env import PushEnv
    from pushctl.rl.env_config import EnvConfig

    recorded: list[tuple] = []
    solve = world_module.cold_contact_step
    # every solve of the cold path as its own cold_contact_step call (the compiled step,
    # slip_step, and the compiled loop, cold_slip_step, make the same calls inside one): the
    # step made in parts, its cold loop in Python
    compiled_step = world_module.SubstepSolver._compiled_step
    cold_path = world_module.SubstepSolver._cold_path
    python_loop = world_module.SubstepSolver._cold_path_in_python

    def in_parts(self, inputs, prongs, guess):
        return None

    def record(*args):
        solved = solve(*args)
        guess, has_guess = args[18], args[19]
        if not (has_guess and solved[0] == HELD):
            D, b, lo, hi, findex, mu, *_ = assemble(*args[:18])
            warm = guess.copy() if has_guess else None
            recorded.append((D, b, lo, hi, findex, mu, warm))
        return solved

    world_module.cold_contact_step = record  # type: ignore[assignment]
    world_module.SubstepSolver._compiled_step = in_parts  # type: ignore[method-assign]
    world_module.SubstepSolver._cold_path = python_loop  # type: ignore[method-assign]
    try:
        env = PushEnv(EnvConfig(duration=6.0, gate_threshold=0.0))
        rng = np.random.default_rng(seed)
        env.reset(seed=seed)
        for i in range(steps):
            _, _, terminated, truncated, _ = env.step(rng.uniform(-1, 1, 3).astype(np.float32))
            if terminated or truncated:
                env.reset(seed=seed + i + 1)
    finally:
        world_module.cold_contact_step = solve  # type: ignore[assignment]
        world_module.SubstepSolver._compiled_step = compiled_step  # type: ignore[method-assign]
        world_module.SubstepSolver._cold_path = cold_path  # type: ignore[method-assign]
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
    (:mod:`pushctl.native`, from 3c3f472 on) the library it would run with: ``git archive``
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
        [sys.executable, "-c", "from pushctl.native.build import build; print(build(optional=True))"],
        env={**os.environ, "PYTHONPATH": str(tree)},
        cwd=tree,
        check=False,
    )


def run_child(tree: Path, problems: Path, core: int = 0) -> dict[str, Any]:
    """One child process timing the tree at ``tree`` (its ``pushctl`` first on the path),
    pinned to ``core``."""
    pin = ["taskset", "-c", str(core)] if shutil.which("taskset") else []
    env = {**os.environ, "PYTHONPATH": str(tree)}
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

    The machine's speed drifts over minutes (on a shared AMD EPYC, 2026-11-25, the ratio of
    the two trees' medians gave 0.55-0.73 for code the two trees share); a pair's two
    children see about the same machine, so the drift cancels in their ratio."""
    return statistics.median(ours / theirs for ours, theirs in zip(this, reference, strict=True))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m pushctl.bench.compare", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--against", default=REFERENCE, help="reference commit (git)")
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


if __name__ == "__main__":
    raise SystemExit(main())

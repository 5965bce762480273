"""cProfile of the training environment with the plant unknowns, as training and evaluation
step it (docs/performance.md).

Run as ``python -m benchmarks.profile_env [shut|open|feedback|train] [--pushes N]
[--top K]``: N pushes of the training stream (seeds 0…N−1) on the ``sim`` plant (its plant
unknowns on, as in training). ``shut``, ``open`` and ``feedback`` push
``PushEnv(EnvConfig(action_repeat=10, observe_offset=True))``, the training environment
before the ``paper`` preset added its base law: with the gate ``shut`` (zero actions),
``open`` (gate threshold 0, uniform random actions) or the ``feedback`` law pushing through
:func:`~pushctl.rl.policy.finish_with_policy` as the evaluation does. ``train`` pushes the
``paper`` preset's own environment (``pushctl/defaults/train_paper.toml``: the feedback law acting
every step, a residual of uniform random actions added every 10 steps), which is what a
``paper`` run's collectors step. The pushes run once unprofiled first (numba's caches, and
the rate without the profiler's overhead), then under cProfile with the resets left out;
prints both rates and the profile's top K functions by own time and by cumulative time.

With ``--sampled`` the second run is not under cProfile either, and only the two rates are
printed: for a sampling profiler attached from outside, which does not inflate short calls
as cProfile does (``py-spy record -r 3000 -f raw -o samples.txt -- python -m
benchmarks.profile_env train --sampled``).
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import sys
import time
from dataclasses import replace

import numpy as np

from pushctl.control.feedback import load_feedback_gains
from pushctl.rl.policy import finish_with_policy
from pushctl.rl.presets import load_preset
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.feedback_actor import FeedbackActor

MODES = ("shut", "open", "feedback", "train")


def environment_config(mode: str) -> EnvConfig:
    """The environment ``mode`` pushes (see the module doc)."""
    if mode == "train":
        return load_preset("paper").env
    config = EnvConfig(action_repeat=10, observe_offset=True)
    if mode == "feedback":
        return config
    return replace(config, gate_threshold=1.0 if mode == "shut" else 0.0)


def push_steps_per_s(mode: str, pushes: int, profile: cProfile.Profile | None = None) -> float:
    """Push steps per second of ``pushes`` pushes in ``mode`` (resets not timed nor
    profiled)."""
    env = PushEnv(environment_config(mode))
    zero = np.zeros(3, dtype=np.float32)
    acting = mode in ("open", "train")
    elapsed, steps = 0.0, 0
    for seed in range(pushes):
        env.reset(seed=seed)
        episode = env.episode
        assert episode is not None
        rng = np.random.default_rng(seed)
        start = time.perf_counter()
        if profile is not None:
            profile.enable()
        if mode == "feedback":
            finish_with_policy(env, FeedbackActor(env, load_feedback_gains()))
        else:
            while not episode.done:
                env.step(rng.uniform(-1, 1, 3).astype(np.float32) if acting else zero)
        if profile is not None:
            profile.disable()
        elapsed += time.perf_counter() - start
        steps += episode.n_steps
    return steps / elapsed


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m benchmarks.profile_env", description=__doc__.splitlines()[0]
    )
    parser.add_argument("mode", choices=MODES)
    parser.add_argument("--pushes", type=int, default=3)
    parser.add_argument("--top", type=int, default=25)
    parser.add_argument("--sampled", action="store_true", help="no cProfile (see the doc)")
    args = parser.parse_args(argv)
    if args.pushes < 1 or args.top < 1:
        print("error: --pushes and --top must be integers >= 1", file=sys.stderr)
        return 2
    rate = push_steps_per_s(args.mode, args.pushes)
    if args.sampled:
        again = push_steps_per_s(args.mode, args.pushes)
        print(f"{args.mode}: {rate:.0f} push steps/s, then {again:.0f} (kernels loaded)")
        return 0
    profile = cProfile.Profile()
    profiled = push_steps_per_s(args.mode, args.pushes, profile)
    print(f"{args.mode}: {rate:.0f} push steps/s ({profiled:.0f} under cProfile)")
    stats = pstats.Stats(profile)
    stats.sort_stats("tottime").print_stats(args.top)
    stats.sort_stats("cumulative").print_stats(args.top)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

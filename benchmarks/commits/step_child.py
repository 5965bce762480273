"""The child process of :mod:`benchmarks.commits.step`: run as ``python -c`` with its text,
in the tree it times (that tree's ``pushctl`` first on the path), the recorded cold problems'
pickle as its argument; prints one JSON line of medians [µs]."""

import json
import pickle
import statistics
import sys
import time

import numpy as np

try:  # this checkout; an older tree had the benchmarks inside the package
    from benchmarks.suite import _pushing_world
except ImportError:
    try:
        from pushctl.bench.suite import _pushing_world
    except ImportError:
        from pushctl.bench import _pushing_world
import pushctl
from pushctl.contact.mlcp import solve_box_mlcp
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig


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
        from pushctl.rl.policy import finish_with_policy
        from pushctl.task.feedback_actor import FeedbackActor

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
    # a reference tree before the controller's own arm model has no such terms
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
print(
    json.dumps(
        {
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
        }
    )
)

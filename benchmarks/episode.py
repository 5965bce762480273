"""``make bench``, closed loop: wall time of PD episodes and where a control step's time goes.

Part of :mod:`benchmarks.suite`. The episode is the README's example push (cube and wedge,
chirp, to (0.62, 0.03, 30 deg)) with the shipped gains; times are medians over repeats on
one core, after one warm-up episode (numba's compiled kernels load from the disk cache).
The cube's push is also timed on the reality proxy (its actuators' latency and joint
friction, its camera), its pushes interleaved with the simulator's so that the ratio of the
two is taken side by side.
"""

from __future__ import annotations

import cProfile
import io
import pstats
import statistics
import time
from typing import Any

from pushctl.control import load_gains
from pushctl.episode import Episode, Scenario
from pushctl.episode.proxy import ProxyEffects
from pushctl.types import PlanarPose

GOAL = PlanarPose.from_degrees(0.62, 0.03, 30.0)


def _episode(object_name: str, effects: ProxyEffects | None = None) -> Episode:
    scenario = Scenario(object=object_name, profile="chirp", goal=GOAL)
    return Episode(scenario, gains=load_gains(), effects=effects)


def _push_seconds(episode: Episode) -> float:
    episode.reset()
    start = time.perf_counter()
    for _ in range(episode.n_steps):
        episode.step()
    return time.perf_counter() - start


def _step_breakdown(episode: Episode) -> dict[str, float]:
    """Median µs per push step of the controller, the world step and the rest (the
    runner's bookkeeping), timed separately on one push."""
    episode.reset()
    controller, world, reference = episode.controller, episode.world, episode.reference
    twists = reference.twist
    control, stepping, total = [], [], []
    for n in range(episode.n_steps):
        t0 = time.perf_counter()
        terms = world.arm_terms
        assert terms is not None
        command = controller.command(
            terms, world.q, reference.position[n], reference.yaw[n], twists[n]
        )
        t1 = time.perf_counter()
        world.step(command.tau, implicit_kv=command.implicit_kv)
        t2 = time.perf_counter()
        control.append(t1 - t0)
        stepping.append(t2 - t1)
    episode.reset()
    for _ in range(episode.n_steps):
        t0 = time.perf_counter()
        episode.step()
        total.append(time.perf_counter() - t0)
    control_us = 1e6 * statistics.median(control)
    world_us = 1e6 * statistics.median(stepping)
    total_us = 1e6 * statistics.median(total)
    return {"controller": control_us, "world": world_us, "step": total_us}


def episode_rows(repeats: int = 5) -> list[dict[str, Any]]:
    """Bench rows: a 2000-step push [s] (median of ``repeats``), a whole episode with its
    plan and approach [s], and the per-step breakdown [µs]."""
    rows: list[dict[str, Any]] = []
    for name in ("cube", "wedge"):
        episode = _episode(name)
        _push_seconds(episode)  # warm-up
        push = statistics.median(_push_seconds(episode) for _ in range(repeats))
        whole = []
        for _ in range(max(1, repeats // 2)):
            start = time.perf_counter()
            _episode(name).run()
            whole.append(time.perf_counter() - start)
        breakdown = _step_breakdown(episode)
        note = f"{name}, chirp to (0.62, 0.03, 30 deg), PD with the shipped gains"
        rows += [
            {"name": f"episode {name} push 2000 steps", "value": push, "unit": "s", "note": note},
            {
                "name": f"episode {name} per control step",
                "value": 1e6 * push / episode.n_steps,
                "unit": "us",
                "note": "controller + world step + trace recording (target <= 150)",
            },
            {
                "name": f"episode {name} controller per step",
                "value": breakdown["controller"],
                "unit": "us",
                "note": "median: task error, damped pseudo-inverse IK, joint PD (compiled)",
            },
            {
                "name": f"episode {name} world step per step",
                "value": breakdown["world"],
                "unit": "us",
                "note": "median: arm terms, contacts, MLCP, integration",
            },
            {
                "name": f"episode {name} whole",
                "value": statistics.median(whole),
                "unit": "s",
                "note": "plan (forces, offset search, reach), plant force plan, world, "
                "3.2 s approach, 20 s push, trace",
            },
        ]
    return rows + proxy_rows(repeats)


def proxy_rows(repeats: int = 5) -> list[dict[str, Any]]:
    """Bench rows: a control step of the cube's push on the reality proxy and on the
    simulator [µs], their pushes alternating (median of ``repeats`` each), and the ratio."""
    episodes = {"sim": _episode("cube"), "proxy": _episode("cube", ProxyEffects())}
    seconds: dict[str, list[float]] = {plant: [] for plant in episodes}
    for episode in episodes.values():
        _push_seconds(episode)  # warm-up
    for _ in range(repeats):
        for plant, episode in episodes.items():
            seconds[plant].append(_push_seconds(episode))
    per_step = {
        plant: 1e6 * statistics.median(times) / episodes[plant].n_steps
        for plant, times in seconds.items()
    }
    note = "cube, chirp, PD; sim and proxy pushes alternating"
    return [
        {"name": "episode cube proxy per control step", "value": per_step["proxy"],
         "unit": "us", "note": f"{note}: latency, joint friction (compiled), camera"},
        {"name": "episode cube proxy / sim per control step",
         "value": per_step["proxy"] / per_step["sim"], "unit": "ratio", "note": note},
    ]  # fmt: skip


def profile_episode(top: int = 15) -> str:
    """cProfile of one 2000-step cube push (after a warm-up): where the time goes."""
    episode = _episode("cube")
    _push_seconds(episode)
    episode.reset()
    profiler = cProfile.Profile()
    profiler.enable()
    for _ in range(episode.n_steps):
        episode.step()
    profiler.disable()
    out = io.StringIO()
    pstats.Stats(profiler, stream=out).sort_stats("tottime").print_stats(top)
    lines = [line for line in out.getvalue().splitlines() if line.strip()]
    return "\n".join(lines[: top + 8])

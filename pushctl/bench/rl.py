"""Benchmark rows of the learning side (``make bench``): environment steps per second with the
gate shut and open, the actor's single-observation forward, and DDPG updates per second at
the ``paper`` preset's network size and batch."""

from __future__ import annotations

import statistics
import time
from dataclasses import replace
from typing import Any

import numpy as np

from pushctl.rl.ddpg import DDPGAgent, configure_torch
from pushctl.rl.env import PushEnv
from pushctl.rl.presets import load_preset
from pushctl.rl.spaces import observation_entries, scales

OPTIONS = {"object": "cube", "profile": "chirp", "scenario_seed": 0}


def _env_steps_per_s(env: PushEnv, act) -> float:
    """Push steps per second of one whole episode (reset not counted)."""
    obs, _ = env.reset(options=OPTIONS)
    assert env.episode is not None
    steps = env.episode.n_steps
    start = time.perf_counter()
    for _ in range(steps):
        obs, *_ = env.step(act(obs))
    return steps / (time.perf_counter() - start)


def rl_rows(preset_name: str = "paper", updates: int = 300) -> list[dict[str, Any]]:
    """Env steps/s (gate shut; gate open with the actor acting), actor forward [µs], DDPG
    update [ms] and updates/s, with the preset's settings and one torch thread."""
    configure_torch(1)
    preset = load_preset(preset_name)
    entries = observation_entries(2, reference_offset=preset.env.offset_observed)
    agent = DDPGAgent(len(entries), 3, preset.ddpg, seed=0, obs_scale=scales(entries))
    zero = np.zeros(3)
    shut = _env_steps_per_s(PushEnv(replace(preset.env, gate_threshold=1.0)), lambda obs: zero)
    opened = PushEnv(replace(preset.env, gate_threshold=0.0))
    acting = _env_steps_per_s(opened, lambda obs: agent.policy_action(obs.astype(np.float64)))

    obs = np.linspace(-1.0, 1.0, len(entries))
    forward = []
    for _ in range(2000):
        start = time.perf_counter()
        agent.policy_action(obs)
        forward.append(time.perf_counter() - start)

    rng = np.random.default_rng(0)
    n = 4 * preset.ddpg.batch_size
    agent.observe(
        rng.normal(size=(n, len(entries))).astype(np.float32),
        rng.uniform(-1.0, 1.0, size=(n, 3)).astype(np.float32),
        rng.normal(size=n).astype(np.float32),
        rng.normal(size=(n, len(entries))).astype(np.float32),
        np.zeros(n, dtype=np.float32),
    )
    for _ in range(20):
        agent.update()  # warm-up
    start = time.perf_counter()
    for _ in range(updates):
        agent.update()
    update_s = (time.perf_counter() - start) / updates

    hidden = "x".join(str(width) for width in preset.ddpg.hidden)
    net = f"MLP {hidden}, batch {preset.ddpg.batch_size}, one torch thread"
    return [
        {
            "name": "rl env steps/s, gate shut",
            "value": shut,
            "unit": "1/s",
            "note": "pushctl/Push-v0, cube chirp, PD only: observation and eq. 17 reward",
        },
        {
            "name": "rl env steps/s, gate open, actor acting",
            "value": acting,
            "unit": "1/s",
            "note": f"as above, gate always open, the untrained actor (zero output) queried "
            f"every step; {net}",
        },
        {
            "name": "rl actor forward, one observation",
            "value": 1e6 * statistics.median(forward),
            "unit": "us",
            "note": net,
        },
        {
            "name": "rl DDPG update",
            "value": 1e3 * update_s,
            "unit": "ms",
            "note": f"critic + actor step + soft target updates; {net}",
        },
        {
            "name": "rl DDPG updates/s",
            "value": 1.0 / update_s,
            "unit": "1/s",
            "note": f"{net}; the paper preset does {preset.ddpg.updates_per_step} per env step",
        },
    ]

"""Benchmark rows of the learning side (``make bench``): environment steps per second with the
gate shut and open, the actor's single-observation forward, DDPG updates per second at
the ``paper`` preset's network size and batch, and training collection beside raw stepping
(:func:`collection_rows`)."""

from __future__ import annotations

import statistics
import time
from dataclasses import replace
from typing import Any

import numpy as np

from benchmarks.engines import pinned_to_one_core
from pushctl.control.gains import load_gains
from pushctl.rl.collect import Behaviour, collect_episodes, episode_rngs, portable
from pushctl.rl.ddpg import DDPGAgent, configure_torch
from pushctl.rl.presets import load_preset
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.spaces import observation_entries, scales
from pushctl.task.vector_env import PushVectorEnv

OPTIONS = {"object": "cube", "profile": "chirp", "scenario_seed": 0}


def _env_steps_per_s(env: PushEnv, act, seed: int | None = None) -> float:
    """Push steps per second of one whole episode (reset not counted); a step() holds its
    action for ``action_repeat`` push steps. The episode is :data:`OPTIONS`' scenario, or
    with a ``seed`` the one ``env.reset(seed=seed)`` draws."""
    obs, _ = env.reset(options=OPTIONS) if seed is None else env.reset(seed=seed)
    episode = env.episode
    assert episode is not None
    start = time.perf_counter()
    while not episode.done:
        obs, *_ = env.step(act(obs))
    return episode.n_steps / (time.perf_counter() - start)


def rl_rows(preset_name: str = "paper", updates: int = 300) -> list[dict[str, Any]]:
    """Env steps/s (gate shut; gate open with the actor acting), actor forward [µs], DDPG
    update [ms] and updates/s, with the preset's settings and one torch thread."""
    configure_torch(1)
    preset = load_preset(preset_name)
    entries = observation_entries(
        2, reference_offset=preset.env.offset_observed, context=preset.env.observe_context
    )
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
        *collection_rows(preset_name=preset_name),
    ]


def collection_rows(
    episodes: int = 4,
    repeats: int = 3,
    preset_name: str = "paper",
    acting_repeats: int = 9,
    scenarios: int = 8,
):
    """Training collection beside raw stepping, side by side on one core (pinned), the
    repeats interleaved, medians of the per-repeat ratios:

    - raw: the ``episodes`` of a round pushed by a PushEnv with zero actions, resets included;
    - collection: the same episodes by :func:`~pushctl.rl.collect.collect_episodes`, stepped
      together (one batched forward of the preset's actor, plus its OU noise, per step),
      resets, transitions and curve metrics included; and one at a time, as before;
    - an acting step (uniform random actions, gate open: prongs slip) against a zero-residual
      step of the same push, resets excluded: in the preset's environment (a decision every
      ``action_repeat`` push steps), and in ``Push-v0``'s defaults (a decision every step),
      where the actions jolt the prongs most often. One push each way per repeat,
      alternating, ``acting_repeats`` times (each repeat's actions from its own seed), after
      one untimed push each way (numba loads the cold path's kernels at its first use); the
      note gives the quartiles: three repeats of whole pushes spread by 1.7× between runs;
    - the same ratio over ``scenarios`` of the scenarios ``Push-v0`` itself draws (its
      defaults all through, the gate's too: ``reset(seed=s)`` for s = 0 … scenarios − 1
      picks the object, the profile and the scenario, as ``gymnasium.make`` gives it), one
      pair of pushes each: the one scenario above is one draw from a wide spread.
    """
    configure_torch(1)
    preset = load_preset(preset_name)
    config, gains = preset.env, load_gains()
    ddpg = replace(preset.ddpg, actor_final_init=3e-3)  # an actor whose output is not 0
    entries = observation_entries(
        2, reference_offset=config.offset_observed, context=config.observe_context
    )
    agent = DDPGAgent(len(entries), 3, ddpg, seed=0, obs_scale=scales(entries))
    behaviour = Behaviour(
        False, portable(agent.actor_state()), ddpg.ou_theta, ddpg.ou_sigma, ddpg.ou_dt
    )
    raw_env, together = PushEnv(config, gains), PushVectorEnv(episodes, config, gains)
    alone = PushVectorEnv(1, config, gains)
    gate_open = PushEnv(replace(config, gate_threshold=0.0), gains)
    every_step = PushEnv(EnvConfig(gate_threshold=0.0), gains)  # Push-v0's defaults
    ratios: dict[str, list[float]] = {"together": [], "alone": []}
    rates: dict[str, list[float]] = {"raw": [], "together": [], "alone": []}
    with pinned_to_one_core():
        for repeat in range(repeats):
            round_ = list(range(1000 + repeat * episodes, 1000 + (repeat + 1) * episodes))
            raw = _rate(_raw_steps, raw_env, round_)
            batched = _rate(_collected_steps, together, round_, behaviour)
            single = _rate(_collected_alone, alone, round_, behaviour)
            for key, value in (("raw", raw), ("together", batched), ("alone", single)):
                rates[key].append(value)
            ratios["together"].append(batched / raw)
            ratios["alone"].append(single / raw)
        ratios["acting"] = _acting_ratios(gate_open, acting_repeats)
        ratios["every"] = _acting_ratios(every_step, acting_repeats)
        ratios["drawn"] = _acting_ratios(PushEnv(EnvConfig(), gains), scenarios, drawn=True)
    median = statistics.median
    where = f"{preset_name} preset env, {episodes} episodes a round, one core, {repeats} repeats"
    return [
        {
            "name": "rl raw env steps/s, resets included",
            "value": median(rates["raw"]),
            "unit": "1/s",
            "note": f"PushEnv, zero actions; {where}",
        },
        {
            "name": "rl collection env steps/s, episodes together",
            "value": median(rates["together"]),
            "unit": "1/s",
            "note": "collect_episodes: batched actor + OU noise, transitions, curve metrics",
        },
        {
            "name": "rl collection / raw env-step rate",
            "value": median(ratios["together"]),
            "unit": "ratio",
            "note": f"episodes together (goal >= 0.5); one at a time: "
            f"{median(ratios['alone']):.3f}",
        },
        {
            "name": "rl acting step / zero-residual step",
            "value": median(ratios["acting"]),
            "unit": "ratio",
            "note": f"cube chirp, gate open, uniform random actions vs zeros, {preset_name} "
            f"preset env (a decision every {config.action_repeat} push steps; goal <= 1.3); "
            + _quartiles(ratios["acting"]),
        },
        {
            "name": "rl acting step / zero-residual step, Push-v0 defaults",
            "value": median(ratios["every"]),
            "unit": "ratio",
            "note": "as above, a decision every push step (goal <= 1.3); "
            + _quartiles(ratios["every"]),
        },
        {
            "name": "rl acting step / zero-residual step, Push-v0's own scenarios",
            "value": median(ratios["drawn"]),
            "unit": "ratio",
            "note": f"Push-v0's defaults, reset(seed=s) for s < {scenarios}: its drawn object, "
            f"profile and scenario, one pair of pushes each (goal <= 1.3); "
            f"{min(ratios['drawn']):.2f}-{max(ratios['drawn']):.2f} over the scenarios",
        },
    ]


def _acting_ratios(env: PushEnv, repeats: int, drawn: bool = False) -> list[float]:
    """Per repeat r, a zero-residual push's step rate over an acting push's (uniform random
    actions from r's own generator), the two pushed one after the other: of the scenario
    :data:`OPTIONS`, or with ``drawn`` of the one ``env.reset(seed=r)`` draws. One untimed
    push each way first."""
    zero = np.zeros(3)

    def still(obs: np.ndarray) -> np.ndarray:
        return zero

    def acting(seed: int):
        rng = np.random.default_rng(seed)
        return lambda obs: rng.uniform(-1.0, 1.0, 3)

    def rate(act, repeat: int) -> float:
        return _env_steps_per_s(env, act, repeat if drawn else None)

    rate(still, repeats)
    rate(acting(repeats), repeats)
    return [rate(still, repeat) / rate(acting(repeat), repeat) for repeat in range(repeats)]


def _quartiles(values: list[float]) -> str:
    low, high = np.percentile(values, [25, 75])
    return f"quartiles {low:.2f}-{high:.2f} of {len(values)} alternating repeats"


def _raw_steps(env: PushEnv, episodes: list[int]) -> int:
    """Push steps (not decisions: a step() holds its action ``action_repeat`` of them)."""
    steps = 0
    zero = np.zeros(3)
    for episode in episodes:
        env.reset(seed=episode_rngs(0, episode)[0])
        assert env.episode is not None
        while not env.episode.done:
            env.step(zero)
        steps += env.episode.n_steps
    return steps


def _collected_steps(vector: PushVectorEnv, episodes: list[int], behaviour: Behaviour) -> int:
    """Push steps of collecting ``episodes`` together."""
    collect_episodes(vector, 0, episodes, behaviour)
    return sum(env.episode.n_steps for env in vector.envs if env.episode is not None)


def _collected_alone(vector: PushVectorEnv, episodes: list[int], behaviour: Behaviour) -> int:
    return sum(_collected_steps(vector, [episode], behaviour) for episode in episodes)


def _rate(run, *args: Any) -> float:
    """Steps per second of ``run(*args)``, which returns the steps it took."""
    start = time.perf_counter()
    steps = run(*args)
    return steps / (time.perf_counter() - start)


if __name__ == "__main__":  # python -m benchmarks.rl: the collection rows alone
    for row in collection_rows():
        print(f"{row['name']}: {row['value']:.3f} {row['unit']} ({row['note']})")

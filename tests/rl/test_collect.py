"""Batched collection: episodes stepped together in a vector env (one batched actor forward
per step) leave the same records, bit for bit, as each episode run alone; the training
curve's PD-only push runs on the episode's plant."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from pushctl.control.gains import load_gains
from pushctl.episode.runner import Episode
from pushctl.errors import StateError
from pushctl.rl.collect import (
    Behaviour,
    _curve_metrics,
    collect_episode,
    collect_episodes,
    pd_only_metrics,
    portable,
)
from pushctl.rl.env import PushEnv
from pushctl.rl.env_config import EnvConfig
from pushctl.rl.networks import Actor, ActorPolicy, initialise
from pushctl.rl.policy import pd_only_episode
from pushctl.rl.spaces import observation_entries, scales
from pushctl.rl.vector_env import PushVectorEnv

SHORT = EnvConfig(
    duration=0.4, objects=("cube", "wedge"), profiles=("constant",), gate_threshold=0.0
)


def _acting() -> Behaviour:
    entries = observation_entries(2)
    actor = Actor(len(entries), 3, (32, 32))
    initialise(actor, torch.Generator().manual_seed(3), final_bound=0.5)  # actions far from 0
    state = ActorPolicy(actor.eval(), scales(entries)).state()
    return Behaviour(False, portable(state), ou_theta=0.15, ou_sigma=0.05, ou_dt=1.0)


def test_episodes_stepped_together_equal_each_episode_alone() -> None:
    gains = load_gains()
    behaviour = _acting()
    episodes = [4, 9, 10]
    together = collect_episodes(PushVectorEnv(3, SHORT, gains), 11, episodes, behaviour)
    for record, episode in zip(together, episodes, strict=True):
        alone = collect_episode(SHORT, gains, 11, episode, behaviour)
        assert record.episode == episode
        assert record.scenario == alone.scenario
        assert record.rl == alone.rl
        assert record.episode_return == alone.episode_return
        for key, rows in alone.transitions.items():
            assert record.transitions[key].tobytes() == rows.tobytes(), key
    # the actor acted: applied actions are large, and they differ between episodes
    actions = [record.transitions["action"] for record in together]
    assert np.abs(actions[0]).max() > 0.1
    assert not np.array_equal(actions[0], actions[1])


def test_the_pd_only_curve_push_runs_on_the_episodes_plant() -> None:
    # A proxy-trained preset: PD-only must push with the proxy's effects, as the RL episode.
    config = EnvConfig(duration=1.0, objects=("cube",), profiles=("constant",), plant="proxy")
    env = PushEnv(config, load_gains())
    metrics = pd_only_metrics(env, 5, 2)
    fresh = Episode(env.scenario, env.gains, plan=env.plan, effects=env.effects, engine=env.engine)
    assert metrics == _curve_metrics(fresh.run())
    without = _curve_metrics(Episode(env.scenario, env.gains, plan=env.plan).run())
    assert metrics != without
    env.step(np.zeros(3))
    with pytest.raises(StateError):
        pd_only_episode(env)  # only from an episode just reset

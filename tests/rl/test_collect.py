"""Batched collection: episodes stepped together in a vector env (one batched actor forward
per step) leave the same records, bit for bit, as each episode run alone."""

from __future__ import annotations

import numpy as np
import torch

from pushctl.control.gains import load_gains
from pushctl.rl.collect import Behaviour, collect_episode, collect_episodes, portable
from pushctl.rl.env_config import EnvConfig
from pushctl.rl.networks import Actor, ActorPolicy, initialise
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

"""Batched collection: episodes stepped together in a vector env (one batched actor forward
per step) leave the same records, bit for bit, as each episode run alone; the training
curve's PD-only push runs on the episode's plant, and pushed from the RL episode's reset it
is bit for bit the push after a reset of its own."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import torch

from pushctl.control.feedback import load_feedback_gains
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
from pushctl.rl.networks import Actor, ActorPolicy, initialise
from pushctl.rl.policy import pd_only_episode
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.spaces import observation_entries, scales
from pushctl.task.vector_env import PushVectorEnv

SHORT = EnvConfig(
    duration=0.4, objects=("cube", "wedge"), profiles=("constant",), gate_threshold=0.0
)


def _acting() -> Behaviour:
    entries = observation_entries(2, reference_offset=SHORT.offset_observed)
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


@pytest.mark.parametrize("plant", ["sim", "proxy"])
def test_the_pd_only_push_from_the_rl_episodes_reset_is_the_learners(plant: str) -> None:
    config = replace(SHORT, plant=plant)
    gains = load_gains()
    records = collect_episodes(PushVectorEnv(3, config, gains), 7, [4, 5, 6], _acting(), [4, 6])
    assert [record.pd is not None for record in records] == [True, False, True]
    alone = PushEnv(config, gains)
    for record in (records[0], records[2]):
        assert record.pd == pd_only_metrics(alone, 7, record.episode)
        assert record.pd != record.rl  # the actor acted; PD-only did not
    # and the RL episode is the same whether PD-only is pushed beside it or not
    without = collect_episodes(PushVectorEnv(3, config, gains), 7, [4, 5, 6], _acting())
    for a, b in zip(records, without, strict=True):
        assert a.rl == b.rl and a.episode_return == b.episode_return


@pytest.mark.parametrize("demonstrated", [False, True])
def test_held_actions_and_the_demonstrated_warm_up_batch_as_they_run_alone(demonstrated) -> None:
    # a decision every 4 steps (one transition each), the feedback law acting in warm-up
    config = replace(SHORT, action_repeat=4)
    gains = load_gains()
    if demonstrated:
        behaviour = Behaviour(True, None, 0.15, 0.05, 1.0, demonstrator=load_feedback_gains())
    else:
        behaviour = _acting()
    together = collect_episodes(PushVectorEnv(2, config, gains), 3, [0, 1], behaviour)
    for record in together:
        alone = collect_episode(config, gains, 3, record.episode, behaviour)
        assert len(record.transitions["reward"]) == 10  # 40 steps, 4 per decision
        for key, rows in alone.transitions.items():
            assert record.transitions[key].tobytes() == rows.tobytes(), key
        assert record.rl == alone.rl
    if not demonstrated:  # (the law's twist is zero this early in a 0.4 s push)
        assert np.abs(together[0].transitions["action"]).max() > 0.0


def test_the_contact_hold_drops_the_policy_while_a_prong_is_off(monkeypatch) -> None:
    """``policy_holds_off_contact``: on a step where a prong reads below the hold force the
    policy's action is dropped and stored as zero; the push is then PD-only's."""
    held = replace(SHORT, base_law="none", policy_gated=False, policy_holds_off_contact=True)
    record = collect_episode(held, load_gains(), 5, 0, _acting())
    applied = np.abs(record.transitions["action"]).sum(axis=1) > 0.0
    assert applied.any()  # once the prongs carry load, the actions are applied
    monkeypatch.setattr("pushctl.task.env.HOLD_FORCE", 1e9)  # every prong reads as off
    record = collect_episode(held, load_gains(), 5, 0, _acting())
    assert np.all(record.transitions["action"] == 0.0)
    env = PushEnv(held, load_gains())
    env.reset(seed=5, options={"object": "cube", "profile": "constant"})
    pd_env = PushEnv(held, load_gains())
    pd_env.reset(seed=5, options={"object": "cube", "profile": "constant"})
    for _ in range(5):
        _, _, _, _, info = env.step(np.ones(3))
        pd_env.step(np.zeros(3))
        assert not info["action_applied"].any()
    np.testing.assert_array_equal(env.observation(), pd_env.observation())


def test_an_action_the_gate_dropped_is_stored_as_zero() -> None:
    """On a base law that gates itself (the default feedback law's), with the gate on the
    policy, the law acts at every step but the policy only while the gate is open: a
    decision taken with the gate shut applied nothing of the policy's, and is stored so."""
    assert load_feedback_gains().owns_gate
    shut = replace(SHORT, base_law="feedback", policy_gated=True, gate_threshold=1.0)  # 1 m
    record = collect_episode(shut, load_gains(), 5, 0, _acting())
    assert np.all(record.transitions["action"] == 0.0)
    # the gate open throughout: every decision's action applied, and stored as proposed
    opened = replace(shut, gate_threshold=0.0)
    record = collect_episode(opened, load_gains(), 5, 0, _acting())
    assert np.all(np.abs(record.transitions["action"]).sum(axis=1) > 0.1)

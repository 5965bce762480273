"""The feedback law reads the environment's state (FeedbackActor.act) where the observation
used to be built for it: the same actions as from the observation at every step of a push,
and the same pushes, on sim and on the proxy (whose law reads the camera and the noisy force
estimate)."""

from __future__ import annotations

import copy
from dataclasses import replace

import numpy as np
import pytest

from pushctl.control.feedback import load_feedback_gains
from pushctl.controllers.feedback import feedback_config
from pushctl.rl.policy import finish_with_policy
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.feedback_actor import FeedbackActor


def _feedback_env(plant: str) -> PushEnv:
    config = feedback_config(EnvConfig(plant=plant, stream="tuning", duration=4.0))
    env = PushEnv(config)
    env.reset(options={"object": "wedge", "profile": "chirp", "scenario_seed": 3})
    return env


def _frame(env: PushEnv) -> bytes:
    assert env.episode is not None
    return env.episode.trace().to_frame().to_numpy().tobytes()


@pytest.mark.parametrize("plant", ["sim", "proxy"])
def test_the_law_on_the_state_acts_as_on_the_observation_at_every_step(plant) -> None:
    env = _feedback_env(plant)
    from_state = FeedbackActor(env, load_feedback_gains())
    from_observation = FeedbackActor(env, load_feedback_gains())
    assert env.episode is not None
    acted = 0
    while not env.episode.done:
        action = None
        if env.gate_open:
            expected = from_observation(np.asarray(env.observation(), dtype=np.float64))
            action = np.array(from_state.act())
            assert action.tobytes() == expected.tobytes()
            acted += np.any(action != 0.0)
        env.advance(action)
    assert acted > 50  # the law acted, not only held still


@pytest.mark.parametrize("plant", ["sim", "proxy"])
def test_a_push_with_the_law_is_the_push_from_its_observations(plant) -> None:
    env = _feedback_env(plant)
    fast, slow = copy.deepcopy(env), copy.deepcopy(env)
    finish_with_policy(fast, FeedbackActor(fast, load_feedback_gains()))
    law = FeedbackActor(slow, load_feedback_gains())
    finish_with_policy(slow, lambda obs: law(obs))  # not the law itself: the observation path
    assert _frame(fast) == _frame(slow)


def test_the_base_law_under_a_policy_pushes_as_the_law_from_observations() -> None:
    """A policy's environment adds the law's action at every step (EnvConfig.base_law),
    now read from the state; the law fed the observation by hand pushes the same."""
    config = EnvConfig(base_law="feedback", action_repeat=10, stream="tuning", duration=4.0)
    env = PushEnv(config)
    env.reset(options={"object": "cube", "profile": "trapezoid", "scenario_seed": 2})
    by_hand = copy.deepcopy(env)
    finish_with_policy(env, lambda obs: np.zeros(3))
    by_hand.config = replace(by_hand.config, base_law="none", action_repeat=1)
    by_hand._base = None
    law = FeedbackActor(by_hand, load_feedback_gains(), interval=config.dt)
    finish_with_policy(by_hand, lambda obs: law(obs))
    assert _frame(env) == _frame(by_hand)


def test_a_subclass_of_the_law_is_asked_through_its_own_twist() -> None:
    """The state path is the law's own: a subclass that extends twist() (the residual study
    records the law's twists) is called at every decision, through the observation."""

    class Counting(FeedbackActor):
        calls = 0

        def twist(self, observation: np.ndarray) -> np.ndarray:
            Counting.calls += 1
            return super().twist(observation)

    env = _feedback_env("sim")
    assert env.config.action_repeat == 1  # a decision at every step the gate is open
    opened = finish_with_policy(env, Counting(env, load_feedback_gains()))
    assert Counting.calls == opened > 100

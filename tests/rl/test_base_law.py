"""The residual on the feedback law (EnvConfig.base_law): a zero residual pushes exactly as
the feedback controller does, step() and finish_with_policy() agree, a residual moves the push
off the law's, and old policies load without it."""

from __future__ import annotations

import copy
from dataclasses import replace

import numpy as np
import pytest

from pushctl.control.feedback import load_feedback_gains
from pushctl.errors import ConfigError
from pushctl.evaluation.controllers import FeedbackActor, feedback_config
from pushctl.rl.env import PushEnv
from pushctl.rl.env_config import EnvConfig
from pushctl.rl.policy import finish_with_policy

ZERO = np.zeros(3)


def _reset(repeat: int) -> PushEnv:
    config = EnvConfig(base_law="feedback", action_repeat=repeat, stream="tuning", duration=4.0)
    env = PushEnv(config)
    env.reset(options={"object": "cube", "profile": "constant", "scenario_seed": 1})
    return env


def _frame(env: PushEnv) -> bytes:
    assert env.episode is not None
    return env.episode.trace().to_frame().to_numpy().tobytes()


@pytest.mark.parametrize("repeat", [1, 10])
def test_a_zero_residual_on_the_law_is_the_feedback_controller_to_the_bit(repeat) -> None:
    env = _reset(repeat)
    on_law, by_steps, law_alone = copy.deepcopy(env), copy.deepcopy(env), copy.deepcopy(env)
    finish_with_policy(on_law, lambda obs: ZERO)
    assert by_steps.episode is not None
    while not by_steps.episode.done:
        by_steps.step(ZERO)
    law_alone.config = replace(law_alone.config, base_law="none")
    law_alone._base = None  # the copy was reset with the law under it
    finish_with_policy(law_alone, FeedbackActor(law_alone, load_feedback_gains()))
    assert _frame(on_law) == _frame(by_steps) == _frame(law_alone)
    # and the law acted: the push is not PD-only's
    pd_only = copy.deepcopy(env)
    assert pd_only.episode is not None
    assert pd_only.episode.finish().to_frame().to_numpy().tobytes() != _frame(on_law)


def test_a_residual_is_added_to_the_laws_action_and_clipped() -> None:
    env = _reset(10)
    observation = env.observation()
    law = FeedbackActor(copy.deepcopy(env), load_feedback_gains())
    expected = np.clip(law(observation.astype(np.float64)) + 0.3, -1.0, 1.0)
    np.testing.assert_allclose(env.decide(np.full(3, 0.3), observation), expected, atol=1e-12)
    np.testing.assert_array_equal(
        env.decide(np.full(3, 5.0), observation), np.ones(3)
    )  # clipped after the sum


def test_the_feedback_column_never_adds_the_law_twice_and_bad_values_are_one_line() -> None:
    assert feedback_config(EnvConfig(base_law="feedback")).base_law == "none"
    assert EnvConfig.from_saved({}).base_law == "none"
    with pytest.raises(ConfigError, match="env base_law must be one of none, feedback"):
        EnvConfig(base_law="pid")

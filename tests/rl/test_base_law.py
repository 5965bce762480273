"""The residual on the feedback law (EnvConfig.base_law): a zero residual held for 100 ms
pushes exactly as the feedback controller deciding every 10 ms, step() and
finish_with_policy() agree, a residual moves the push off the law's, and old policies load
without it."""

from __future__ import annotations

import copy
from dataclasses import replace

import numpy as np
import pytest

from pushctl.control.feedback import load_feedback_gains
from pushctl.controllers.feedback import feedback_config
from pushctl.errors import ConfigError
from pushctl.rl.policy import finish_with_policy
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.feedback_actor import FeedbackActor

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
    # the feedback controller decides every 10 ms whatever the policy's interval, and the
    # shipped law, which gates itself, sees every step (feedback_config opens the gate)
    law_alone.config = replace(
        law_alone.config, base_law="none", action_repeat=1, gate_threshold=0.0
    )
    law_alone._base = None  # the copy was reset with the law under it
    finish_with_policy(law_alone, FeedbackActor(law_alone, load_feedback_gains()))
    assert _frame(on_law) == _frame(by_steps) == _frame(law_alone)
    # and the law acted: the push is not PD-only's
    pd_only = copy.deepcopy(env)
    assert pd_only.episode is not None
    assert pd_only.episode.finish().to_frame().to_numpy().tobytes() != _frame(on_law)


def test_a_residual_moves_the_push_off_the_laws() -> None:
    env = _reset(10)
    zero, pushed = copy.deepcopy(env), copy.deepcopy(env)
    finish_with_policy(zero, lambda obs: ZERO)
    finish_with_policy(pushed, lambda obs: np.array([0.0, 0.5, 0.0]))
    assert zero.episode is not None and pushed.episode is not None
    assert pushed.episode.reference_offset[1] != zero.episode.reference_offset[1]


def test_the_feedback_column_never_adds_the_law_twice_and_bad_values_are_one_line() -> None:
    assert feedback_config(EnvConfig(base_law="feedback")).base_law == "none"
    # beside a policy whose residual is scaled down, the law still acts with the whole envelope
    policy_config = EnvConfig(base_law="feedback", residual_scale=0.2)
    assert feedback_config(policy_config).residual_scale == 1.0
    assert EnvConfig.from_saved({}).base_law == "none"
    with pytest.raises(ConfigError, match="env base_law must be one of none, feedback"):
        EnvConfig(base_law="pid")


def test_the_residual_scale_shrinks_the_policys_action_before_the_law_is_added() -> None:
    """residual_scale 0.2 with action a pushes exactly as scale 1 with action 0.2 a."""
    env = _reset(10)
    scaled, equivalent = copy.deepcopy(env), copy.deepcopy(env)
    scaled.config = replace(scaled.config, residual_scale=0.2)
    finish_with_policy(scaled, lambda obs: np.array([0.5, -0.5, 1.0]))
    finish_with_policy(equivalent, lambda obs: 0.2 * np.array([0.5, -0.5, 1.0]))
    assert _frame(scaled) == _frame(equivalent)
    full = copy.deepcopy(env)
    finish_with_policy(full, lambda obs: np.array([0.5, -0.5, 1.0]))
    assert _frame(full) != _frame(scaled)
    for bad in (0.0, 1.5, True):
        with pytest.raises(ConfigError, match="residual_scale must be a number in"):
            EnvConfig(residual_scale=bad)


@pytest.mark.parametrize(
    ("plant", "policy_gated"), [("sim", False), ("proxy", False), ("sim", True)]
)
def test_a_zero_residual_on_a_self_gating_law_is_the_feedback_column_to_the_bit(
    plant, policy_gated
) -> None:
    """The shipped law gates itself (``gate_threshold`` in its file): it acts at every step
    whatever the environment's gate (which then switches only the policy, if
    ``policy_gated``), as in the ``feedback`` column, so a policy that holds zeros reports
    the feedback column's trial exactly, on Push-v1 and on the gated Push-v0 settings."""
    gains = load_feedback_gains()
    assert gains.owns_gate
    config = replace(EnvConfig.v1(), stream="tuning", duration=4.0, plant=plant)
    config = replace(config, policy_gated=policy_gated)
    assert config.gate_threshold > 0.0
    options = {"object": "wedge", "profile": "chirp", "scenario_seed": 3}
    on_law = PushEnv(config)
    on_law.reset(options=options)
    shut = finish_with_policy(on_law, lambda obs: ZERO)
    column = PushEnv(feedback_config(config, gains))
    column.reset(options=options)
    finish_with_policy(column, FeedbackActor(column, gains))
    assert _frame(on_law) == _frame(column)
    if plant == "sim":  # on the proxy the camera's noise holds the gate open
        assert 0 < shut < on_law.episode.n_steps  # the environment's gate was shut at times


def test_the_gate_still_switches_the_policy_under_a_self_gating_law() -> None:
    """With ``policy_gated`` an action inside the dead band changes nothing: the push with
    a constant action equals the zero-residual push until the gate first opens."""
    config = replace(EnvConfig.v1(policy_gated=True, gate_threshold=1.0), stream="tuning")
    env = PushEnv(replace(config, duration=2.0))
    env.reset(options={"object": "cube", "profile": "constant", "scenario_seed": 1})
    zero, pushed = copy.deepcopy(env), copy.deepcopy(env)
    finish_with_policy(zero, lambda obs: ZERO)
    finish_with_policy(pushed, lambda obs: np.array([0.0, 0.5, 0.0]))
    assert _frame(zero) == _frame(pushed)  # a 1 m gate never opens: the law alone
    free = copy.deepcopy(env)
    free.config = replace(free.config, policy_gated=False)
    finish_with_policy(free, lambda obs: np.array([0.0, 0.5, 0.0]))
    assert _frame(free) != _frame(zero)

"""Push-v1's settings: the policy acts inside the gate's dead band, a zero residual is still
the law to the bit, the context and privileged rows, the documented tables, and Push-v0's
behaviour reachable (EnvConfig() and saved policies)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from pushctl.control.feedback import STEADY_FEEDBACK_FILE, load_feedback_gains
from pushctl.rl.policy import finish_with_policy
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.spaces import (
    CONTEXT_ENTRIES,
    PRIVILEGED_SCALES,
    index,
    markdown_table,
    observation_entries,
)

ZERO = np.zeros(3)
OPTIONS = {"object": "cube", "profile": "constant", "scenario_seed": 1}


def _reset(config: EnvConfig) -> PushEnv:
    env = PushEnv(replace(config, stream="tuning", duration=2.0))
    env.reset(options=OPTIONS)
    return env


def _frame(env: PushEnv) -> bytes:
    assert env.episode is not None
    return env.episode.trace().to_frame().to_numpy().tobytes()


def test_a_zero_residual_on_push_v1_is_the_law_to_the_bit():
    v1 = _reset(EnvConfig.v1())
    law = _reset(replace(EnvConfig.v1(), policy_gated=True, observe_context=False))
    finish_with_policy(v1, lambda obs: ZERO)
    finish_with_policy(law, lambda obs: ZERO)
    assert _frame(v1) == _frame(law)


def test_the_policy_acts_inside_the_dead_band_only_when_ungated(monkeypatch):
    # the steady law leaves the gate to the environment (the shipped law gates itself)
    steady = load_feedback_gains(STEADY_FEEDBACK_FILE)
    monkeypatch.setattr("pushctl.task.env.load_feedback_gains", lambda: steady)
    shut = dict(gate_threshold=1.0)  # a 1 m gate: never open, the law never acts
    gated = _reset(EnvConfig.v1(policy_gated=True, **shut))
    free = _reset(EnvConfig.v1(**shut))
    gated_info = gated.step(np.array([0.0, 0.5, 0.0]))[4]
    free_info = free.step(np.array([0.0, 0.5, 0.0]))[4]
    assert not gated_info["residual_active"] and free_info["residual_active"]
    assert free_info["residual"][1] != 0.0 or free_info["residual"][0] != 0.0
    assert not np.array_equal(gated.observation(), free.observation())
    assert gated.policy_acts is False and free.policy_acts is True


def test_context_rows_hold_the_error_rate_plan_speed_and_law_action():
    env = _reset(EnvConfig.v1())
    where = index(env.observation_entries)
    obs = env.observation()
    assert len(obs) == len(observation_entries(2, True)) + len(CONTEXT_ENTRIES)
    assert obs[where["error_rate_x"]] == 0.0 and obs[where["law_x"]] == 0.0
    speed = np.hypot(*env.plan.trajectory.velocity[0, :2])
    assert obs[where["plan_speed"]] == pytest.approx(speed, rel=1e-6)
    for _ in range(5):
        obs = env.step(ZERO)[0]
    rates = obs[[where["error_rate_x"], where["error_rate_y"], where["error_rate_theta"]]]
    assert np.all(np.isfinite(rates)) and np.any(rates != 0.0)
    law = obs[[where["law_x"], where["law_y"], where["law_wz"]]]
    assert np.all(np.abs(law) <= 1.0)
    assert where["phase"] == len(obs) - 1


def test_privileged_state_holds_the_unknowns_and_the_exact_error():
    env = _reset(EnvConfig.v1())
    priv = env.privileged_state()
    assert priv.shape == PRIVILEGED_SCALES.shape and priv.dtype == np.float32
    unknowns = env.scenario.unknowns
    assert priv[0] == np.float32(unknowns.placement[0])
    np.testing.assert_array_equal(priv[-3:], env.pose_error.astype(np.float32))
    assert np.all(np.abs(priv / PRIVILEGED_SCALES) < 100)


def test_push_v0_stays_the_default_and_saved_policies_load_it():
    config = EnvConfig()
    assert config.policy_gated and not config.observe_context
    saved = EnvConfig.v1().to_dict()
    for key in ("policy_gated", "observe_context"):
        del saved[key]
    old = EnvConfig.from_saved(saved)
    assert old.policy_gated and not old.observe_context
    assert EnvConfig.from_mapping(EnvConfig.v1().to_dict()) == EnvConfig.v1()


def test_push_v1s_table_is_the_environments_own_layout():
    env = PushEnv(EnvConfig.v1())
    entries = observation_entries(2, reference_offset=True, context=True)
    assert env.observation_entries == entries
    table = markdown_table(entries).splitlines()
    assert len(table) - 2 == env.observation_space.shape[0]

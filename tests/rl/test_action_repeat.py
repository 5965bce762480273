"""The decision interval (``action_repeat``) and the reference offset in the observation:
a held action is k single steps, the policy loop of evaluation holds it the same way, and the
observed offset is the one the episode built, in the plan frame."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from pushctl.errors import ConfigError
from pushctl.rl.policy import finish_with_policy
from pushctl.task.env import PushEnv
from pushctl.task.env_config import LEGACY_VALUES, EnvConfig
from pushctl.task.spaces import index

SHORT = EnvConfig(duration=1.0, gate_threshold=0.0, landing="believed")  # 100 steps, gate open
OPTIONS = {"object": "cube", "profile": "chirp", "scenario_seed": 5}


def _actor(obs: np.ndarray) -> np.ndarray:
    """A deterministic actor whose action changes with every observation."""
    return np.array([1.0, -0.5, 0.3]) * math.cos(1e3 * float(np.sum(obs)))


def test_one_held_step_is_k_single_steps_with_the_summed_reward() -> None:
    held = PushEnv(replace(SHORT, action_repeat=4))
    single = PushEnv(SHORT)
    held.reset(options=OPTIONS)
    single.reset(options=OPTIONS)
    action = np.array([0.6, -0.4, 0.8])
    obs, reward, done, _, info = held.step(action)
    rewards = []
    for _ in range(4):
        single_obs, single_reward, *_ = single.step(action)
        rewards.append(single_reward)
    assert held.episode is not None and held.episode.step_index == 4
    np.testing.assert_array_equal(obs, single_obs)
    assert reward == pytest.approx(sum(rewards), rel=1e-12)
    assert info["residual_active"] and not done


def test_the_last_held_step_ends_with_the_episode() -> None:
    env = PushEnv(replace(SHORT, action_repeat=30))  # 100 steps: 3 full holds and one of 10
    env.reset(options=OPTIONS)
    ends = [env.step(np.zeros(3))[2] for _ in range(4)]
    assert ends == [False, False, False, True]
    assert env.episode is not None and env.episode.step_index == 100


@pytest.mark.parametrize("plant", ["sim", "proxy"])
def test_finishing_with_a_policy_holds_its_action_as_step_does(plant: str) -> None:
    config = replace(SHORT, action_repeat=7, plant=plant, gate_threshold=1e-3)
    env = PushEnv(config)
    obs, _ = env.reset(options=OPTIONS)
    done = False
    while not done:
        obs, _, done, _, _ = env.step(_actor(np.asarray(obs, dtype=np.float64)))
    assert env.episode is not None
    stepped = env.episode.trace()
    env.reset(options=OPTIONS)
    finish_with_policy(env, _actor)
    finished = env.episode.trace()
    np.testing.assert_array_equal(finished.object_pose, stepped.object_pose)
    np.testing.assert_array_equal(finished.pusher_position, stepped.pusher_position)


def test_the_observed_offset_is_the_episodes_offset_in_the_plan_frame() -> None:
    env = PushEnv(SHORT)
    obs, _ = env.reset(options=OPTIONS)
    where = index(env.observation_entries)
    offset_names = ("offset_x", "offset_y", "offset_theta")
    assert [obs[where[name]] for name in offset_names] == [0.0, 0.0, 0.0]
    for _ in range(20):
        obs, *_ = env.step(np.array([1.0, 0.5, -1.0]))
    assert env.episode is not None
    world = env.episode.reference_offset
    yaw = env.plan.trajectory.pose[env.episode.step_index, 2]
    c, s = math.cos(yaw), math.sin(yaw)
    expected = [c * world[0] + s * world[1], -s * world[0] + c * world[1], world[2]]
    observed = [obs[where[name]] for name in offset_names]
    np.testing.assert_allclose(observed, expected, rtol=1e-6, atol=1e-12)
    # 20 steps of a full action, plan frame, at the default scales: 20 x 10 ms x scale.
    assert abs(world[2]) == pytest.approx(20 * 0.01 * SHORT.action_scale_angular, rel=1e-9)
    assert math.hypot(world[0], world[1]) == pytest.approx(
        20 * 0.01 * SHORT.action_scale_linear * math.hypot(1.0, 0.5), rel=1e-2
    )


def test_the_velocity_path_and_old_policies_observe_no_offset() -> None:
    velocity = PushEnv(replace(SHORT, residual_path="velocity"))
    reference = PushEnv(SHORT)
    assert len(reference.observation_entries) == len(velocity.observation_entries) + 3
    assert "offset_x" not in index(velocity.observation_entries)
    legacy = EnvConfig.from_saved({"duration": 1.0})
    assert (legacy.observe_offset, legacy.action_repeat) == (False, 1)
    assert legacy.residual_path == LEGACY_VALUES["residual_path"]
    assert not legacy.offset_observed


@pytest.mark.parametrize("repeat", [0, 101, 2.5, True])
def test_a_bad_action_repeat_is_one_line(repeat: object) -> None:
    with pytest.raises(ConfigError, match="action_repeat must be an integer in 1..100"):
        EnvConfig.from_mapping({"action_repeat": repeat})

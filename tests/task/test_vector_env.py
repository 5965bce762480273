"""The vector environment: ``gymnasium.make_vec`` builds it, and its N sub-environments give
byte for byte what N single PushEnvs give with the same seeds and actions, over a whole
episode, the auto-reset and steps of the next episode."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest

import pushctl.task
from pushctl.errors import ConfigError, StateError
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.vector_env import PushVectorEnv

# 40 push steps; the gate always open, so every action acts and prongs slip
SHORT = EnvConfig(duration=0.4, objects=("cube", "wedge"), profiles=("constant",))
SHORT_OPEN = EnvConfig(
    duration=0.4, objects=("cube", "wedge"), profiles=("constant",), gate_threshold=0.0
)
N = 8


def test_make_vec_returns_the_native_vector_env() -> None:
    envs = gymnasium.make_vec(pushctl.task.ENV_ID, num_envs=3, config=SHORT)
    assert isinstance(envs, PushVectorEnv)
    assert isinstance(envs, gymnasium.vector.VectorEnv)
    assert envs.num_envs == 3
    obs, info = envs.reset(seed=5)
    assert obs.shape == (3, envs.single_observation_space.shape[0])
    assert envs.observation_space.contains(obs)
    assert info["_scenario"].all()
    assert envs.metadata["autoreset_mode"] == gymnasium.vector.AutoresetMode.NEXT_STEP


def test_eight_envs_equal_eight_single_envs_over_an_episode_and_its_auto_reset() -> None:
    vector = gymnasium.make_vec(pushctl.task.ENV_ID, num_envs=N, config=SHORT_OPEN)
    singles = [PushEnv(SHORT_OPEN) for _ in range(N)]
    rng = np.random.default_rng(0)
    obs, _ = vector.reset(seed=100)
    expected = [env.reset(seed=100 + i)[0] for i, env in enumerate(singles)]
    assert obs.tobytes() == np.stack(expected).tobytes()
    steps = singles[0].episode.n_steps
    done = np.zeros(N, dtype=bool)
    resets = 0
    for _ in range(steps + 6):  # the episode, the auto-reset step, 5 steps of the next
        actions = rng.uniform(-1.0, 1.0, size=(N, 3))
        obs, reward, terminated, truncated, info = vector.step(actions)
        rows, expected_info = [], {}
        for i, env in enumerate(singles):
            if done[i]:  # NEXT_STEP: this step resets it, its action unused
                observation, single_info = env.reset()
                rows.append((observation, 0.0, False, False))
                resets += 1
            else:
                observation, r, term, trunc, single_info = env.step(actions[i])
                rows.append((observation, r, term, trunc))
            expected_info = vector._add_info(expected_info, single_info, i)  # gymnasium's
        assert info.keys() == expected_info.keys()
        for key, value in info.items():
            if key not in ("scenario", "unknowns"):  # objects: compared through obs
                assert np.asarray(value).dtype == np.asarray(expected_info[key]).dtype, key
                assert np.array_equal(value, expected_info[key]), key
        assert obs.tobytes() == np.stack([row[0] for row in rows]).tobytes()
        assert reward.tobytes() == np.array([row[1] for row in rows]).tobytes()
        assert terminated.tolist() == [row[2] for row in rows]
        assert truncated.tolist() == [row[3] for row in rows]
        done = terminated | truncated
    assert resets == N  # every sub-environment went through one auto-reset
    assert info["_residual_active"].all()
    # the steps changed the pushes: an action that did nothing would make this test weak
    assert np.abs(info["residual"]).max() > 0.0


def test_disabled_mode_resets_only_the_masked_envs() -> None:
    vector = PushVectorEnv(2, SHORT, autoreset_mode="Disabled")
    obs, _ = vector.reset(seed=[7, 8])
    for _ in range(vector.envs[0].episode.n_steps):
        obs, _, terminated, _, _ = vector.step(np.zeros((2, 3)))
    assert terminated.all()
    with pytest.raises(StateError):
        vector.step(np.zeros((2, 3)))  # not reset: the push is over
    kept = obs[1].copy()
    fresh, info = vector.reset(seed=[7, None], options={"reset_mask": np.array([True, False])})
    assert fresh[1].tobytes() == kept.tobytes()
    assert info["_scenario"].tolist() == [True, False]
    single = PushEnv(SHORT)
    single.reset(seed=7)
    for _ in range(single.episode.n_steps):
        single.step(np.zeros(3))
    assert fresh[0].tobytes() == single.reset(seed=7)[0].tobytes()


@pytest.mark.parametrize(
    "make",
    [
        lambda: PushVectorEnv(0, SHORT),
        lambda: PushVectorEnv(2, SHORT, autoreset_mode="SameStep"),
        lambda: PushVectorEnv(2, SHORT).reset(seed=[1]),
        lambda: PushVectorEnv(2, SHORT).reset(seed=True),
        lambda: PushVectorEnv(2, SHORT).step(np.zeros(3)),
    ],
)
def test_bad_input_is_a_config_error(make) -> None:
    with pytest.raises(ConfigError):
        make()

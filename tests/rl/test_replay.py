"""Replay buffer: ring order, wrap-around, batches, sampling and exact state round-trips."""

import numpy as np
import pytest
import torch

from pushctl.errors import ConfigError, StateError
from pushctl.rl.replay import FIELDS, ReplayBuffer

OBS, ACT = 3, 2


def _transition(i: int):
    """Transition number i, every entry encoding i so that rows can be identified."""
    return (np.full(OBS, i), np.full(ACT, i / 100), float(i), np.full(OBS, i + 0.5), i % 2)


def _filled(capacity: int, n: int) -> ReplayBuffer:
    buffer = ReplayBuffer(capacity, OBS, ACT)
    for i in range(n):
        buffer.add(*_transition(i))
    return buffer


def _batch(start: int, n: int):
    rows = [_transition(i) for i in range(start, start + n)]
    return [np.array(column) for column in zip(*rows, strict=True)]


def test_add_stores_rows_in_order():
    buffer = _filled(10, 4)
    state = buffer.state_dict()
    assert len(buffer) == 4 and buffer.position == 4
    np.testing.assert_array_equal(state["reward"], [0, 1, 2, 3])
    np.testing.assert_array_equal(state["obs"][2], [2, 2, 2])
    np.testing.assert_array_equal(state["next_obs"][2], [2.5, 2.5, 2.5])
    np.testing.assert_array_equal(state["done"], [0, 1, 0, 1])
    assert all(state[name].dtype == np.float32 for name in FIELDS)


def test_wrap_around_overwrites_the_oldest_rows():
    buffer = _filled(5, 7)
    assert len(buffer) == 5 and buffer.position == 2
    np.testing.assert_array_equal(buffer.state_dict()["reward"], [5, 6, 2, 3, 4])


@pytest.mark.parametrize(("start", "sizes"), [(0, [3, 4]), (2, [6]), (0, [12]), (1, [4, 9, 2])])
def test_add_batch_equals_sequential_adds(start, sizes):
    sequential, batched = _filled(5, start), _filled(5, start)
    i = start
    for n in sizes:
        batched.add_batch(*_batch(i, n))
        for j in range(i, i + n):
            sequential.add(*_transition(j))
        i += n
    a, b = sequential.state_dict(), batched.state_dict()
    assert (len(batched), batched.position) == (len(sequential), sequential.position)
    for name in FIELDS:
        np.testing.assert_array_equal(a[name], b[name])


def test_state_dict_holds_only_filled_rows():
    state = _filled(100, 7).state_dict()
    assert all(state[name].shape[0] == 7 for name in FIELDS)
    assert state["position"] == 7 and state["size"] == 7


def test_state_round_trip_after_wrap_continues_identically():
    original = _filled(5, 8)
    restored = ReplayBuffer(5, OBS, ACT)
    # Through torch tensors, as the agent's checkpoint stores them.
    restored.load_state_dict(
        {
            k: torch.from_numpy(v) if isinstance(v, np.ndarray) else v
            for k, v in original.state_dict().items()
        }
    )
    assert (len(restored), restored.position) == (5, 3)
    for buffer in (original, restored):
        buffer.add(*_transition(8))
    a, b = original.state_dict(), restored.state_dict()
    for name in FIELDS:
        np.testing.assert_array_equal(a[name], b[name])
    sample_a = original.sample(16, np.random.default_rng(1))
    sample_b = restored.sample(16, np.random.default_rng(1))
    for name in FIELDS:
        np.testing.assert_array_equal(sample_a[name], sample_b[name])


def test_sample_draws_only_filled_rows_and_all_of_them():
    buffer = _filled(1000, 10)
    batch = buffer.sample(2000, np.random.default_rng(0))
    assert batch["obs"].shape == (2000, OBS) and batch["action"].shape == (2000, ACT)
    assert batch["reward"].shape == (2000,) and batch["done"].shape == (2000,)
    assert set(batch["reward"].tolist()) == set(range(10))
    np.testing.assert_array_equal(batch["obs"][:, 0], batch["reward"])


def test_sample_is_reproducible_from_the_generator():
    buffer = _filled(50, 30)
    a = buffer.sample(8, np.random.default_rng(5))["reward"]
    b = buffer.sample(8, np.random.default_rng(5))["reward"]
    np.testing.assert_array_equal(a, b)


def test_bad_inputs_raise():
    buffer = ReplayBuffer(5, OBS, ACT)
    obs, action, reward, next_obs, done = _transition(0)
    with pytest.raises(StateError, match="obs must have shape"):
        buffer.add(np.zeros(OBS + 1), action, reward, next_obs, done)
    with pytest.raises(StateError, match="action must be finite"):
        buffer.add(obs, np.array([0.0, np.nan]), reward, next_obs, done)
    with pytest.raises(StateError, match="reward must be finite"):
        buffer.add(obs, action, np.inf, next_obs, done)
    with pytest.raises(StateError, match="shape"):
        buffer.add_batch(obs, action, reward, next_obs, done)
    with pytest.raises(StateError, match="empty"):
        buffer.sample(1, np.random.default_rng(0))
    with pytest.raises(ConfigError, match="capacity"):
        ReplayBuffer(0, OBS, ACT)
    with pytest.raises(ConfigError, match="capacity"):
        ReplayBuffer(6, OBS, ACT).load_state_dict(_filled(5, 2).state_dict())
    assert len(buffer) == 0

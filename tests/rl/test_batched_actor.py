"""The batched actor: row i of a batch forward is bit for bit the forward of observation i
alone, for every batch size, and equals the torch actor up to float32 rounding."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from pushctl.errors import StateError
from pushctl.rl.networks import Actor, ActorPolicy, initialise


def _policy(hidden=(128, 128), seed: int = 0) -> ActorPolicy:
    actor = Actor(14, 3, hidden)
    # a wide output layer, so actions are far from 0 and rounding shows
    initialise(actor, torch.Generator().manual_seed(seed), final_bound=0.5)
    return ActorPolicy(actor.eval(), np.linspace(0.5, 2.0, 14))


@pytest.mark.parametrize("hidden", [(128, 128), (37, 5, 64), (256, 256)])
def test_every_row_is_its_single_forward_bit_for_bit_at_every_batch_size(hidden) -> None:
    policy = _policy(hidden)
    obs = np.random.default_rng(1).normal(scale=3.0, size=(17, 14)).astype(np.float32)
    singles = np.concatenate([policy.batch(obs[i : i + 1]) for i in range(len(obs))])
    for size in (2, 3, 8, 16, 17):
        assert policy.batch(obs[:size]).tobytes() == singles[:size].tobytes()
    with torch.inference_mode():
        reference = policy.actor(torch.from_numpy(obs / policy.obs_scale)).numpy()
    np.testing.assert_allclose(singles, reference, rtol=0, atol=2e-6)
    assert np.abs(singles).max() > 0.05  # not a zero actor


def test_an_optimiser_step_shows_through_the_batched_forward() -> None:
    policy = _policy()
    obs = np.ones((2, 14), dtype=np.float32)
    before = policy.batch(obs)
    with torch.no_grad():
        policy.actor.net[-1].bias.add_(0.1)  # in place, as an optimiser step
    after = policy.batch(obs)
    assert not np.array_equal(before, after)
    np.testing.assert_allclose(after, ActorPolicy(policy.actor, policy.obs_scale).batch(obs))


def test_bad_batches_are_state_errors() -> None:
    policy = _policy()
    with pytest.raises(StateError):
        policy.batch(np.ones(14))
    with pytest.raises(StateError):
        policy.batch(np.full((2, 14), np.nan))

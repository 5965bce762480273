"""Ornstein–Uhlenbeck noise: shapes, the AR(1) statistics, reproducibility and state."""

import numpy as np
import pytest

from pushctl.errors import ConfigError
from pushctl.rl.noise import OrnsteinUhlenbeckNoise


def _noise(size=3, theta=0.15, sigma=0.2, dt=1.0, seed=0):
    return OrnsteinUhlenbeckNoise(size, theta, sigma, dt, np.random.default_rng(seed))


def test_shapes_and_start_at_zero():
    assert _noise(4).sample().shape == (4,)
    batch = _noise((5, 2))
    assert batch.shape == (5, 2)
    assert batch.state_dict()["x"].shape == (5, 2)
    assert not batch.state_dict()["x"].any()
    assert batch.sample().shape == (5, 2)


def test_without_diffusion_it_decays_geometrically_to_zero():
    noise = _noise(2, theta=0.3, sigma=0.0, dt=0.5)
    noise.load_state_dict({"x": np.array([5.0, -2.0])})
    for k in range(1, 30):
        np.testing.assert_allclose(noise.sample(), np.array([5.0, -2.0]) * 0.85**k, rtol=1e-12)


def test_mean_reverts_from_an_offset():
    noise = _noise(20_000, theta=0.15, sigma=0.2)
    noise.load_state_dict({"x": np.full(20_000, 3.0)})
    for _ in range(10):
        x = noise.sample()
    # The mean follows 3·0.85^k; the spread of the mean of 20 000 rows is ~0.003.
    assert x.mean() == pytest.approx(3.0 * 0.85**10, abs=0.015)


def test_long_run_mean_and_exact_stationary_variance():
    theta, sigma, dt = 0.15, 0.2, 1.0
    noise = _noise(2_000, theta, sigma, dt)
    for _ in range(100):  # burn-in: 0.85^100 ≈ 1e-7 of the start is left
        noise.step()
    samples = np.array([noise.sample() for _ in range(1_000)])
    exact = sigma**2 / (theta * (2.0 - theta * dt))  # AR(1): sigma²·dt / (1 − (1 − θ·dt)²)
    small_theta = sigma**2 / (2.0 * theta)
    assert noise.stationary_variance() == pytest.approx(exact)
    assert abs(samples.mean()) < 0.01
    # ~160 000 effective samples: the variance is known to ~0.4 %; the two formulas differ 8 %.
    assert samples.var() == pytest.approx(exact, rel=0.02)
    assert abs(samples.var() / small_theta - 1.0) > 0.05


def test_reproducible_from_a_seed_and_seeds_differ():
    first, second = _noise(seed=7), _noise(seed=7)
    for _ in range(50):
        np.testing.assert_array_equal(first.sample(), second.sample())
    assert not np.array_equal(_noise(seed=7).sample(), _noise(seed=8).sample())


def test_reset_all_or_some_rows():
    noise = _noise((3, 2))
    for _ in range(5):
        noise.step()
    noise.reset(np.array([1]))
    x = noise.state_dict()["x"]
    assert not x[1].any() and x[0].all() and x[2].all()
    noise.reset()
    assert not noise.state_dict()["x"].any()


def test_state_round_trip_continues_identically():
    rng = np.random.default_rng(3)
    noise = OrnsteinUhlenbeckNoise(2, 0.15, 0.2, 1.0, rng)
    for _ in range(7):
        noise.step()
    saved, rng_state = noise.state_dict(), rng.bit_generator.state
    expected = [noise.sample() for _ in range(5)]
    rng2 = np.random.default_rng(99)
    rng2.bit_generator.state = rng_state
    restored = OrnsteinUhlenbeckNoise(2, 0.15, 0.2, 1.0, rng2)
    restored.load_state_dict(saved)
    np.testing.assert_array_equal(np.array(expected), [restored.sample() for _ in range(5)])


def test_sample_returns_a_copy():
    noise = _noise(2)
    x = noise.sample()
    x[:] = 100.0
    assert np.abs(noise.state_dict()["x"]).max() < 10.0


@pytest.mark.parametrize(
    "kwargs", [{"theta": -0.1}, {"sigma": -1.0}, {"dt": 0.0}, {"theta": 2.0}, {"size": 0}]
)
def test_bad_parameters_raise(kwargs):
    with pytest.raises(ConfigError):
        _noise(**kwargs)


def test_explore_adds_one_noise_step_to_the_action_or_is_the_noise_alone():
    noise = OrnsteinUhlenbeckNoise(3, 0.15, 2.0, 1.0, np.random.default_rng(4))
    twin = OrnsteinUhlenbeckNoise(3, 0.15, 2.0, 1.0, np.random.default_rng(4))
    alone = noise.explore(None)  # the warm-up
    np.testing.assert_array_equal(alone, np.clip(twin.sample(), -1.0, 1.0))
    action = np.array([0.5, -0.5, 0.0])
    expected = np.clip(action + twin.sample(), -1.0, 1.0)
    assert noise.explore(action) is action  # in place
    np.testing.assert_array_equal(action, expected)
    assert np.abs(expected).max() == 1.0  # sigma 2: clipped

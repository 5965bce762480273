"""DDPG: config, networks, acting, the update schedule, determinism, resume and learning."""

import io
from dataclasses import replace

import numpy as np
import pytest
import torch

from pushctl.errors import ConfigError, StateError
from pushctl.rl.config import DDPGConfig
from pushctl.rl.ddpg import DDPGAgent, configure_torch, soft_update
from pushctl.rl.networks import FINAL_LAYER_BOUND, Actor, ActorPolicy, Critic, initialise
from pushctl.rl.noise import OrnsteinUhlenbeckNoise

OBS, ACT = 4, 2
SMALL = DDPGConfig(hidden=(16, 16), batch_size=8, buffer_size=64, warmup_steps=20)


@pytest.fixture(autouse=True)
def _one_torch_thread():
    """One intra-op thread, as training runs use: tiny matrices gain nothing from more, and
    on a loaded machine extra OpenMP threads make each update ~20x slower."""
    threads = torch.get_num_threads()
    configure_torch(1)
    yield
    torch.set_num_threads(threads)


def _agent(config=SMALL, seed=0, obs_scale=None) -> DDPGAgent:
    return DDPGAgent(OBS, ACT, config, seed=seed, obs_scale=obs_scale)


def _weights(agent: DDPGAgent) -> list[torch.Tensor]:
    nets = (agent.actor, agent.critic, agent.actor_target, agent.critic_target)
    return [p for net in nets for p in net.state_dict().values()]


def _toy_step(obs: np.ndarray, action: np.ndarray, rng: np.random.Generator):
    """A random linear system: enough to drive acting, storing and updating."""
    next_obs = 0.9 * obs + 0.1 * np.concatenate([action, action]) + 0.05 * rng.normal(size=OBS)
    return next_obs, -float(obs @ obs)


def _run(agent: DDPGAgent, obs: np.ndarray, rng: np.random.Generator, steps: int) -> np.ndarray:
    """``steps`` exploring env steps, with updates as due; episodes of 15 steps."""
    for _ in range(steps):
        if agent.env_steps % 15 == 0:
            agent.reset_noise()
        action = agent.act(obs, explore=True)
        next_obs, reward = _toy_step(obs, action, rng)
        agent.observe(obs, action, reward, next_obs, agent.env_steps % 15 == 14)
        for _ in range(agent.updates_due(1)):
            agent.update()
        obs = next_obs
    return obs


# --- config ---------------------------------------------------------------------------------


def test_config_from_mapping_round_trips_and_converts_lists():
    config = DDPGConfig.from_mapping({"hidden": [32, 16], "gamma": 0.9, "batch_size": 64})
    assert config.hidden == (32, 16) and config.gamma == 0.9 and config.batch_size == 64
    assert DDPGConfig.from_mapping(config.to_dict()) == config
    assert DDPGConfig().to_dict()["hidden"] == [256, 256]


def test_config_rejects_unknown_keys_listing_the_accepted_ones():
    with pytest.raises(ConfigError, match="lr.*accepted: hidden, actor_lr") as error:
        DDPGConfig.from_mapping({"lr": 1e-3})
    assert "\n" not in str(error.value)


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("hidden", ()),
        ("hidden", (64, 0)),
        ("hidden", [64]),
        ("actor_lr", 0.0),
        ("critic_lr", float("nan")),
        ("gamma", 1.5),
        ("tau", 0.0),
        ("batch_size", 0),
        ("batch_size", 2.5),
        ("buffer_size", 10),
        ("warmup_steps", -1),
        ("updates_per_step", 0.0),
        ("ou_theta", -0.1),
        ("ou_sigma", float("inf")),
        ("ou_dt", 0.0),
        ("ou_theta", 2.0),
        ("reward_scale", -1.0),
        ("critic_grad_clip", -1.0),
        ("torch_threads", True),
        ("gamma", "0.9"),
    ],
)
def test_config_rejects_bad_values_in_one_line(field, value):
    with pytest.raises(ConfigError, match=field) as error:
        DDPGConfig(**{field: value})
    assert "\n" not in str(error.value)


# --- networks -------------------------------------------------------------------------------


def test_network_output_shapes_and_action_bounds():
    actor, critic = Actor(OBS, ACT, (8, 8)), Critic(OBS, ACT, (8, 8))
    initialise(actor, torch.Generator().manual_seed(0))
    initialise(critic, torch.Generator().manual_seed(1))
    obs = 100.0 * torch.randn(5, OBS, generator=torch.Generator().manual_seed(0))
    action = actor(obs)
    assert action.shape == (5, ACT) and critic(obs, action).shape == (5,)
    assert action.abs().max() <= 1.0 and action.abs().max() > 0.0


def test_initialise_uses_only_the_given_generator():
    global_state = torch.get_rng_state()
    a, b = Actor(OBS, ACT, (8, 8)), Actor(OBS, ACT, (8, 8))
    initialise(a, torch.Generator().manual_seed(3))
    torch.manual_seed(12345)  # must not matter
    initialise(b, torch.Generator().manual_seed(3))
    for p, q in zip(a.parameters(), b.parameters(), strict=True):
        assert torch.equal(p, q)
    last = a.net[-1]
    assert last.weight.abs().max() <= FINAL_LAYER_BOUND and last.bias.abs().max() <= 3e-3
    assert a.net[0].weight.abs().max() > 0.1  # fan-in bound 1/√4 = 0.5 for the first layer
    torch.set_rng_state(global_state)


def test_agent_leaves_global_rngs_alone():
    torch_state = torch.get_rng_state()
    numpy_state = np.random.get_state()  # noqa: NPY002 (the legacy global RNG is the point)
    agent = _agent()
    _run(agent, np.ones(OBS), np.random.default_rng(0), 40)
    assert torch.equal(torch.get_rng_state(), torch_state)
    assert np.random.get_state()[1].tolist() == numpy_state[1].tolist()  # noqa: NPY002


def test_soft_update_endpoints_and_midpoint():
    gen = torch.Generator().manual_seed(0)
    source, target = Critic(OBS, ACT, (8,)), Critic(OBS, ACT, (8,))
    initialise(source, gen)
    initialise(target, gen)
    before = [p.clone() for p in target.parameters()]
    soft_update(target, source, 0.0)
    assert all(torch.equal(p, q) for p, q in zip(target.parameters(), before, strict=True))
    soft_update(target, source, 0.5)
    for p, s, b in zip(target.parameters(), source.parameters(), before, strict=True):
        torch.testing.assert_close(p, (s + b) / 2)
    soft_update(target, source, 1.0)
    assert all(
        torch.equal(p, s) for p, s in zip(target.parameters(), source.parameters(), strict=True)
    )
    with pytest.raises(ConfigError):
        soft_update(target, source, 1.5)


# --- acting ---------------------------------------------------------------------------------


@pytest.mark.parametrize("explore", [False, True])
@pytest.mark.parametrize("warmup_steps", [0, 20])
def test_act_shapes_and_bounds_for_single_and_batch(explore, warmup_steps):
    agent = _agent(
        DDPGConfig(hidden=(16,), batch_size=8, buffer_size=64, warmup_steps=warmup_steps)
    )
    rng = np.random.default_rng(0)
    single = agent.act(rng.normal(size=OBS), explore=explore)
    batch = agent.act(rng.normal(size=(7, OBS)), explore=explore)
    assert single.shape == (ACT,) and batch.shape == (7, ACT)
    assert single.dtype == batch.dtype == np.float64
    assert np.abs(single).max() <= 1.0 and np.abs(batch).max() <= 1.0


def test_single_fast_path_matches_the_actor_module():
    agent = _agent(obs_scale=np.array([1.0, 2.0, 4.0, 0.5]))
    _run(agent, np.ones(OBS), np.random.default_rng(0), 60)  # weights moved by updates
    obs = np.random.default_rng(1).normal(size=(5, OBS))
    batch = agent.policy_action(obs)
    singles = np.array([agent.policy_action(o) for o in obs])
    np.testing.assert_allclose(singles, batch, atol=1e-6)
    with torch.no_grad():
        direct = agent.actor(torch.tensor(obs / agent.obs_scale, dtype=torch.float32))
    np.testing.assert_allclose(batch, direct.numpy(), atol=1e-6)


def test_obs_scale_divides_observations_before_the_networks():
    scale = np.array([10.0, 1.0, 100.0, 2.0])
    scaled, plain = _agent(obs_scale=scale), _agent()
    obs = np.array([3.0, -1.0, 50.0, 0.4])
    np.testing.assert_allclose(scaled.policy_action(obs), plain.policy_action(obs / scale))


def test_warmup_actions_are_the_noise_alone_then_actor_plus_noise():
    config = DDPGConfig(hidden=(16,), batch_size=8, buffer_size=512, warmup_steps=300)
    agent = _agent(replace(config, actor_final_init=0.5))  # an actor far from zero
    obs = np.zeros(OBS)
    warm = np.array([agent.act(obs, explore=True) for _ in range(300)])
    # training's rule (OrnsteinUhlenbeckNoise.explore): the same noise process, no actor
    noise = OrnsteinUhlenbeckNoise(ACT, 0.15, 0.2, 1.0, _agent(config)._noise_rng)  # fresh
    assert np.array_equal(warm, np.array([noise.explore(None) for _ in range(300)]))
    assert abs(warm.mean()) < 0.15 and 0.2 < warm.std() < 0.6  # correlated, not uniform
    for _ in range(300):
        agent.observe(obs, np.zeros(ACT), 0.0, obs, False)
    acting = np.array([agent.act(obs, explore=True) for _ in range(300)])
    noisy = acting - agent.policy_action(obs)
    assert abs(noisy.mean()) < 0.15 and 0.2 < noisy.std() < 0.6  # OU std √0.144 = 0.38
    assert abs(acting.mean() - agent.policy_action(obs).mean()) < 0.15
    # One OU process per batch row: rows are independent, not copies.
    rows = agent.act(np.zeros((3, OBS)), explore=True)
    assert len({tuple(row) for row in rows}) == 3


def test_bad_observations_raise():
    agent = _agent()
    with pytest.raises(StateError, match="shape"):
        agent.act(np.zeros(OBS + 1), explore=False)
    with pytest.raises(StateError, match="finite"):
        agent.act(np.array([0.0, np.nan, 0.0, 0.0]), explore=False)
    with pytest.raises(StateError, match="finite"):
        agent.act(np.full((2, OBS), np.inf), explore=True)
    with pytest.raises(ConfigError, match="obs_scale"):
        _agent(obs_scale=np.array([1.0, 0.0, 1.0, 1.0]))


# --- the update schedule --------------------------------------------------------------------


def _due_per_step(config: DDPGConfig, steps: int) -> list[int]:
    agent = _agent(config)
    due = []
    for _ in range(steps):
        agent.observe(np.zeros(OBS), np.zeros(ACT), 0.0, np.zeros(OBS), False)
        due.append(agent.updates_due(1))
    return due


def test_no_updates_during_warmup_or_before_a_batch_is_stored():
    due = _due_per_step(SMALL, 30)
    assert due == [0] * 20 + [1] * 10
    config = DDPGConfig(hidden=(8,), batch_size=16, buffer_size=64, warmup_steps=4)
    assert _due_per_step(config, 20) == [0] * 15 + [1] * 5


@pytest.mark.parametrize(("rate", "expected"), [(0.1, [0] * 9 + [1]), (2.5, [2, 3]), (1.0, [1])])
def test_fractional_updates_per_step(rate, expected):
    config = DDPGConfig(
        hidden=(8,), batch_size=1, buffer_size=64, warmup_steps=0, updates_per_step=rate
    )
    assert _due_per_step(config, 40) == expected * (40 // len(expected))


def test_updates_due_for_a_batch_of_steps_crossing_the_warmup():
    agent = _agent(
        DDPGConfig(hidden=(8,), batch_size=4, buffer_size=64, warmup_steps=10, updates_per_step=0.5)
    )
    zeros = np.zeros((12, OBS))
    agent.observe(zeros, np.zeros((12, ACT)), np.zeros(12), zeros, np.zeros(12))
    assert agent.env_steps == 12 and agent.updates_due(12) == 1  # 2 eligible steps × 0.5


def test_update_needs_a_full_batch():
    with pytest.raises(StateError, match="8 transitions"):
        _agent().update()


# --- determinism and resume -----------------------------------------------------------------


def test_one_seed_gives_identical_weights_and_different_seeds_differ():
    agents = [_agent(seed=s) for s in (4, 4, 5)]
    for agent in agents:
        _run(agent, np.ones(OBS), np.random.default_rng(0), 80)
    a, b, c = (_weights(agent) for agent in agents)
    assert agents[0].n_updates == 60
    assert all(torch.equal(p, q) for p, q in zip(a, b, strict=True))
    assert not any(torch.equal(p, q) for p, q in zip(a, c, strict=True) if p.abs().sum() > 0)


@pytest.mark.parametrize("split", [20, 52])  # during warm-up; mid-episode after a buffer wrap
def test_resume_from_a_checkpoint_is_bit_identical(split):
    config = DDPGConfig(
        hidden=(16, 16),
        batch_size=8,
        buffer_size=40,
        warmup_steps=25,
        updates_per_step=0.7,
        critic_grad_clip=1.0,
    )
    scale = np.array([1.0, 2.0, 0.5, 3.0])
    straight = _agent(config, seed=11, obs_scale=scale)
    end_straight = _run(straight, np.ones(OBS), np.random.default_rng(0), 100)

    env_rng = np.random.default_rng(0)
    first = _agent(config, seed=11, obs_scale=scale)
    obs = _run(first, np.ones(OBS), env_rng, split)
    stream = io.BytesIO()
    torch.save(first.state_dict(), stream)
    stream.seek(0)
    resumed = _agent(config, seed=999)  # its own seed and scale must not matter
    resumed.load_state_dict(torch.load(stream))  # weights_only: tensors and plain values
    end_resumed = _run(resumed, obs, env_rng, 100 - split)

    np.testing.assert_array_equal(end_straight, end_resumed)
    assert (resumed.env_steps, resumed.n_updates) == (straight.env_steps, straight.n_updates)
    assert all(
        torch.equal(p, q) for p, q in zip(_weights(straight), _weights(resumed), strict=True)
    )
    for name in ("actor_optim", "critic_optim"):
        a, b = getattr(straight, name).state_dict(), getattr(resumed, name).state_dict()
        for key, state in a["state"].items():
            assert all(torch.equal(state[k], b["state"][key][k]) for k in state)
    np.testing.assert_array_equal(straight.obs_scale, resumed.obs_scale)


def test_state_dict_is_a_snapshot():
    agent = _agent()
    _run(agent, np.ones(OBS), np.random.default_rng(0), 30)
    state = agent.state_dict()
    saved = state["actor"]["net.0.weight"].clone()
    _run(agent, np.ones(OBS), np.random.default_rng(1), 10)
    assert torch.equal(state["actor"]["net.0.weight"], saved)
    assert not torch.equal(agent.actor.net[0].weight, saved)


def test_loading_a_checkpoint_of_another_config_or_size_fails_in_one_line():
    state = _agent().state_dict()
    other = DDPGConfig(hidden=(16, 16), batch_size=8, buffer_size=64, warmup_steps=20, gamma=0.9)
    with pytest.raises(ConfigError, match=r"gamma=0.99 \(agent: 0.9\)") as error:
        DDPGAgent(OBS, ACT, other, seed=0).load_state_dict(state)
    assert "\n" not in str(error.value)
    with pytest.raises(ConfigError, match="obs_dim"):
        DDPGAgent(OBS + 1, ACT, SMALL, seed=0).load_state_dict(state)


def test_actor_state_rebuilds_the_deterministic_policy():
    agent = _agent(obs_scale=np.array([2.0, 1.0, 1.0, 5.0]))
    _run(agent, np.ones(OBS), np.random.default_rng(0), 40)
    stream = io.BytesIO()
    torch.save(agent.actor_state(), stream)
    stream.seek(0)
    policy = ActorPolicy.from_state(torch.load(stream))
    obs = np.random.default_rng(2).normal(size=(6, OBS))
    np.testing.assert_array_equal(policy(obs), agent.policy_action(obs))
    np.testing.assert_array_equal(policy(obs[0]), agent.policy_action(obs[0]))


def test_configure_torch_validates_threads():
    with pytest.raises(ConfigError):
        configure_torch(0)


# --- learning -------------------------------------------------------------------------------

DT, HORIZON = 0.1, 50
"""Double integrator: time step [s] and episode length [steps] (no terminal state)."""


def _integrator_step(state: np.ndarray, u: float) -> tuple[np.ndarray, float]:
    """State (x [m], v [m/s]), acceleration u [m/s²] in [-1, 1]; semi-implicit Euler."""
    x, v = state
    reward = -(x * x + 0.1 * v * v + 0.01 * u * u)
    v = v + u * DT
    return np.array([x + v * DT, v]), reward


def _mean_return(policy, starts: np.ndarray) -> float:
    total = 0.0
    for x0 in starts:
        state = np.array([x0, 0.0])
        for _ in range(HORIZON):
            state, reward = _integrator_step(state, float(policy(state)[0]))
            total += reward
    return total / len(starts)


def test_learns_to_stop_a_double_integrator_at_the_origin():
    """From x0 ~ U(-1, 1) at rest. Measured over seeds 0-3 (5000 steps, ~9 s on one core):
    mean return -3.4 … -5.2 against -18.3 for u = 0 and -31 for uniform random actions;
    a saturated finite-horizon LQR gets -2.85. The warm-up explores with the OU noise alone
    (training's rule): a fast one (θ 0.5, σ 0.5) covers the states in 500 steps, where θ
    0.15, σ 0.3 left seed 0 at -19.5 (seeds 1-3: -6.7 … -8.7)."""
    config = DDPGConfig(
        hidden=(64, 64),
        actor_lr=1e-3,
        gamma=0.95,
        tau=0.01,
        batch_size=64,
        buffer_size=100_000,
        warmup_steps=500,
        ou_theta=0.5,
        ou_sigma=0.5,
    )
    agent = DDPGAgent(2, 1, config, seed=0)
    rng = np.random.default_rng(1000)
    while agent.env_steps < 5000:
        state = np.array([rng.uniform(-1.0, 1.0), 0.0])
        agent.reset_noise()
        for _ in range(HORIZON):
            action = agent.act(state, explore=True)
            next_state, reward = _integrator_step(state, float(action[0]))
            agent.observe(state, action, reward, next_state, False)  # time limit: not done
            for _ in range(agent.updates_due(1)):
                agent.update()
            state = next_state
    starts = np.linspace(-1.0, 1.0, 21)
    random_rng = np.random.default_rng(0)
    trained = _mean_return(agent.policy_action, starts)
    zero = _mean_return(lambda s: np.zeros(1), starts)
    random = _mean_return(lambda s: random_rng.uniform(-1.0, 1.0, 1), starts)
    assert agent.n_updates == 4500
    assert -trained < 0.4 * -random and -trained < 0.7 * -zero, (trained, zero, random)


# --- residual-policy options ------------------------------------------------------------------


def test_a_zero_final_layer_starts_the_residual_at_exactly_zero():
    agent = _agent(DDPGConfig(hidden=(16, 16), batch_size=8, buffer_size=64, actor_final_init=0.0))
    obs = np.random.default_rng(0).normal(size=(10, OBS))
    assert np.all(agent.policy_action(obs) == 0.0)


def test_critic_burn_in_leaves_the_actor_until_it_ends():
    config = DDPGConfig(
        hidden=(16, 16), batch_size=8, buffer_size=64, warmup_steps=0, critic_burn_in=5
    )
    agent = _agent(config)
    rng = np.random.default_rng(1)
    agent.observe(
        rng.normal(size=(32, OBS)), rng.uniform(-1, 1, (32, ACT)), rng.normal(size=32),
        rng.normal(size=(32, OBS)), np.zeros(32),
    )  # fmt: skip
    actor = [p.clone() for p in agent.actor.parameters()]
    critic = [p.clone() for p in agent.critic.parameters()]
    for _ in range(5):
        agent.update()
    assert all(torch.equal(a, b) for a, b in zip(actor, agent.actor.parameters(), strict=True))
    assert not all(
        torch.equal(a, b) for a, b in zip(critic, agent.critic.parameters(), strict=True)
    )
    agent.update()
    assert not all(torch.equal(a, b) for a, b in zip(actor, agent.actor.parameters(), strict=True))


def test_the_action_penalty_pulls_the_actor_towards_zero():
    """With a critic that ignores the action, only the penalty moves the actor: its actions
    shrink."""
    config = DDPGConfig(
        hidden=(16, 16), batch_size=32, buffer_size=64, warmup_steps=0, action_penalty=10.0,
        actor_final_init=0.3, critic_lr=1e-12, actor_lr=1e-2,
    )  # fmt: skip
    agent = _agent(config)
    rng = np.random.default_rng(2)
    obs = rng.normal(size=(64, OBS))
    agent.observe(obs, rng.uniform(-1, 1, (64, ACT)), np.zeros(64), obs, np.zeros(64))
    before = np.abs(agent.policy_action(obs)).mean()
    for _ in range(50):
        agent.update()
    assert np.abs(agent.policy_action(obs)).mean() < 0.2 * before


def test_the_zero_residual_outputs_zero_and_leaves_the_snapshot_alone() -> None:
    agent = DDPGAgent(5, 3, DDPGConfig(hidden=(8, 8), actor_final_init=0.5), seed=1)
    state = agent.actor_state()
    obs = np.linspace(-1.0, 1.0, 5)
    before = ActorPolicy.from_state(state)(obs)
    assert np.abs(before).max() > 0.0
    zero = ActorPolicy.zero_residual(state)
    np.testing.assert_array_equal(ActorPolicy.from_state(zero)(obs), np.zeros(3))
    np.testing.assert_array_equal(ActorPolicy.from_state(state)(obs), before)


# --- the actor step's shortcuts ---------------------------------------------------------------

PRIOR = DDPGConfig(
    hidden=(16, 16), batch_size=8, buffer_size=64, warmup_steps=0, prior_weight=2.0,
    action_penalty=0.1,
)  # fmt: skip


def _filled(config: DDPGConfig) -> DDPGAgent:
    agent = _agent(config, seed=3)
    rng = np.random.default_rng(4)
    agent.observe(
        rng.normal(size=(32, OBS)), rng.uniform(-1, 1, (32, ACT)), rng.normal(size=32),
        rng.normal(size=(32, OBS)), np.zeros(32),
    )  # fmt: skip
    return agent


@pytest.mark.parametrize("final_init", [0.0, 0.3])
def test_the_actor_step_equals_the_one_with_the_critics_gradients_and_the_priors_forward(
    final_init,
):
    """The update freezes the critic for the actor's backward pass and, with a prior that
    acts 0 everywhere, skips the prior's forward pass: the weights after 12 updates are
    those of an agent that does neither, to the bit."""
    config = replace(PRIOR, actor_final_init=final_init)
    fast, plain = _filled(config), _filled(config)
    assert fast._prior_is_zero == (final_init == 0.0)
    plain._prior_is_zero = False  # the prior's forward pass, as before the shortcut
    critic = plain.critic
    critic.requires_grad_ = lambda requires_grad=True: critic  # the critic's gradients too
    for _ in range(12):
        fast.update()
        plain.update()
    assert all(p.requires_grad for p in fast.critic.parameters())
    for a, b in zip(_weights(fast), _weights(plain), strict=True):
        assert torch.equal(a, b)
    assert not torch.equal(fast.actor.net[0].weight, _filled(config).actor.net[0].weight)


def test_a_restored_prior_is_recognised_as_zero_or_not():
    for final_init in (0.0, 0.3):
        agent = _filled(replace(PRIOR, actor_final_init=final_init))
        agent.update()
        buffer = io.BytesIO()
        torch.save(agent.state_dict(), buffer)
        buffer.seek(0)
        restored = _agent(replace(PRIOR, actor_final_init=final_init), seed=9)
        restored.load_state_dict(torch.load(buffer, weights_only=True))
        assert restored._prior_is_zero == (final_init == 0.0)
        for a, b in zip(agent.prior.parameters(), restored.prior.parameters(), strict=True):
            assert torch.equal(a, b)


def test_the_averaged_actor_is_what_a_run_ships_and_it_resumes():
    """``policy_average``: an exponential average of the actor's weights, moved with each
    actor step; ``shipped_state`` holds it (the actor itself without an average), and a
    checkpoint restores it."""
    config = DDPGConfig(hidden=(8, 8), batch_size=4, buffer_size=64, warmup_steps=4)
    plain = DDPGAgent(3, 2, config, seed=0)
    assert torch.equal(
        plain.shipped_state()["actor"]["net.0.weight"], plain.actor_state()["actor"]["net.0.weight"]
    )
    averaged = DDPGAgent(3, 2, replace(config, policy_average=0.1), seed=0)
    rng = np.random.default_rng(0)
    obs = rng.normal(size=(16, 3))
    averaged.observe(obs, rng.uniform(-1, 1, (16, 2)), -np.ones(16), obs, np.zeros(16))
    start = averaged.shipped_state()["actor"]
    expected = {k: v.clone() for k, v in start.items()}
    for _ in range(5):
        averaged.update()
        for key, value in averaged.actor.state_dict().items():
            expected[key] = 0.9 * expected[key] + 0.1 * value
    shipped = averaged.shipped_state()["actor"]
    actor = averaged.actor_state()["actor"]
    for key in shipped:
        assert torch.allclose(shipped[key], expected[key], atol=1e-6)
    assert not torch.equal(shipped["net.0.weight"], actor["net.0.weight"])
    again = DDPGAgent(3, 2, replace(config, policy_average=0.1), seed=1)
    again.load_state_dict(averaged.state_dict())
    for key, value in again.shipped_state()["actor"].items():
        assert torch.equal(value, shipped[key])
    with pytest.raises(ConfigError):
        DDPGConfig(policy_average=1.5)

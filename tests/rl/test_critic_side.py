"""The critic's switchable parts (DDPGConfig): each runs, changes what it should and nothing
else, resumes bit for bit; n-step rows by hand; the critic warm-up leaves the actor alone."""

import io

import numpy as np
import pytest
import torch

from pushctl.errors import ConfigError, StateError
from pushctl.rl.config import DDPGConfig
from pushctl.rl.critic_side import critic_warmup_due, n_step_rows, warm_critic
from pushctl.rl.ddpg import DDPGAgent, configure_torch

OBS, ACT, PRIV = 4, 2, 3
BASE = dict(hidden=(16, 16), batch_size=8, buffer_size=64, warmup_steps=20)
PARTS = {
    "twin": dict(twin_critics=True, actor_delay=2),
    "n_step": dict(n_step=3),
    "layer_norm": dict(critic_layer_norm=True),
    "warmup": dict(critic_warmup_updates=5),
    "privileged": dict(privileged_critic=True),
}


@pytest.fixture(autouse=True)
def _one_torch_thread():
    threads = torch.get_num_threads()
    configure_torch(1)
    yield
    torch.set_num_threads(threads)


def _agent(part: str, seed: int = 0) -> DDPGAgent:
    config = DDPGConfig(**BASE, **PARTS[part])
    priv = np.ones(PRIV) if config.privileged_critic else None
    return DDPGAgent(OBS, ACT, config, seed=seed, priv_scale=priv)


def _episode(rng: np.random.Generator, agent: DDPGAgent, steps: int = 10) -> dict:
    obs = rng.normal(size=(steps, OBS))
    rows = {
        "obs": obs,
        "action": np.clip(rng.normal(size=(steps, ACT)), -1, 1),
        "reward": -np.square(obs).sum(axis=1),
        "next_obs": np.roll(obs, -1, axis=0),
        "done": np.r_[np.zeros(steps - 1), 1.0],
    }
    if agent.priv_dim:
        rows["priv"] = rng.normal(size=(steps, PRIV))
        rows["next_priv"] = np.roll(rows["priv"], -1, axis=0)
    return n_step_rows({k: v.astype(np.float32) for k, v in rows.items()}, agent.config.n_step, 0.9)


def _run(agent: DDPGAgent, rng: np.random.Generator, episodes: int) -> None:
    for _ in range(episodes):
        rows = _episode(rng, agent)
        agent.observe(
            rows["obs"], rows["action"], rows["reward"], rows["next_obs"], rows["done"],
            rows.get("priv"), rows.get("next_priv"),
        )  # fmt: skip
        if critic_warmup_due(agent):
            warm_critic(agent)
        for _ in range(agent.updates_due(10)):
            agent.update()


def _tensors(agent: DDPGAgent) -> list[torch.Tensor]:
    state = agent.state_dict()
    names = ["actor", "critic", "actor_target", "critic_target", "twin_critic", "twin_target"]
    return [t for name in names if name in state for t in state[name].values()]


def test_n_step_rows_sum_discounted_rewards_up_to_the_terminal():
    rows = {
        "obs": np.arange(5, dtype=np.float32)[:, None],
        "reward": np.array([1, 2, 3, 4, 5], dtype=np.float32),
        "next_obs": np.arange(1, 6, dtype=np.float32)[:, None],
        "done": np.array([0, 0, 0, 0, 1], dtype=np.float32),
    }
    out = n_step_rows(rows, 3, 0.5)
    np.testing.assert_allclose(out["reward"], [2.75, 4.5, 6.25, 6.5, 5.0])
    np.testing.assert_array_equal(out["next_obs"][:, 0], [3, 4, 5, 5, 5])
    np.testing.assert_array_equal(out["done"], [0, 0, 1, 1, 1])
    assert n_step_rows(rows, 1, 0.5) is rows


@pytest.mark.parametrize("part", sorted(PARTS))
def test_each_part_trains_and_resumes_bit_for_bit(part):
    straight = _agent(part)
    _run(straight, np.random.default_rng(1), 8)
    first = _agent(part)
    rng = np.random.default_rng(1)
    _run(first, rng, 4)
    stream = io.BytesIO()
    torch.save(first.state_dict(), stream)
    stream.seek(0)
    resumed = _agent(part, seed=7)
    resumed.load_state_dict(torch.load(stream))
    _run(resumed, rng, 4)
    assert straight.n_updates > 0 and straight.n_updates == resumed.n_updates
    pairs = zip(_tensors(straight), _tensors(resumed), strict=True)
    assert all(torch.equal(a, b) for a, b in pairs)


def test_the_parts_shape_the_critic_and_never_the_actor():
    plain = DDPGAgent(OBS, ACT, DDPGConfig(**BASE), seed=0)
    twin, norm, priv = _agent("twin"), _agent("layer_norm"), _agent("privileged")
    assert plain.twin is None and twin.twin is not None
    assert any(isinstance(m, torch.nn.LayerNorm) for m in norm.critic.modules())
    assert not any(isinstance(m, torch.nn.LayerNorm) for m in norm.actor.modules())
    assert priv.critic.obs_dim == OBS + PRIV and priv.actor.obs_dim == OBS
    # the actor and first critic draw as without the parts
    for agent in (twin, norm, priv):
        assert torch.equal(agent.actor.net[0].weight, plain.actor.net[0].weight)
    assert torch.equal(twin.critic.net[0].weight, plain.critic.net[0].weight)


def test_critic_warmup_moves_the_critic_alone_and_counts_no_update():
    agent = _agent("warmup")
    rng = np.random.default_rng(3)
    for _ in range(2):  # 20 decisions: the warm-up
        rows = _episode(rng, agent)
        agent.observe(rows["obs"], rows["action"], rows["reward"], rows["next_obs"], rows["done"])
    actor = [p.clone() for p in agent.actor.parameters()]
    critic = [p.clone() for p in agent.critic.parameters()]
    assert critic_warmup_due(agent)
    warm_critic(agent)
    assert not critic_warmup_due(agent) and agent.n_updates == 0
    assert all(torch.equal(a, b) for a, b in zip(actor, agent.actor.parameters(), strict=True))
    moved = zip(critic, agent.critic.parameters(), strict=True)
    assert not all(torch.equal(a, b) for a, b in moved)


def test_a_privileged_buffer_needs_its_rows_and_bad_parts_are_refused():
    agent = _agent("privileged")
    rows = _episode(np.random.default_rng(0), agent)
    with pytest.raises(StateError):
        agent.observe(rows["obs"], rows["action"], rows["reward"], rows["next_obs"], rows["done"])
    for bad in (dict(n_step=0), dict(actor_delay=0), dict(twin_critics=1), dict(target_noise=-1)):
        with pytest.raises(ConfigError):
            DDPGConfig(**bad)


def _moved(before: list[torch.Tensor], module: torch.nn.Module) -> bool:
    return any(
        not torch.equal(a, b) for a, b in zip(before, module.state_dict().values(), strict=True)
    )


def test_with_a_delayed_actor_every_target_moves_only_with_the_actor_step():
    """TD3 (Fujimoto et al. 2018, Algorithm 1): the critics' targets move with the delayed
    actor step, not on the critic-only updates between."""
    agent = _agent("twin")
    rng = np.random.default_rng(3)
    _run(agent, rng, 4)
    assert agent.n_updates > 0 and agent.twin is not None
    rows = _episode(rng, agent)
    agent.observe(rows["obs"], rows["action"], rows["reward"], rows["next_obs"], rows["done"])
    modules = (agent.critic_target, agent.twin.target, agent.actor)
    for _ in range(4):
        due = agent.n_updates % agent.config.actor_delay == 0
        before = [[t.clone() for t in m.state_dict().values()] for m in modules]
        agent.update()
        assert [_moved(b, m) for b, m in zip(before, modules, strict=True)] == [due] * 3

"""The demonstrated warm-up: the feedback law acting in warm-up episodes, behaviour cloning of
the actor on the buffer, and a run with both resumed to the same weights."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from pushctl.control.feedback import load_feedback_gains
from pushctl.control.gains import load_gains
from pushctl.errors import ConfigError
from pushctl.rl.collect import Behaviour, collect_episode, episode_rngs
from pushctl.rl.config import DDPGConfig
from pushctl.rl.ddpg import DDPGAgent
from pushctl.rl.policy import finish_with_policy
from pushctl.rl.presets import load_preset
from pushctl.rl.train import Trainer
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.feedback_actor import FeedbackActor

TINY = """
[train]
episodes = 4
checkpoint_every = 1
pd_every = 2
workers = 0

[env]
objects = ["cube"]
profiles = ["constant"]
duration = 1.0
gate_threshold = 0.0
action_repeat = 5

[ddpg]
hidden = [16, 16]
batch_size = 16
buffer_size = 1000
warmup_steps = 40
updates_per_step = 0.2
reward_scale = 10.0
critic_burn_in = 3
demonstrator = "feedback"
imitation_updates = 50
prior_weight = 1.0
"""


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ({"demonstrator": "expert"}, "demonstrator must be one of none, feedback"),
        ({"imitation_updates": -1}, "imitation_updates must be an integer >= 0"),
    ],
)
def test_bad_demonstration_settings_are_one_line(values: dict, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        DDPGConfig.from_mapping(values)


def test_imitation_fits_the_actor_to_the_buffers_actions_once() -> None:
    config = DDPGConfig(hidden=(32, 32), batch_size=64, warmup_steps=500, imitation_updates=1500)
    agent = DDPGAgent(4, 2, config, seed=3)
    rng = np.random.default_rng(0)
    obs = rng.uniform(-1.0, 1.0, size=(500, 4))
    actions = np.tanh(np.stack([0.8 * obs[:, 0] - 0.3 * obs[:, 1], 0.5 * obs[:, 2]], axis=1))
    assert not agent.imitation_due  # nothing observed yet
    agent.observe(obs, actions, np.zeros(500), obs, np.zeros(500))
    assert agent.imitation_due
    before = float(np.mean((agent.policy_action(obs) - actions) ** 2))
    agent.imitate()
    after = float(np.mean((agent.policy_action(obs) - actions) ** 2))
    assert after < 0.02 * before and after < 1e-3
    assert not agent.imitation_due
    for mine, target in zip(agent.actor.parameters(), agent.actor_target.parameters(), strict=True):
        assert torch.equal(mine, target)
    assert agent.n_updates == 0  # the critic's burn-in counts DDPG updates only


def test_the_warm_up_demonstrator_pushes_as_the_feedback_controller() -> None:
    """With no exploration noise, a warm-up episode with the demonstrator is the feedback
    law's push: the same trace as the evaluation's feedback loop."""
    config = EnvConfig(objects=("cube",), profiles=("constant",), duration=1.0, gate_threshold=0.0)
    gains, law = load_gains(), load_feedback_gains()
    behaviour = Behaviour(
        warmup=True, actor_state=None, ou_theta=0.15, ou_sigma=0.0, ou_dt=1.0, demonstrator=law
    )
    env = PushEnv(config, gains)
    record = collect_episode(config, gains, seed=4, episode=2, behaviour=behaviour, env=env)
    assert env.episode is not None
    demonstrated = env.episode.trace()
    assert np.abs(record.transitions["action"]).max() > 0.0  # the law acted

    replay = PushEnv(config, gains)
    replay.reset(seed=episode_rngs(4, 2)[0])
    finish_with_policy(replay, FeedbackActor(replay, law))
    assert replay.episode is not None
    np.testing.assert_array_equal(replay.episode.trace().object_pose, demonstrated.object_pose)


def test_a_demonstrated_run_resumes_to_the_same_weights(tmp_path: Path) -> None:
    path = tmp_path / "tiny.toml"
    path.write_text(TINY)
    preset = load_preset(str(path))
    straight = Trainer.start(preset, 2, tmp_path / "straight")
    straight.run(4, made_by="# made by: test")
    assert straight.agent.imitation_due is False and straight.agent.n_updates > 3

    first = Trainer.start(preset, 2, tmp_path / "run")

    def stop_after_second(progress) -> None:
        if progress.episodes_done == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        first.run(4, on_episode=stop_after_second, made_by="# made by: test")
    resumed = Trainer.resume(tmp_path / "run")
    resumed.run(4, made_by="# made by: test")
    for name in ("actor", "critic", "actor_target", "critic_target"):
        ours, theirs = getattr(resumed.agent, name), getattr(straight.agent, name)
        for a, b in zip(ours.state_dict().values(), theirs.state_dict().values(), strict=True):
            assert torch.equal(a, b), name
    # the cloned actor acts: not the zero residual it was initialised to
    obs = np.linspace(-1.0, 1.0, straight.agent.obs_dim)
    assert np.abs(straight.agent.policy_action(obs)).max() > 0.0


def test_the_prior_weight_holds_the_actor_near_the_cloned_one() -> None:
    """The same updates with and without the prior term: with it, the actor stays closer to
    the clone it started from."""
    rng = np.random.default_rng(1)
    obs = rng.uniform(-1.0, 1.0, size=(400, 4))
    actions = np.tanh(0.7 * obs[:, :2])
    rewards = -np.abs(obs[:, 0] - 0.5)  # a critic that prefers other actions than the clone's
    drift = {}
    for weight in (0.0, 10.0):
        config = DDPGConfig(
            hidden=(16, 16),
            batch_size=32,
            warmup_steps=400,
            imitation_updates=300,
            prior_weight=weight,
            actor_lr=1e-3,
        )
        agent = DDPGAgent(4, 2, config, seed=5)
        agent.observe(obs, actions, rewards, obs, np.ones(400))
        agent.imitate()
        cloned = agent.policy_action(obs)
        for _ in range(300):
            agent.update()
        drift[weight] = float(np.mean((agent.policy_action(obs) - cloned) ** 2))
        state = agent.state_dict()
        again = DDPGAgent(4, 2, config, seed=0)
        again.load_state_dict(state)
        assert again.prior is not None
        np.testing.assert_array_equal(again.policy_action(obs), agent.policy_action(obs))
    assert drift[10.0] < 0.5 * drift[0.0]

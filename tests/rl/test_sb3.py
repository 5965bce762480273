"""``--algo sb3-sac``: SAC's deterministic actor copied into a pushctl policy acts the same,
and the CLI refuses what such a run cannot do in one line."""

from __future__ import annotations

import gymnasium
import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.rl.networks import ActorPolicy
from pushctl.rl.sb3 import sac_actor_state

pytest.importorskip("stable_baselines3")


class _Toy(gymnasium.Env):
    observation_space = gymnasium.spaces.Box(-np.inf, np.inf, (5,), np.float32)
    action_space = gymnasium.spaces.Box(-1.0, 1.0, (3,), np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        return np.zeros(5, np.float32), {}

    def step(self, action):
        return np.ones(5, np.float32), 0.0, False, False, {}


def test_sac_actor_copies_into_a_pushctl_policy_that_acts_the_same():
    from stable_baselines3 import SAC

    model = SAC("MlpPolicy", _Toy(), policy_kwargs={"net_arch": [16, 16]}, seed=0, device="cpu")
    scale = np.array([1.0, 2.0, 0.5, 4.0, 1.0])
    policy = ActorPolicy.from_state(sac_actor_state(model, scale))
    obs = np.random.default_rng(0).normal(size=(7, 5)).astype(np.float32)
    expected, _ = model.predict(obs / scale.astype(np.float32), deterministic=True)
    np.testing.assert_allclose(policy.batch(obs), expected, atol=1e-6)


@pytest.mark.parametrize(
    "args",
    [["--algo", "td3"], ["--algo", "sb3-sac", "--resume"], ["--algo", "sb3-sac", "--seeds", "0,1"]],
)
def test_train_refuses_bad_algo_options_in_one_line(args, tmp_path):
    result = CliRunner().invoke(app, ["train", *args, "--out", str(tmp_path / "run")])
    assert result.exit_code == 2
    assert result.output.startswith("error: ") and len(result.output.strip().splitlines()) == 1


TINY_SAC = """
[train]
episodes = 8
episodes_per_round = 2
validation_per_cell = 2

[env]
objects = ["cube"]
profiles = ["constant"]
duration = 2.0
action_repeat = 10

[ddpg]
hidden = [16, 16]
batch_size = 16
buffer_size = 2000
warmup_steps = 40
updates_per_step = 0.3
"""


def test_sac_gets_the_update_rate_and_warm_up_asked_for_and_labels_the_run(tmp_path):
    """Two episodes of 20 decisions on two environments: the 40-decision warm-up is the
    learner's (two whole episodes), then 0.3 updates per decision, not per vector step;
    the last validation row names the run's episodes, not the preset's."""
    from stable_baselines3 import SAC

    from pushctl.rl.presets import load_preset
    from pushctl.rl.sb3 import MODEL, train_sac

    path = tmp_path / "tiny.toml"
    path.write_text(TINY_SAC)
    out = tmp_path / "run"
    train_sac(load_preset(str(path)), 0, out, "# made by: test", episodes=4, log=lambda _: None)
    model = SAC.load(out / MODEL, device="cpu")
    per_vector_step = model.gradient_steps / model.train_freq.frequency
    assert per_vector_step / model.n_envs == pytest.approx(0.3)
    assert model._n_updates == pytest.approx(0.3 * 2 * 20, abs=3)  # after the warm-up
    table = pd.read_csv(out / "validation.csv", comment="#")
    assert list(table["episode"]) == [0, 4]


def test_sac_refuses_each_setting_it_cannot_honour_naming_it() -> None:
    from pushctl.errors import ConfigError
    from pushctl.rl.config import DDPGConfig
    from pushctl.rl.sb3 import UNSUPPORTED, check_supported

    check_supported(DDPGConfig())
    asked = {"n_step": 3, "critic_layer_norm": True, "critic_warmup_updates": 10}
    asked |= {"privileged_critic": True, "actor_delay": 2, "policy_average": 1e-3}
    assert sorted(asked) == sorted(UNSUPPORTED)
    for key, value in asked.items():
        with pytest.raises(ConfigError, match=key):
            check_supported(DDPGConfig(**{key: value}))

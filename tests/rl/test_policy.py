"""Policy files across the residual-path change: a policy saved before ``residual_path`` and
``observe_camera`` existed loads with the settings it was trained with (the paper's velocity
path, the exact pose), so the shipped results stay reproducible; a new one keeps its own."""

from __future__ import annotations

from pathlib import Path

import pytest
import torch

from pushctl.errors import ConfigError
from pushctl.rl.config import DDPGConfig
from pushctl.rl.ddpg import DDPGAgent
from pushctl.rl.policy import load_policy, write_policy
from pushctl.task.env_config import LEGACY_VALUES, EnvConfig

SHIPPED = Path(__file__).resolve().parents[2] / "results" / "training" / "policy.pt"


def _saved(tmp_path: Path, env: EnvConfig, drop: tuple[str, ...] = ()) -> Path:
    agent = DDPGAgent(17, 3, DDPGConfig(hidden=(4, 4)), seed=0)
    path = tmp_path / "policy.pt"
    write_policy(path, agent.actor_state(), env, "# made by: test; seed 7 (training stream)")
    if drop:  # rewrite the file as a policy from before these keys existed
        state = torch.load(path, weights_only=True)
        state["env"] = {k: v for k, v in state["env"].items() if k not in drop}
        state.pop("digest", None)  # an old policy carries no digest
        torch.save(state, path)
    return path


def test_a_policy_saved_before_the_residual_path_existed_loads_on_the_velocity_path(
    tmp_path: Path,
) -> None:
    path = _saved(tmp_path, EnvConfig(action_scale_linear=0.02), drop=tuple(LEGACY_VALUES))
    loaded = load_policy(path, trust_undigested=True).env
    assert loaded.residual_path == "velocity"
    assert loaded.observe_camera is False
    assert loaded.action_scale_linear == 0.02  # saved keys keep their values


def test_a_new_policy_keeps_its_residual_path(tmp_path: Path) -> None:
    assert EnvConfig().residual_path == "reference"  # the default of new runs
    loaded = load_policy(_saved(tmp_path, EnvConfig())).env
    assert loaded == EnvConfig()
    loaded = load_policy(
        _saved(tmp_path, EnvConfig(residual_path="velocity", landing="believed"))
    ).env
    assert loaded.residual_path == "velocity" and loaded.observe_camera is True


@pytest.mark.skipif(not SHIPPED.is_file(), reason="no shipped policy in this checkout")
def test_the_shipped_policy_loads_as_it_was_trained() -> None:
    saved = torch.load(SHIPPED, weights_only=True)["env"]
    env = load_policy(SHIPPED).env
    if "residual_path" not in saved:  # a policy from before the residual_path key
        assert (env.residual_path, env.observe_camera) == ("velocity", False)
    else:  # every key it recorded comes back as it was
        assert {key: env.to_dict()[key] for key in saved} == saved


def test_a_bad_residual_path_is_one_line() -> None:
    with pytest.raises(ConfigError, match="residual_path must be one of reference, velocity"):
        EnvConfig.from_mapping({"residual_path": "torque"})
    with pytest.raises(ConfigError, match="observe_camera must be true or false"):
        EnvConfig(observe_camera=1)  # type: ignore[arg-type]

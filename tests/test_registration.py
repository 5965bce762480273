"""``import pushctl`` registers ``pushctl/Push-v1`` and ``pushctl/Push-v0``: the one line a new
user writes first, and the version the shipped policies were trained on.

Run in a fresh interpreter, since this test session has long since imported pushctl.task.
"""

from __future__ import annotations

import importlib
import subprocess
import sys
import warnings
from pathlib import Path

import gymnasium
import pytest

SHIPPED_POLICY = Path(__file__).parent.parent / "results" / "training" / "policy.pt"

MAKE_AFTER_IMPORT = """
import sys
import gymnasium as gym
import pushctl
assert "pushctl.task.env" not in sys.modules, "registration loaded the environment module"
assert "torch" not in sys.modules, "registration imported torch"
env = gym.make("pushctl/Push-v0")
assert gym.spec(pushctl.ENV_ID).id == "pushctl/Push-v1"
obs, _ = env.reset(seed=0)
print(env.spec.id, obs.shape)
"""

MAKE_WITH_PUSHCTL_FIRST = """
import sys
import pushctl
assert "numpy" not in sys.modules and "gymnasium" not in sys.modules
import gymnasium as gym
env = gym.make("pushctl/Push-v1")
print(env.spec.id)
"""

MAKE_WITH_MODULE_PREFIX = """
import gymnasium as gym
env = gym.make("pushctl:pushctl/Push-v0")
print(env.spec.id)
"""


def _run(code: str) -> str:
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=600, check=False
    )
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout


def test_import_pushctl_registers_push_env_without_loading_it() -> None:
    out = _run(MAKE_AFTER_IMPORT)
    assert out.split()[0] == "pushctl/Push-v0"


def test_import_pushctl_before_gymnasium_registers_it_once_gymnasium_loads() -> None:
    assert _run(MAKE_WITH_PUSHCTL_FIRST).strip() == "pushctl/Push-v1"


def test_gymnasium_module_prefix_imports_pushctl() -> None:
    assert _run(MAKE_WITH_MODULE_PREFIX).strip() == "pushctl/Push-v0"


def test_registration_is_idempotent() -> None:
    import pushctl.task

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a second register() would warn "Overriding environment"
        importlib.reload(pushctl.task)
    assert gymnasium.spec("pushctl/Push-v0").entry_point == "pushctl.task.versions:push_v0"
    assert gymnasium.spec("pushctl/Push-v1").entry_point == "pushctl.task.versions:push_v1"


def test_env_id_is_the_newest_version() -> None:
    import pushctl.task

    versions = sorted(pushctl.task.VERSIONS, key=lambda env_id: int(env_id.rsplit("-v", 1)[1]))
    assert pushctl.task.ENV_ID == versions[-1] == "pushctl/Push-v1"
    assert "v1:" in pushctl.task.__doc__ and "v0:" in pushctl.task.__doc__  # the version history


def test_push_v1_runs_the_shipped_policy() -> None:
    """The shipped policy acts on ``Push-v1``'s observation, the one it was trained on."""
    import numpy as np

    from pushctl.rl.policy import load_policy

    shipped = load_policy(SHIPPED_POLICY)
    env = gymnasium.make("pushctl/Push-v1")
    obs, _ = env.reset(seed=0)
    assert obs.shape == (shipped.actor.actor.obs_dim,)
    action = shipped.actor(obs.astype(np.float64))
    assert action.shape == env.action_space.shape
    env.close()


def test_push_v1_takes_its_own_defaults() -> None:
    from pushctl.task.env_config import EnvConfig

    if not hasattr(EnvConfig, "v1"):
        pytest.skip("EnvConfig.v1 (Push-v1's settings) is not in this tree")
    env = gymnasium.make("pushctl/Push-v1")
    assert env.unwrapped.config == EnvConfig.v1()
    assert gymnasium.make("pushctl/Push-v0").unwrapped.config == EnvConfig()
    given = EnvConfig(duration=1.0)
    assert gymnasium.make("pushctl/Push-v1", config=given).unwrapped.config == given

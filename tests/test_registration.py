"""``import pushctl`` registers ``pushctl/Push-v0``: the one line a new user writes first.

Run in a fresh interpreter, since this test session has long since imported pushctl.rl.
"""

from __future__ import annotations

import importlib
import subprocess
import sys
import warnings

import gymnasium

MAKE_AFTER_IMPORT = """
import sys
import gymnasium as gym
import pushctl
assert "pushctl.rl.env" not in sys.modules, "registration loaded the environment module"
assert "torch" not in sys.modules, "registration imported torch"
env = gym.make("pushctl/Push-v0")
obs, _ = env.reset(seed=0)
print(env.spec.id, obs.shape)
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


def test_gymnasium_module_prefix_imports_pushctl() -> None:
    assert _run(MAKE_WITH_MODULE_PREFIX).strip() == "pushctl/Push-v0"


def test_registration_is_idempotent() -> None:
    import pushctl.rl

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a second register() would warn "Overriding environment"
        importlib.reload(pushctl.rl)
    assert gymnasium.spec("pushctl/Push-v0").entry_point == "pushctl.rl.env:PushEnv"

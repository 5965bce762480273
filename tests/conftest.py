"""Test-wide settings.

Hypothesis runs derandomized by default, so `make test` explores the same examples on every
machine and a failure reproduces; set ``HYPOTHESIS_PROFILE=explore`` to draw fresh examples.
"""

import os

from hypothesis import settings  # (it does not load numpy)

import pushctl
from pushctl.machine.kernel_cache import drop_stale

pushctl.reproducible()  # before the test modules load numpy: the recorded digests' CPU code
drop_stale()  # before any kernel loads: a kernel's cache does not follow edits of its callees

settings.register_profile("default", derandomize=True)
settings.register_profile("explore", derandomize=False, max_examples=500)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))


import pytest  # noqa: E402


@pytest.fixture(scope="session")
def ray_local():
    """One local Ray instance (2 CPUs) for every test that runs parallel work; the code under
    test finds it connected and leaves it running."""

    from pushctl.distributed.engine import connect, shutdown

    connect(num_cpus=2)
    yield
    shutdown()


_TINY_PRESET = """
[train]
episodes = {episodes}
checkpoint_every = 2
pd_every = {pd_every}
workers = {workers}
validate_every = {validate_every}
validation_per_cell = 1

[env]
objects = ["cube"]
profiles = ["constant"]
duration = 1.0
gate_threshold = 0.0

[ddpg]
hidden = [8, 8]
batch_size = 16
buffer_size = 1000
warmup_steps = 100
updates_per_step = 0.05
reward_scale = 100.0
"""


@pytest.fixture
def write_tiny_preset(tmp_path):
    """A writer of a training preset of a few 1 s cube pushes and an 8×8 network, for the
    tests that train through Ray: ``write_tiny_preset(episodes=…, pd_every=…,
    validate_every=…, workers=…)`` returns the path of ``tmp_path/tiny.toml``."""

    def write(episodes: int, pd_every: int, validate_every: int, workers: int = 0):
        path = tmp_path / "tiny.toml"
        text = _TINY_PRESET.format(
            episodes=episodes, pd_every=pd_every, validate_every=validate_every, workers=workers
        )
        path.write_text(text)
        return path

    return write

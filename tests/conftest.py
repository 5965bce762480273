"""Test-wide settings.

Hypothesis runs derandomized by default, so `make test` explores the same examples on every
machine and a failure reproduces; set ``HYPOTHESIS_PROFILE=explore`` to draw fresh examples.
"""

import os

from hypothesis import settings

settings.register_profile("default", derandomize=True)
settings.register_profile("explore", derandomize=False, max_examples=500)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))


import pytest  # noqa: E402


@pytest.fixture(scope="session")
def ray_local():
    """One local Ray instance (2 CPUs) for every test that runs parallel work; the code under
    test finds it connected and leaves it running."""
    import ray

    from pushctl.distributed.engine import connect

    connect(num_cpus=2)
    yield
    ray.shutdown()

"""Test-wide settings.

Hypothesis runs derandomized by default, so `make test` explores the same examples on every
machine and a failure reproduces; set ``HYPOTHESIS_PROFILE=explore`` to draw fresh examples.
"""

import os

from hypothesis import settings

settings.register_profile("default", derandomize=True)
settings.register_profile("explore", derandomize=False, max_examples=500)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))

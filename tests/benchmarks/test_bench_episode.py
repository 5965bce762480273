"""make bench's closed-loop rows (benchmarks.episode): the proxy beside the simulator."""

from __future__ import annotations

import math

from benchmarks.episode import proxy_rows


def test_the_proxy_rows_time_a_step_and_its_ratio_to_the_simulators() -> None:
    step, ratio = proxy_rows(repeats=1)
    assert step["name"] == "episode cube proxy per control step" and step["unit"] == "us"
    assert ratio["name"] == "episode cube proxy / sim per control step"
    assert ratio["unit"] == "ratio"
    # not a timing assertion: both are measured, finite and positive
    assert math.isfinite(step["value"]) and step["value"] > 0.0
    assert math.isfinite(ratio["value"]) and ratio["value"] > 0.0

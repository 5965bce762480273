"""The bench's collection rows run and measure what they name: collection and raw stepping
of the same episodes, both positive rates, and their ratio."""

from __future__ import annotations

import math

from pushctl.bench.rl import collection_rows


def test_collection_rows_time_collection_beside_raw_stepping(write_tiny_preset) -> None:
    preset = write_tiny_preset(episodes=2, pd_every=1, validate_every=0)
    rows = {
        row["name"]: row for row in collection_rows(episodes=2, repeats=1, preset_name=str(preset))
    }
    raw = rows["rl raw env steps/s, resets included"]["value"]
    together = rows["rl collection env steps/s, episodes together"]["value"]
    ratio = rows["rl collection / raw env-step rate"]["value"]
    assert raw > 0 and together > 0
    assert math.isclose(ratio, together / raw)  # one repeat: the median is that repeat's
    assert rows["rl acting step / zero-residual step"]["value"] > 0
    assert "one at a time" in rows["rl collection / raw env-step rate"]["note"]

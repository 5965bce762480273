"""The bench's collection rows run and measure what they name: collection and raw stepping
of the same episodes, both positive rates of push steps, and their ratio; the acting rows
from alternating repeats, with their quartiles, and over the scenarios Push-v0 draws, with
their range (the median within it)."""

from __future__ import annotations

import math

import pytest

from benchmarks.rl import collection_rows


@pytest.mark.parametrize("repeat", [1, 5])
def test_collection_rows_time_collection_beside_raw_stepping(write_tiny_preset, repeat) -> None:
    preset = write_tiny_preset(episodes=2, pd_every=1, validate_every=0)
    text = preset.read_text().replace("duration = 1.0", f"duration = 1.0\naction_repeat = {repeat}")
    preset.write_text(text)  # a decision every `repeat` push steps: rates still in push steps
    rows = collection_rows(
        episodes=2, repeats=1, preset_name=str(preset), acting_repeats=2, scenarios=2
    )
    by_name = {row["name"]: row for row in rows}
    raw = by_name["rl raw env steps/s, resets included"]["value"]
    together = by_name["rl collection env steps/s, episodes together"]["value"]
    ratio = by_name["rl collection / raw env-step rate"]["value"]
    assert raw > 0 and together > 0
    assert math.isclose(ratio, together / raw)  # one repeat: the median is that repeat's
    for name in ("", ", Push-v0 defaults"):
        acting = by_name[f"rl acting step / zero-residual step{name}"]
        assert acting["value"] > 0 and "of 2 alternating repeats" in acting["note"]
    assert "one at a time" in by_name["rl collection / raw env-step rate"]["note"]
    drawn = by_name["rl acting step / zero-residual step, Push-v0's own scenarios"]
    low, high = (float(x) for x in drawn["note"].rsplit("; ", 1)[1].split()[0].split("-"))
    assert 0 < low <= drawn["value"] <= high and "s < 2" in drawn["note"]

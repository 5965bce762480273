"""make bench's engine rows (pushctl.bench.engines): both engines, same scenes, ratios."""

import pytest

from pushctl.bench import engines as bench_engines
from pushctl.cli.reproduce import MJ_STEP_ROW


def test_engine_rows_time_both_engines_and_give_their_ratio():
    rows = bench_engines.engine_rows(steps=bench_engines.BLOCK)
    by_name = {row["name"]: row["value"] for row in rows}
    for label, _, _ in bench_engines.SCENES:
        ours, mujoco = by_name[f"{label} [ours]"], by_name[f"{label} [mujoco]"]
        assert ours > 0 and mujoco > 0
        assert by_name[f"{label} ours/mujoco"] == pytest.approx(ours / mujoco)
    assert by_name[MJ_STEP_ROW] > 0  # the row the reproduction's manifest reads


def test_pinning_restores_the_cpu_set():
    import os

    if not hasattr(os, "sched_getaffinity"):
        pytest.skip("no CPU affinity on this platform")
    before = os.sched_getaffinity(0)
    with bench_engines.pinned_to_one_core():
        assert len(os.sched_getaffinity(0)) == 1
    assert os.sched_getaffinity(0) == before

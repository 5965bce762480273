"""make bench's engine rows (benchmarks.engines): both engines, same scenes, ratios."""

import pytest

from benchmarks import engines as bench_engines
from pushctl.reproduce.manifest import MJ_STEP_ROW


def test_engine_rows_time_both_engines_and_give_their_ratio():
    rows = bench_engines.engine_rows(steps=bench_engines.BLOCK)
    by_name = {row["name"]: row["value"] for row in rows}
    for label, _, _ in bench_engines.SCENES:
        ours, mujoco = by_name[f"{label} [ours]"], by_name[f"{label} [mujoco]"]
        assert ours > 0 and mujoco > 0
        assert by_name[f"{label} ours/mujoco"] == pytest.approx(ours / mujoco)
    assert by_name[MJ_STEP_ROW] > 0  # the row the reproduction's manifest reads
    for build in bench_engines.RAW_NOTES:  # ours against MuJoCo alone
        label = next(label for label, scene, _ in bench_engines.SCENES if scene is build)
        raw = by_name[f"{label} [mujoco mj_step alone]"]
        ratio = by_name[f"{label} [ours]"] / raw
        assert by_name[f"{label} ours/mj_step alone"] == pytest.approx(ratio)


@pytest.mark.parametrize(("engine", "raw"), [("ours", False), ("mujoco", False), ("mujoco", True)])
def test_the_pd_loop_pushes_the_cube_at_its_target_speed(engine, raw):
    """The closed loop's scene pushes the cube, not the air: over 2 s behind a target that
    moves at 1 cm/s the cube moves about 2 cm on every engine, raw MuJoCo included."""
    world, step = bench_engines.pd_push(engine, raw)
    x0 = float(world.object_pose[0])  # MuJoCo's world reads it from its data
    for _ in range(200):
        step()
    assert float(world.object_pose[0]) - x0 == pytest.approx(0.02, rel=0.2)


def test_pinning_restores_the_cpu_set():
    import os

    if not hasattr(os, "sched_getaffinity"):
        pytest.skip("no CPU affinity on this platform")
    before = os.sched_getaffinity(0)
    with bench_engines.pinned_to_one_core():
        assert len(os.sched_getaffinity(0)) == 1
    assert os.sched_getaffinity(0) == before

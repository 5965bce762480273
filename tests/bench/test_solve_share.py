"""``python -m pushctl.bench.solve_share``: bad arguments and an existing output are one-line
errors; the cut item 1 needs follows from the four times; a one-repeat study times the
contact solve inside the step and leaves the push's bits alone."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pushctl.bench.rl import OPTIONS
from pushctl.bench.solve_share import SolveClock, main, solve_cut_needed, study
from pushctl.control.gains import load_gains
from pushctl.rl.env import PushEnv
from pushctl.rl.env_config import EnvConfig


def test_bad_repeats_are_a_one_line_error(capsys) -> None:
    assert main(["--repeats", "0"]) == 2
    assert capsys.readouterr().err == "error: --repeats must be an integer >= 1, got 0\n"


def test_an_existing_output_is_refused(capsys, tmp_path) -> None:
    out = tmp_path / "share.csv"
    out.write_text("kept\n")
    assert main(["--repeats", "1", "--out", str(out)]) == 2
    assert "--force" in capsys.readouterr().err
    assert out.read_text() == "kept\n"


def test_the_cut_brings_the_ratio_to_the_target() -> None:
    # acting 110 µs with 54 of solve, zero 67 with 11: cut x of both solves to reach 1.3
    x = solve_cut_needed(110.0, 54.0, 67.0, 11.0)
    assert (110.0 - x * 54.0) == pytest.approx(1.3 * (67.0 - x * 11.0))
    assert 0.0 < x < 1.0
    assert solve_cut_needed(80.0, 20.0, 70.0, 10.0) == 0.0  # already within 1.3
    # the rest alone over 1.3: no cut of the solve reaches it
    assert math.isnan(solve_cut_needed(150.0, 10.0, 70.0, 10.0))


def test_a_clocked_push_is_the_same_push() -> None:
    env = PushEnv(EnvConfig(gate_threshold=0.0, duration=1.0), load_gains())
    finals = []
    for clocked in (False, True):
        env.reset(options=OPTIONS)
        episode = env.episode
        clock = SolveClock(episode.world) if clocked else None
        rng = np.random.default_rng(0)
        while not episode.done:
            env.step(rng.uniform(-1.0, 1.0, 3))
        if clock is not None:
            assert clock.seconds > 0.0
            clock.remove()
            assert "solve" not in vars(episode.world.solver)
        finals.append(episode.world.object_pose.tobytes())
    assert finals[0] == finals[1]


@pytest.mark.parametrize("drawn", [False, True])
def test_one_repeat_study_splits_each_step(drawn) -> None:
    table = study(1, drawn).set_index("way")
    for way in ("zero", "acting"):
        row = table.loc[way]
        assert 0.0 < row["solve_us"] < row["clocked_step_us"]
        assert row["rest_us"] == pytest.approx(row["clocked_step_us"] - row["solve_us"])
    figures = table.loc["figures"]
    zero, acting = table.loc["zero"], table.loc["acting"]
    assert figures["ratio"] == pytest.approx(acting["step_us"] / zero["step_us"])
    assert figures["ratio_solve_free"] == pytest.approx(acting["rest_us"] / zero["rest_us"])
    x = figures["solve_cut_needed"]
    assert figures["unreachable"] == (1 if math.isinf(x) else 0)
    if 0.0 < x < 1.0:  # the cut brings the timed pushes to the target
        cut_acting = acting["clocked_step_us"] - x * acting["solve_us"]
        cut_zero = zero["clocked_step_us"] - x * zero["solve_us"]
        assert cut_acting == pytest.approx(1.3 * cut_zero)
    if not drawn:  # the cube chirp's random actions slip the prongs
        assert acting["solves_per_step"] > zero["solves_per_step"]

"""``python -m benchmarks.learners``: a tiny budget writes one row per task, learner and
seed, two runs with one seed write the same bytes, and the summary judges ours against
SB3's TD3 interval."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import benchmarks.learners as learners
from benchmarks.learners import BoxScale, Budget, main, summary, t_interval

TINY = Budget(steps=300, warmup_steps=100, hidden=(16, 16), learning_rate=1e-3, gamma=0.98,
              batch_size=32, eval_episodes=1)  # fmt: skip
"""A few hundred Pendulum steps: 200 updates, one evaluation episode of 200 steps."""


@pytest.mark.parametrize(
    "argv",
    [
        ["--tasks", "CartPole-v1"],
        ["--learners", "ours-sac"],
        ["--seeds", "0,x"],
        ["--seeds", "1000"],
    ],  # fmt: skip
)
def test_bad_arguments_are_one_line_errors(capsys, tmp_path, argv) -> None:
    assert main([*argv, "--out", str(tmp_path / "rows.csv")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --") and err.count("\n") == 1


def test_an_existing_output_is_refused(capsys, tmp_path) -> None:
    out = tmp_path / "rows.csv"
    out.write_text("kept\n")
    assert main(["--out", str(out)]) == 2
    assert "--force" in capsys.readouterr().err
    assert out.read_text() == "kept\n"


def test_a_tiny_budget_writes_every_row_and_one_seed_the_same_bytes(monkeypatch, tmp_path) -> None:
    monkeypatch.setitem(learners.BUDGETS, "Pendulum-v1", TINY)
    argv = ["--tasks", "Pendulum-v1", "--seeds", "0"]
    first, second = tmp_path / "a.csv", tmp_path / "b.csv"
    assert main([*argv, "--out", str(first)]) == 0
    assert main([*argv, "--out", str(second)]) == 0
    assert first.read_bytes() == second.read_bytes()
    text = first.read_text()
    assert text.startswith("# made by: python -m benchmarks.learners --tasks Pendulum-v1")
    rows = pd.read_csv(first, comment="#")
    assert list(rows.columns) == learners.COLUMNS
    assert list(rows.learner) == list(learners.LEARNERS)
    assert (rows.steps == 300).all() and (rows.eval_episodes == 1).all()
    # Pendulum's reward per step is in [-16.3, 0]: 200 steps
    assert ((rows.mean_return <= 0.0) & (rows.mean_return >= -16.3 * 200)).all()


def test_box_scale_maps_the_ends_and_the_middle() -> None:
    class Space:
        low, high = np.array([-2.0, 0.0]), np.array([2.0, 1.0])

    box = BoxScale(Space())
    assert box.to_env(np.array([-1.0, -1.0])).tolist() == [-2.0, 0.0]
    assert box.to_env(np.array([1.0, 1.0])).tolist() == [2.0, 1.0]
    assert box.to_env(np.array([0.0, 0.0])).tolist() == [0.0, 0.5]


def test_t_interval_of_three_values() -> None:
    mean, low, high = t_interval(np.array([1.0, 2.0, 3.0]))
    # t(0.975, 2) = 4.3027, standard error 1/√3
    assert mean == 2.0
    assert high - mean == pytest.approx(4.3027 / np.sqrt(3.0), abs=1e-4)
    assert mean - low == pytest.approx(high - mean)


def test_summary_judges_ours_against_the_reference_interval() -> None:
    scores = {
        "sb3-td3": [-160.0, -150.0, -170.0],
        "ours-td3": [-155.0, -165.0, -160.0],
        "ours-ddpg": [-900.0, -800.0, -1000.0],
        "sb3-sac": [-140.0, -150.0, -145.0],
    }
    rows = pd.DataFrame(
        [
            {"task": "Pendulum-v1", "learner": learner, "seed": seed, "mean_return": value}
            for learner, values in scores.items()
            for seed, value in enumerate(values)
        ]  # fmt: skip
    )
    table = summary(rows).set_index("learner")
    assert table.loc["ours-td3", "verdict"] == "within"
    assert table.loc["ours-ddpg", "verdict"] == "below"
    assert table.loc["sb3-sac", "verdict"] == "" and table.loc["sb3-td3", "verdict"] == ""
    assert table.loc["sb3-td3", "mean"] == -160.0
    assert (table.seeds == 3).all()

"""The prior-weight sweep (studies.prior_weight): its presets differ from the ablation
baseline in the prior weight only, and its table reads each run's validation rows."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pandas as pd

from pushctl.rl.presets import load_preset
from studies.prior_weight import BASELINE, WEIGHTS, run_directory, summary, sweep_presets


def test_the_sweep_changes_the_prior_weight_only() -> None:
    base = load_preset(str(BASELINE))
    presets = sweep_presets()
    assert sorted(presets) == sorted(WEIGHTS) == [0.0, 0.1, 0.4, 2.0]
    for weight, preset in presets.items():
        assert preset.ddpg == replace(base.ddpg, prior_weight=weight)
        assert preset.env == base.env and preset.train == base.train
    short = sweep_presets((0.4,), episodes=40, per_cell=5)[0.4]
    assert short.train.episodes == short.train.validate_every == 40
    assert short.train.validation_per_cell == 5


def test_the_summary_holds_each_runs_last_row_beside_episode_0(tmp_path: Path) -> None:
    for weight, error in ((0.1, 0.5), (2.0, 0.7)):
        directory = run_directory(tmp_path, weight, 3)
        directory.mkdir(parents=True)
        rows = pd.DataFrame(
            {
                "episode": [0, 40],
                "translation_error_pct": [0.6, error],
                "angle_error_pct": [1.0, 1.1],
                "force_error": [0.03, 0.02],
                "kept": [False, False],
            }
        )
        rows.to_csv(directory / "validation.csv", index=False)
    table = summary(tmp_path)
    assert list(table["weight"]) == [0.1, 2.0] and list(table["seed"]) == [3, 3]
    assert list(table["translation_error_pct"]) == [0.5, 0.7]
    assert list(table["law_translation_error_pct"]) == [0.6, 0.6]
    assert list(table["episode"]) == [40, 40]

"""``pushctl sweep``: the sweep file (grid, random draws, checks), and a 2 values × 2 seeds
sweep on local Ray writing its tables and figure, scored on tuning-stream seeds the runs
never picked their actor on."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import torch
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.control.gains import load_gains
from pushctl.errors import ConfigError
from pushctl.rl.presets import load_preset
from pushctl.rl.validate import Validator
from pushctl.runs.sweep import FIGURE_FILE, SUMMARY_FILE, TRIALS_FILE
from pushctl.runs.sweep_config import Range, read_sweep

runner = CliRunner()


def _write(write_tiny_preset, body: str) -> Path:
    """A sweep file with ``body`` over the tiny preset, beside it."""
    preset = write_tiny_preset(episodes=3, pd_every=3, validate_every=0)
    path = preset.parent / "sweep.toml"
    path.write_text('preset = "tiny.toml"\n' + body)
    return path


def test_a_grid_is_every_combination_in_order(tmp_path: Path, write_tiny_preset) -> None:
    sweep = read_sweep(
        _write(
            write_tiny_preset,
            'seeds = [0, 1]\n[parameters]\n"env.action_scale_linear" = [0.01, 0.02]\n'
            "ddpg.batch_size = [16, 32, 64]\n",
        )
    )
    assert sweep.seeds == (0, 1)
    assert sweep.keys == ["env.action_scale_linear", "ddpg.batch_size"]
    configurations = sweep.configurations()
    assert len(configurations) == 6
    assert configurations[1] == {"env.action_scale_linear": 0.01, "ddpg.batch_size": 32}
    preset = sweep.preset_for(configurations[5])
    assert (preset.env.action_scale_linear, preset.ddpg.batch_size) == (0.02, 64)
    assert preset.ddpg.hidden == (8, 8)  # the rest is the base preset's
    assert "ddpg.batch_size=64" in preset.name


def test_random_draws_are_seeded_and_in_range(tmp_path: Path, write_tiny_preset) -> None:
    body = (
        'seeds = "0"\nsearch = "random"\nsamples = 50\nsearch_seed = 3\n[parameters]\n'
        '"ddpg.actor_lr" = { low = 1e-5, high = 1e-3, log = true }\n'
        '"ddpg.batch_size" = { low = 16, high = 64 }\n"env.gate_threshold" = [0.0, 1e-4]\n'
    )
    sweep = read_sweep(_write(write_tiny_preset, body))
    draws = sweep.configurations()
    assert draws == read_sweep(tmp_path / "sweep.toml").configurations()
    rates = np.array([d["ddpg.actor_lr"] for d in draws])
    assert (rates >= 1e-5).all() and (rates <= 1e-3).all()
    assert (rates < 1e-4).sum() > 10  # log-uniform: half below the geometric middle
    sizes = [d["ddpg.batch_size"] for d in draws]
    assert all(isinstance(s, int) and 16 <= s <= 64 for s in sizes)
    assert {d["env.gate_threshold"] for d in draws} == {0.0, 1e-4}
    assert Range(1, 3).draw(np.random.default_rng(0)) in (1, 2, 3)


@pytest.mark.parametrize(
    ("body", "fragment"),
    [
        ('seeds = "0"\n[parameters]\n"env.gate" = [0.0]\n', "'env.gate' is not a preset key"),
        ('seeds = "0"\n[parameters]\n"ddpg.gamma" = [0.9, 2.0]\n', "gamma must be"),
        ('seeds = "0"\n[parameters]\n"ddpg.tau" = { low = 0.1, high = 0.2 }\n', "grid search"),
        ('seeds = "0"\nsearch = "bayes"\n[parameters]\n"ddpg.tau" = [0.1]\n', "unknown search"),
        ('seeds = "2-1"\n[parameters]\n"ddpg.tau" = [0.1]\n', "backwards"),
        ('seeds = "0"\nepochs = 3\n[parameters]\n"ddpg.tau" = [0.1]\n', "unknown keys"),
        ('seeds = "0"\n', "'parameters' is missing"),
    ],
)
def test_bad_sweep_files_are_refused_in_one_line(
    tmp_path: Path, write_tiny_preset, body: str, fragment: str
) -> None:
    with pytest.raises(ConfigError, match="sweep file") as caught:
        read_sweep(_write(write_tiny_preset, body))
    assert fragment in str(caught.value) and "\n" not in str(caught.value)


def test_a_sweep_writes_its_tables_and_figure(
    tmp_path: Path, write_tiny_preset, ray_local: None
) -> None:
    config = _write(
        write_tiny_preset, 'seeds = "0-1"\n[parameters]\n"ddpg.updates_per_step" = [0.05, 0.1]\n'
    )
    out = tmp_path / "sweep"
    result = runner.invoke(app, ["sweep", str(config), "--out", str(out)])
    assert result.exit_code == 0, result.output
    trials = pd.read_csv(out / TRIALS_FILE, comment="#")
    assert list(trials["trial"]) == [0, 0, 1, 1] and list(trials["seed"]) == [0, 1, 0, 1]
    assert list(trials["ddpg.updates_per_step"]) == [0.05, 0.05, 0.1, 0.1]
    assert (trials["episodes"] == 3).all() and (trials["wall_time_s"] > 0).all()
    np.testing.assert_allclose(
        trials["score"], trials["force_ratio"] + trials["translation_ratio"], rtol=1e-7
    )
    assert list(trials["beats_pd"]) == list(
        (trials["force_ratio"] < 1) & (trials["translation_ratio"] < 1)
    )
    # The policies are the last actors (validate_every 0): they changed PD-only's pushes.
    assert (trials["score"] != 2.0).all() and trials["score"].nunique() == 4
    # A row's score is its policy on tuning seed 1 (a run picks its actor on seed 0).
    row = trials.iloc[3]
    run = out / row["run"]
    preset = load_preset(str(tmp_path / "tiny.toml"))
    validator = Validator(preset.env, load_gains(), 1, first=1)
    assert [o["scenario_seed"] for o in validator.options] == [1]
    actor = torch.load(run / "policy.pt", weights_only=True)["actor"]
    assert validator.score(actor).score == pytest.approx(row["score"], rel=1e-8)
    summary = pd.read_csv(out / SUMMARY_FILE, comment="#")
    assert sorted(summary["trial"]) == [0, 1] and (summary["seeds"] == 2).all()
    for _, line in summary.iterrows():
        scores = trials.loc[trials["trial"] == line["trial"], "score"]
        assert line["score_mean"] == pytest.approx(scores.mean())
    assert list(summary["score_mean"]) == sorted(summary["score_mean"])
    assert (out / FIGURE_FILE).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "score mean" in result.output
    made_by = (out / TRIALS_FILE).read_text().splitlines()[0]
    assert made_by.startswith(f"# made by: pushctl sweep {config}") and "--out" not in made_by

    again = runner.invoke(app, ["sweep", str(config), "--out", str(out)])
    assert again.exit_code == 2 and "--resume" in again.output
    resumed = runner.invoke(app, ["sweep", str(config), "--out", str(out), "--resume"])
    assert resumed.exit_code == 0, resumed.output
    rescored = pd.read_csv(out / TRIALS_FILE, comment="#")
    pd.testing.assert_series_equal(rescored["score"], trials["score"])

"""The training loop and ``pushctl train``: curves, checkpoints, a killed run resumed to the
same weights, the collector process, the policy file, and bad input."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import torch
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.errors import ConfigError
from pushctl.rl.collect import CURVE_METRICS
from pushctl.rl.policy import load_policy
from pushctl.rl.presets import PRESET_NAMES, load_preset
from pushctl.rl.train import (
    CHECKPOINT,
    CURVE,
    LAST_POLICY,
    POLICY,
    VALIDATION,
    Trainer,
    read_checkpoint,
)

TINY = """
[train]
episodes = 5
checkpoint_every = 2
pd_every = 2
workers = {workers}
episodes_per_round = {per_round}
validate_every = 2
validation_per_cell = 1

[env]
objects = ["cube"]
profiles = ["constant", "trapezoid"]
duration = 2.0
gate_threshold = 0.0

[ddpg]
hidden = [16, 16]
batch_size = 32
buffer_size = 2000
warmup_steps = 200
updates_per_step = 0.05
reward_scale = 100.0
"""

runner = CliRunner()


def _preset(tmp_path: Path, workers: int = 0, per_round: int = 1) -> str:
    path = tmp_path / f"tiny{workers}-{per_round}.toml"
    path.write_text(TINY.format(workers=workers, per_round=per_round))
    return str(path)


def _weights(trainer: Trainer) -> dict[str, torch.Tensor]:
    agent = trainer.agent
    return {
        f"{name}.{key}": value
        for name in ("actor", "critic", "actor_target", "critic_target")
        for key, value in getattr(agent, name).state_dict().items()
    }


def _assert_same_weights(a: dict[str, torch.Tensor], b: dict[str, torch.Tensor]) -> None:
    assert a.keys() == b.keys()
    for key in a:
        assert torch.equal(a[key], b[key]), key


@pytest.fixture(scope="module")
def straight(tmp_path_factory: pytest.TempPathFactory) -> Trainer:
    """Five episodes straight through, in this process."""
    tmp = tmp_path_factory.mktemp("straight")
    preset = load_preset(_preset(tmp))
    trainer = Trainer.start(preset, 7, tmp / "run")
    trainer.run(5, made_by="# made by: test")
    return trainer


def test_the_curve_has_one_row_per_episode_with_rl_and_every_nth_pd(straight: Trainer) -> None:
    curve = pd.read_csv(straight.out / CURVE, comment="#")
    assert list(curve["episode"]) == [0, 1, 2, 3, 4]
    for name in CURVE_METRICS:
        assert curve[f"rl_{name}"].notna().all()
        assert list(curve[f"pd_{name}"].notna()) == [True, False, True, False, True]
    assert set(curve["object"]) == {"cube"}
    assert (straight.out / CURVE).read_text().startswith("# made by: test")
    # The trained steps pushed: the RL and PD errors of an episode differ.
    assert (curve["rl_force_error"] != curve["pd_force_error"]).iloc[[0, 2, 4]].all()


def test_updates_follow_the_schedule(straight: Trainer) -> None:
    # 5 × 200 steps; warm-up 200; 0.05 updates per step after it; the last episode's
    # updates are still pending (they run while the next episode would be collected).
    assert straight.agent.env_steps == 1000
    assert straight.agent.n_updates + straight.pending_updates == round(0.05 * 800)
    assert straight.pending_updates == 10


def test_a_stopped_run_resumes_to_the_same_weights(straight: Trainer, tmp_path: Path) -> None:
    preset = load_preset(_preset(tmp_path))
    first = Trainer.start(preset, 7, tmp_path / "run")

    def stop_after_third(progress) -> None:
        if progress.episodes_done == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        first.run(5, on_episode=stop_after_third, made_by="# made by: test")
    assert read_checkpoint(tmp_path / "run" / CHECKPOINT)["next_episode"] == 2
    resumed = Trainer.resume(tmp_path / "run")
    resumed.run(5, made_by="# made by: test")
    _assert_same_weights(_weights(resumed), _weights(straight))
    assert (tmp_path / "run" / CURVE).read_bytes() == (straight.out / CURVE).read_bytes()


def test_resuming_a_finished_run_changes_nothing(straight: Trainer, tmp_path: Path) -> None:
    # make reproduce-tables resumes a run that may be complete: no episode, no second
    # validation of the last actor, the same files.
    run = tmp_path / "run"
    shutil.copytree(straight.out, run)
    before = {path.name: path.read_bytes() for path in run.iterdir() if path.suffix == ".csv"}
    resumed = Trainer.resume(run)
    resumed.run(5, made_by="# made by: test")
    after = {path.name: path.read_bytes() for path in run.iterdir() if path.suffix == ".csv"}
    assert after == before
    _assert_same_weights(_weights(resumed), _weights(straight))
    obs = np.linspace(-1.0, 1.0, load_policy(run / POLICY).actor.actor.obs_dim)
    expected = load_policy(straight.out / POLICY).actor(obs)
    np.testing.assert_array_equal(load_policy(run / POLICY).actor(obs), expected)


def test_the_collector_process_gives_the_same_run(
    straight: Trainer, tmp_path: Path, ray_local: None
) -> None:
    preset = load_preset(_preset(tmp_path, workers=1))
    parallel = Trainer.start(preset, 7, tmp_path / "run")
    parallel.run(5, made_by="# made by: test")
    _assert_same_weights(_weights(parallel), _weights(straight))


def test_rounds_of_episodes_give_the_same_run_with_any_number_of_collectors(
    tmp_path: Path, ray_local: None
) -> None:
    runs = []
    for workers in (0, 2):
        preset = load_preset(_preset(tmp_path, workers=workers, per_round=2))
        trainer = Trainer.start(preset, 7, tmp_path / f"run{workers}")
        trainer.run(5, made_by="# made by: test")
        runs.append(trainer)
    _assert_same_weights(_weights(runs[0]), _weights(runs[1]))
    assert (runs[0].out / CURVE).read_bytes() == (runs[1].out / CURVE).read_bytes()
    # Every episode of a round credits its updates (5 × 200 steps, 200 of warm-up, 0.05
    # per step): none is lost when two episodes are absorbed at once.
    agent = runs[0].agent
    assert agent.n_updates + runs[0].pending_updates == round(0.05 * 800)


def test_the_last_policy_file_holds_the_trained_actor(straight: Trainer) -> None:
    policy = load_policy(straight.out / LAST_POLICY)
    obs = np.linspace(-1.0, 1.0, 18)
    np.testing.assert_array_equal(policy.actor(obs), straight.agent.policy_action(obs))
    assert policy.env == straight.preset.env


def test_validation_keeps_the_best_actor_that_beats_pd_on_both_errors(straight: Trainer) -> None:
    table = pd.read_csv(straight.out / VALIDATION, comment="#")
    assert list(table["episode"]) == [0, 2, 4, 5]  # every 2nd episode, and the end
    start = table.iloc[0]  # episode 0's zero residual: the start, never kept itself
    beats_pd = (table["force_error"] < table["pd_force_error"]) & (
        table["translation_error_pct"] < table["pd_translation_error_pct"]
    )
    no_worse = (table["force_error"] <= start["force_error"]) & (
        table["translation_error_pct"] <= start["translation_error_pct"]
    )
    best, kept = np.inf, []
    for episode, beats, fine, score in zip(
        table["episode"], beats_pd, no_worse, table["score"], strict=True
    ):
        kept.append(bool(episode > 0 and beats and fine and score < best))
        best = score if kept[-1] else best
    assert list(table["kept"]) == kept
    # PD-only is the same validation set every time.
    assert table["pd_force_error"].nunique() == 1
    chosen = load_policy(straight.out / POLICY)
    obs = np.linspace(-1.0, 1.0, 18)
    from pushctl.rl.networks import ActorPolicy

    if any(kept):
        assert straight.best_actor is not None
        expected = ActorPolicy.from_state(straight.best_actor)(obs)
    else:  # nothing beat episode 0's zero residual: it is shipped, under the run's settings
        assert straight.best_actor is None
        expected = np.zeros(3)
        assert chosen.env == straight.preset.env
    np.testing.assert_array_equal(chosen.actor(obs), expected)


def _children(pid: int) -> list[int]:
    """Processes whose parent is ``pid`` (Linux /proc)."""
    children = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            children.append(int(stat.parent.name))
    return children


def test_a_killed_cli_run_resumes_to_the_weights_of_a_straight_one(tmp_path: Path) -> None:
    """SIGKILL to the learner mid-run (no clean-up at all): its collector process exits by
    itself, and ``--resume`` ends with the weights of a run straight through."""
    preset = _preset(tmp_path, workers=1)
    straight_out, killed_out = tmp_path / "straight", tmp_path / "killed"
    command = [sys.executable, "-m", "pushctl.cli", "train", "--preset", preset, "--seed", "3"]
    command += ["--workers", "1"]  # a collector process, on Ray (one seed: else in-process)
    subprocess.run([*command, "--out", str(straight_out)], check=True, capture_output=True)

    process = subprocess.Popen(
        [*command, "--out", str(killed_out), "--episodes", "9"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 120
    while not (killed_out / CHECKPOINT).exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    collectors = _children(process.pid)
    assert collectors, "the preset runs one collector process"
    os.kill(process.pid, signal.SIGKILL)  # the learner only: no clean-up runs
    process.wait()
    deadline = time.monotonic() + 10
    while any(Path(f"/proc/{pid}").exists() for pid in collectors):
        assert time.monotonic() < deadline, "the collector outlived its learner"
        time.sleep(0.1)
    assert read_checkpoint(killed_out / CHECKPOINT)["next_episode"] < 5
    resumed = subprocess.run(
        [sys.executable, "-m", "pushctl.cli", "train", "--resume", "--out", str(killed_out),
         "--episodes", "5"],
        capture_output=True, text=True,
    )  # fmt: skip
    assert resumed.returncode == 0, resumed.stderr
    a = Trainer.resume(straight_out)
    b = Trainer.resume(killed_out)
    _assert_same_weights(_weights(a), _weights(b))


def test_cli_train_writes_the_run_and_reports(tmp_path: Path) -> None:
    out = tmp_path / "run"
    result = runner.invoke(app, ["train", "--preset", _preset(tmp_path), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert {p.name for p in out.iterdir()} == {CHECKPOINT, CURVE, POLICY, LAST_POLICY, VALIDATION}
    assert "gradient updates" in result.output
    first_line = (out / CURVE).read_text().splitlines()[0]
    assert first_line.startswith("# made by: pushctl train --preset")
    assert "--seed" not in first_line or "--seed 0" in first_line


def _one_line_error(result, *fragments: str) -> None:
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), result.output
    for fragment in fragments:
        assert fragment in lines[0]
    assert "Traceback" not in result.output


def test_bad_input_gives_one_line_errors_and_overwrites_nothing(tmp_path: Path) -> None:
    preset = _preset(tmp_path)
    _one_line_error(
        runner.invoke(app, ["train", "--preset", "huge", "--out", str(tmp_path / "x")]),
        "unknown preset 'huge'",
        "quick, paper",
    )
    _one_line_error(
        runner.invoke(app, ["train", "--resume", "--out", str(tmp_path / "none")]),
        "no checkpoint",
    )
    occupied = tmp_path / "occupied"
    occupied.mkdir()
    (occupied / "notes.txt").write_text("keep me")
    _one_line_error(
        runner.invoke(app, ["train", "--preset", preset, "--out", str(occupied)]),
        "already holds a run",
        "--resume",
        "--force",
    )
    assert (occupied / "notes.txt").read_text() == "keep me"
    _one_line_error(
        runner.invoke(app, ["train", "--resume", "--force", "--out", str(occupied)]),
        "exclude each other",
    )
    corrupt = tmp_path / "corrupt"
    corrupt.mkdir()
    (corrupt / CHECKPOINT).write_bytes(b"not a checkpoint")
    _one_line_error(
        runner.invoke(app, ["train", "--resume", "--out", str(corrupt)]), "is not a checkpoint"
    )
    assert (corrupt / CHECKPOINT).read_bytes() == b"not a checkpoint"


def test_resume_refuses_another_seed_or_format(tmp_path: Path) -> None:
    out = tmp_path / "run"
    result = runner.invoke(app, ["train", "--preset", _preset(tmp_path), "--out", str(out)])
    assert result.exit_code == 0, result.output
    before = (out / CHECKPOINT).read_bytes()
    _one_line_error(
        runner.invoke(app, ["train", "--resume", "--seed", "9", "--out", str(out)]),
        "incompatible",
        "seed 0",
    )
    state = torch.load(out / CHECKPOINT, weights_only=True)
    state.pop("digest", None)  # edited on purpose: what is checked is what follows
    state["format"] = 99
    torch.save(state, out / CHECKPOINT)
    resume = ["train", "--resume", "--trust-undigested", "--out", str(out)]
    _one_line_error(runner.invoke(app, resume), "format 99")
    state["format"] = 1
    state["agent"]["obs_dim"] = 4
    torch.save(state, out / CHECKPOINT)
    _one_line_error(runner.invoke(app, resume), "incompatible")
    del before


def test_force_starts_over(tmp_path: Path) -> None:
    out = tmp_path / "run"
    preset = _preset(tmp_path)
    assert runner.invoke(app, ["train", "--preset", preset, "--out", str(out)]).exit_code == 0
    again = runner.invoke(
        app, ["train", "--preset", preset, "--out", str(out), "--force", "--episodes", "2"]
    )
    assert again.exit_code == 0, again.output
    assert read_checkpoint(out / CHECKPOINT)["next_episode"] == 2


@pytest.mark.parametrize("name", PRESET_NAMES)
def test_the_shipped_presets_load(name: str) -> None:
    preset = load_preset(name)
    assert preset.train.episodes >= 1
    assert preset.env.w_normal > 0.0


def test_a_preset_with_an_unknown_key_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(TINY.format(workers=0, per_round=1).replace("[train]", "[train]\nepochs = 3"))
    with pytest.raises(ConfigError, match=r"\[train\] has unknown keys \['epochs'\]"):
        load_preset(str(path))


def test_on_a_base_law_the_zero_residual_is_scored_and_no_kept_actor_tracks_worse(
    tmp_path: Path,
) -> None:
    """Episode 0's actor (a zero residual: the law) gets a validation row, and every later
    row is kept only if it also tracks no worse than that row on translation and angle."""
    text = TINY.format(workers=0, per_round=1).replace(
        "gate_threshold = 0.0\n",
        'gate_threshold = 0.0\nbase_law = "feedback"\naction_repeat = 10\n',
    )
    text = text.replace(
        "validation_per_cell = 1\n", 'validation_per_cell = 1\nselect_on = "tracking"\n'
    )
    path = tmp_path / "law.toml"
    path.write_text(text.replace("warmup_steps = 200", "warmup_steps = 20"))
    trainer = Trainer.start(load_preset(str(path)), 7, tmp_path / "run")
    trainer.run(5, made_by="# made by: test")
    table = pd.read_csv(trainer.out / VALIDATION, comment="#")
    assert list(table["episode"]) == [0, 2, 4, 5]
    base = table.iloc[0]
    best, kept = np.inf, []
    for _, row in table.iterrows():
        beats_pd = (row["translation_error_pct"] < row["pd_translation_error_pct"]) and (
            row["angle_error_pct"] < row["pd_angle_error_pct"]
        )
        no_worse = row["episode"] == 0 or (
            row["translation_error_pct"] <= base["translation_error_pct"]
            and row["angle_error_pct"] <= base["angle_error_pct"]
        )
        kept.append(bool(row["episode"] > 0 and beats_pd and row["score"] < best and no_worse))
        best = row["score"] if kept[-1] else best
    assert list(table["kept"]) == kept
    from pushctl.rl.validate import ValidationScore

    score = ValidationScore(0.03, 0.2, 0.02, 0.8, 0.5, 2.0, rule="tracking")
    assert score.no_worse_than({"translation_error_pct": 0.2, "angle_error_pct": 0.5})
    assert not score.no_worse_than({"translation_error_pct": 0.3, "angle_error_pct": 0.4})
    assert score.no_worse_than(None)


def test_every_run_validates_its_zero_residual_at_episode_0_and_pairs_against_it(
    tmp_path: Path,
) -> None:
    """Without a base law too, episode 0's actor (the zero residual, re-landed as every
    later actor is) is scored on the validation set, later actors are paired against it,
    and a run whose actors never beat it ships it, under the run's own settings."""
    text = TINY.format(workers=0, per_round=1).replace(
        "validation_per_cell = 1\n", 'validation_per_cell = 1\nselect_on = "paired"\n'
    )
    path = tmp_path / "paired.toml"
    path.write_text(text)
    preset = load_preset(str(path))
    assert preset.env.base_law == "none" and preset.env.landing == "measured"
    trainer = Trainer.start(preset, 7, tmp_path / "run")
    trainer.run(3, made_by="# made by: test")
    table = pd.read_csv(trainer.out / VALIDATION, comment="#")
    assert list(table["episode"]) == [0, 2, 3]
    start = table.iloc[0]
    assert start["translation_diff"] == 0.0 and start["angle_diff"] == 0.0
    assert not start["kept"]
    for _, row in table.iloc[1:].iterrows():  # the mean of the differences, against row 0
        expected = row["translation_error_pct"] - start["translation_error_pct"]
        assert row["translation_diff"] == pytest.approx(expected, rel=1e-4)  # CSV digits
    chosen = load_policy(trainer.out / POLICY)
    if not table["kept"].any():
        assert chosen.env == preset.env  # episode 0's actor under the run's settings
        np.testing.assert_array_equal(chosen.actor(np.linspace(-1.0, 1.0, 18)), np.zeros(3))


def test_the_quick_presets_actor_moves_before_its_first_validation(tmp_path: Path) -> None:
    """The ``quick`` preset's schedule in episodes (warm-up, critic burn-in, updates per
    episode, validation every 30), with 2 s pushes and the decision counts scaled to them:
    the actor validated at episode 30 has had actor updates, and scores other than episode
    0's zero residual on the validation set."""
    from dataclasses import replace

    quick = load_preset("quick")
    factor = 2.0 / quick.env.duration  # decisions per 2 s push / per preset push
    ddpg = quick.ddpg
    preset = replace(
        quick,
        env=replace(quick.env, duration=2.0, objects=("cube",), profiles=("trapezoid",)),
        train=replace(quick.train, workers=0, validation_per_cell=2, pd_every=1000),
        ddpg=replace(
            ddpg,
            warmup_steps=round(ddpg.warmup_steps * factor),
            critic_burn_in=round(ddpg.critic_burn_in * factor),
            batch_size=round(ddpg.batch_size * factor),
        ),
    )
    first = preset.train.validate_every
    trainer = Trainer.start(preset, 0, tmp_path / "run")
    trainer.run(first + preset.train.episodes_per_round, made_by="# made by: test")
    table = pd.read_csv(trainer.out / VALIDATION, comment="#").set_index("episode")
    assert table.loc[first, "updates"] > preset.ddpg.critic_burn_in  # the actor has learned
    columns = ["force_error", "translation_error_pct", "angle_error_pct"]
    assert not table.loc[first, columns].equals(table.loc[0, columns])

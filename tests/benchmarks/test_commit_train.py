"""``python -m benchmarks.compare_commits train``: the preset it times, the command, and its
arguments."""

from __future__ import annotations

from pathlib import Path

import pytest

from benchmarks.commits.train import OVERRIDES, bench_preset, command, main
from pushctl.errors import ConfigError
from pushctl.rl.presets import load_preset

PAPER = Path(__file__).resolve().parents[2] / "pushctl" / "defaults" / "train_paper.toml"


def test_the_timed_preset_is_the_paper_preset_shortened(tmp_path: Path) -> None:
    path = tmp_path / "bench.toml"
    path.write_text(bench_preset(PAPER.read_text()))
    bench, paper = load_preset(str(path)), load_preset("paper")
    assert bench.train.episodes == 40 and bench.train.validate_every == 20
    assert bench.ddpg.warmup_steps == 2000 and bench.ddpg.critic_burn_in == 200
    # in one process, as each of three seeds on two cores; else the paper preset's
    assert bench.train.workers == 0
    assert bench.env == paper.env
    assert bench.train.episodes_per_round == paper.train.episodes_per_round
    assert bench.train.pd_every == paper.train.pd_every
    assert bench.ddpg.hidden == paper.ddpg.hidden
    assert bench.ddpg.updates_per_step == paper.ddpg.updates_per_step


def test_a_preset_without_one_of_the_keys_is_refused() -> None:
    text = PAPER.read_text().replace("\nvalidate_every =", "\n# validate_every =")
    with pytest.raises(ConfigError, match="0 lines setting 'validate_every'"):
        bench_preset(text)
    assert set(OVERRIDES) >= {"episodes", "validate_every"}


def test_the_timed_command_trains_one_seed(tmp_path: Path) -> None:
    args = command(tmp_path / "p.toml", tmp_path / "out")
    assert args[:3] == ["-m", "pushctl.cli", "train"]
    assert f"--preset {tmp_path / 'p.toml'} --seed 0 --out {tmp_path / 'out'}" in " ".join(args)


def test_bad_arguments_are_one_line_errors(capsys) -> None:
    assert main(["--against", "HEAD", "--repeats", "0"]) == 2
    assert main(["--against", "no-such-commit"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[0] == "error: --repeats must be an integer >= 1, got 0"
    assert err[1].startswith("error: --against no-such-commit: cannot unpack it")
    assert len(err) == 2

"""``pushctl evaluate``: the files and the summary, the same bytes with any number of workers,
PD-only without a policy, and one-line errors with nothing written."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.control.feedback import load_feedback_gains
from pushctl.rl.config import DDPGConfig
from pushctl.rl.ddpg import DDPGAgent
from pushctl.rl.policy import write_policy
from pushctl.task.env_config import EnvConfig
from pushctl.task.spaces import observation_entries, scales

runner = CliRunner()
MADE_BY = "# made by: a test run"


def _policy(path: Path, n_obs: int | None = None) -> Path:
    """An untrained, acting actor (gate always open) with a 2 s push."""
    entries = observation_entries(2, reference_offset=True)
    n = n_obs if n_obs is not None else len(entries)
    config = DDPGConfig(hidden=(8, 8), actor_final_init=0.5)
    agent = DDPGAgent(n, 3, config, seed=0, obs_scale=scales(entries)[:n])
    write_policy(path, agent.actor_state(), EnvConfig(duration=2.0, gate_threshold=0.0), MADE_BY)
    return path


@pytest.fixture(scope="module")
def policy(tmp_path_factory) -> Path:
    return _policy(tmp_path_factory.mktemp("policy") / "policy.pt")


def _evaluate(out: Path, *args: str):
    tiny = ["--object", "cube", "--profile", "chirp", "--trials", "1", "--out", str(out)]
    return runner.invoke(app, ["evaluate", *tiny, *args])


def test_two_workers_write_the_same_bytes_as_one(
    tmp_path: Path, policy: Path, ray_local: None
) -> None:
    """In two places, too: the provenance line names neither --out nor --workers."""
    one = _evaluate(tmp_path / "one", "--policy", str(policy), "--workers", "1")
    two = _evaluate(tmp_path / "two", "--policy", str(policy), "--workers", "2")
    assert one.exit_code == 0, one.output
    assert two.exit_code == 0, two.output
    for name in ("trials.csv", "steps.csv"):
        assert (tmp_path / "one" / name).read_bytes() == (tmp_path / "two" / name).read_bytes()
    trials = pd.read_csv(tmp_path / "one" / "trials.csv", comment="#")
    assert list(trials["plant"]) == ["sim"] * 3 + ["proxy"] * 3
    assert list(trials["controller"]) == ["pd", "feedback", "rl"] * 2
    made_by = (tmp_path / "one" / "trials.csv").read_text().splitlines()[0]
    assert "--workers" not in made_by and "--out" not in made_by
    assert "scenario seeds 0-0 (evaluation stream)" in made_by
    assert f"policy {policy}, made by: a test run" in made_by
    gains = load_feedback_gains()
    law = f"feedback k {gains.k:g} /s, k_i {gains.k_i:g} /s², lateral_ratio "
    law += f"{gains.lateral_ratio:g}, seek {gains.seek_rate:g} rad/s over {gains.seek_ramp:g} s, "
    law += f"turn_ratio {gains.turn_ratio:g}, smoothing {gains.smoothing:g} s (feedback_gains.toml)"
    assert law in made_by
    for heading in ("transl.", "mN·m", "slip", "goals redrawn as infeasible: 0 of 1 targets"):
        assert heading in one.output
    assert "proxy" in one.output and "RL" in one.output
    assert "wrote" in one.output and "steps.csv" in one.output


def test_pd_only_needs_no_policy_and_the_seed_moves_the_targets(tmp_path: Path) -> None:
    missing = str(tmp_path / "none.pt")
    args = ("--controller", "pd", "--plant", "sim", "--policy", missing)
    first = _evaluate(tmp_path / "a", *args)
    other = _evaluate(tmp_path / "b", *args, "--scenario-block", "3")
    assert first.exit_code == 0, first.output
    assert other.exit_code == 0, other.output
    a = pd.read_csv(tmp_path / "a" / "trials.csv", comment="#")
    b = pd.read_csv(tmp_path / "b" / "trials.csv", comment="#")
    assert list(a["controller"]) == ["pd"] and list(b["seed"]) == [300_000]
    assert a["goal_dx"].iloc[0] != b["goal_dx"].iloc[0]
    assert "RL" not in first.output


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--object", "sphere"], "unknown --object 'sphere'; accepted: cube, wedge or all"),
        (["--profile", "sine"], "accepted: constant, trapezoid, chirp or all"),
        (["--plant", "real"], "accepted: sim, proxy, mujoco, both or all"),
        (["--controller", "ppo"], "accepted: pd, feedback, rl or all"),
        (["--trials", "0"], "--trials must be an integer in 1"),
        (["--workers", "0"], "--workers must be an integer in 1 … 8"),
        (["--workers", "9"], "--workers must be an integer in 1 … 8"),
        (["--scenario-block", "-1"], "--scenario-block must be an integer >= 0"),
        (["--policy", "MISSING"], "no policy file"),
        (["--policy", "CORRUPT"], "is not a policy file or is cut short"),
        (["--policy", "SMALL"], "incompatible: its actor takes 14 observations"),
        (["--out", "FILE"], "is a file; give a directory"),
        (["--out", "UNDER_FILE"], "is a file, not a directory"),
    ],
)
def test_bad_input_is_one_line_exit_2_and_nothing_written(
    tmp_path: Path, policy: Path, args: list[str], fragment: str
) -> None:
    (tmp_path / "corrupt.pt").write_bytes(b"not a policy")
    (tmp_path / "file").write_text("")
    replace = {
        "MISSING": str(tmp_path / "none.pt"),
        "CORRUPT": str(tmp_path / "corrupt.pt"),
        "SMALL": str(_policy(tmp_path / "small.pt", n_obs=14)),
        "FILE": str(tmp_path / "file"),
        "UNDER_FILE": str(tmp_path / "file" / "out"),
    }
    args = [replace.get(arg, arg) for arg in args]
    if "--policy" not in args:
        args += ["--policy", str(policy)]
    out = tmp_path / "out"
    result = runner.invoke(app, ["evaluate", "--trials", "1", "--out", str(out), *args])
    assert result.exit_code == 2, result.output
    assert fragment in result.output
    assert "Traceback" not in result.output
    assert len(result.output.strip().splitlines()) == 1
    assert not out.exists()


def test_a_bare_evaluation_writes_under_runs(tmp_path: Path, monkeypatch) -> None:
    """The default --out is runs/evaluation, never the shipped results/ (which a first run
    would have to --force). Not on a terminal, progress is plain lines that never wrap,
    however narrow the console, and no live bar."""
    from pushctl.cli import common

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(common.console, "width", 40)
    tiny = ["--object", "cube", "--profile", "chirp", "--trials", "1", "--controller", "pd"]
    result = runner.invoke(app, ["evaluate", *tiny, "--plant", "sim"])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "runs" / "evaluation" / "trials.csv").is_file()
    assert (tmp_path / "runs" / "evaluation" / "steps.csv").is_file()
    progress = [line for line in result.output.splitlines() if "episode" in line or "|F|" in line]
    assert progress and all(line.startswith("episode 1/1 ") for line in progress), progress
    assert all(line.endswith(" mN") for line in progress), progress


def test_the_early_trials_check_has_the_evaluation_s_bound(tmp_path: Path) -> None:
    """The check before the heavy imports refuses what the evaluation itself refuses."""
    from pushctl.cli.names import check_evaluate_options
    from pushctl.errors import ConfigError
    from pushctl.evaluation.trials import SEEDS_PER_EVALUATION

    args = ("cube", "constant", "pd", "sim", 0, "evaluation", 1, tmp_path / "out")
    check_evaluate_options(args[0], args[1], SEEDS_PER_EVALUATION, *args[2:])
    with pytest.raises(ConfigError, match=f"in 1 … {SEEDS_PER_EVALUATION}"):
        check_evaluate_options(args[0], args[1], SEEDS_PER_EVALUATION + 1, *args[2:])

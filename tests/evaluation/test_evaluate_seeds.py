"""Several policies in one evaluation (docs/several-seeds.md): PD-only and feedback once per
trial, each policy its own ``rl`` rows with its training seed, each policy's rows the same as
in an evaluation of that policy alone, the same bytes with any number of workers, and
one-line errors for policies that cannot share an evaluation."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.control.feedback import FeedbackGains
from pushctl.episode.metrics import EpisodeMetrics
from pushctl.errors import ConfigError
from pushctl.evaluation.columns import STEP_COLUMNS
from pushctl.evaluation.evaluate import evaluate, load_evaluation_policy
from pushctl.evaluation.trials import TrialSpec
from pushctl.rl.config import DDPGConfig
from pushctl.rl.ddpg import DDPGAgent
from pushctl.rl.policy import write_policy
from pushctl.task.env_config import EnvConfig
from pushctl.task.spaces import observation_entries, scales

runner = CliRunner()
METRICS = list(EpisodeMetrics.__dataclass_fields__)


def _policy(path: Path, training_seed: int | None, init_seed: int, gate: float = 0.0) -> Path:
    """An untrained, acting actor (gate always open, 2 s push) whose provenance names
    ``training_seed``; ``init_seed`` sets its weights, so two policies push differently."""
    entries = observation_entries(2, reference_offset=True)
    config = DDPGConfig(hidden=(8, 8), actor_final_init=0.5)
    agent = DDPGAgent(len(entries), 3, config, seed=init_seed, obs_scale=scales(entries))
    made_by = "# made by: a test run" + (
        f"; seed {training_seed} (training stream)" if training_seed is not None else ""
    )
    env = EnvConfig(duration=2.0, gate_threshold=gate)
    write_policy(path, agent.actor_state(), env, made_by)
    return path


@pytest.fixture(scope="module")
def policies(tmp_path_factory) -> list[Path]:
    """Two policies, trained (nominally) with seeds 7 and 3, saved under misleading
    directory names: the seed must come from the file, not the path."""
    root = tmp_path_factory.mktemp("policies")
    (root / "seed-0").mkdir()
    (root / "seed-1").mkdir()
    return [
        _policy(root / "seed-0" / "policy.pt", 7, init_seed=0),
        _policy(root / "seed-1" / "policy.pt", 3, init_seed=1),
    ]


def _spec(controllers: tuple[str, ...] = ("pd", "feedback", "rl")) -> TrialSpec:
    return TrialSpec(
        controllers=controllers,
        objects=("cube",),
        profiles=("chirp",),
        plants=("sim", "proxy"),
        trials=2,
    )


def test_each_policy_adds_its_own_rl_rows_and_pd_and_feedback_run_once(
    policies: list[Path],
) -> None:
    loaded = [load_evaluation_policy(p) for p in policies]
    gains = FeedbackGains(20.0, 40.0)
    both = evaluate(_spec(), loaded, controller_gains={"feedback": gains}).trials
    # per plant: pd's trials, feedback's, then rl's, each trial's policies in the order given
    plant = ["pd"] * 2 + ["feedback"] * 2 + ["rl"] * 4
    assert list(both["controller"]) == plant * 2
    seeds = [None if pd.isna(s) else int(s) for s in both["policy_seed"]]
    assert seeds == ([None] * 4 + [7, 3, 7, 3]) * 2
    assert both.groupby("controller").size().to_dict() == {"pd": 4, "feedback": 4, "rl": 8}
    rl = both[both["controller"] == "rl"]
    # two different actors push the same scenarios differently
    assert not np.array_equal(
        rl[rl["policy_seed"] == 7][METRICS].to_numpy(),
        rl[rl["policy_seed"] == 3][METRICS].to_numpy(),
    )
    # every policy's rows, and PD-only's and feedback's, are those of a run of it alone
    for k, policy in enumerate(loaded):
        alone = evaluate(_spec(), policy, controller_gains={"feedback": gains}).trials
        mine = both[(both["controller"] != "rl") | (both["policy_seed"] == policy.seed)]
        pd.testing.assert_frame_equal(
            mine.reset_index(drop=True),
            alone.reset_index(drop=True),
            check_dtype=False,
            check_exact=True,
        )
        assert policy.seed == (7, 3)[k]


def test_the_rl_steps_are_the_mean_over_the_policies(policies: list[Path]) -> None:
    loaded = [load_evaluation_policy(p) for p in policies]
    spec = TrialSpec(
        objects=("cube",), profiles=("chirp",), plants=("sim",), controllers=("rl",), trials=1
    )
    both = evaluate(spec, loaded).steps[list(STEP_COLUMNS)].to_numpy()
    alone = [evaluate(spec, p).steps[list(STEP_COLUMNS)].to_numpy() for p in loaded]
    np.testing.assert_allclose(both, 0.5 * (alone[0] + alone[1]), rtol=1e-12, atol=1e-15)


def test_policies_that_cannot_share_an_evaluation_are_refused(
    tmp_path: Path, policies: list[Path]
) -> None:
    loaded = load_evaluation_policy(policies[0])
    twin = load_evaluation_policy(_policy(tmp_path / "twin.pt", 7, init_seed=5))
    with pytest.raises(ConfigError, match="trained with seed 7"):
        evaluate(_spec(("pd", "rl")), [loaded, twin])
    unnamed = load_evaluation_policy(_policy(tmp_path / "unnamed.pt", None, init_seed=5))
    with pytest.raises(ConfigError, match="must name its training seed"):
        evaluate(_spec(("pd", "rl")), [loaded, unnamed])
    with pytest.raises(ConfigError, match="need a policy"):
        evaluate(_spec(("pd", "rl")), [])
    other = load_evaluation_policy(_policy(tmp_path / "other.pt", 4, init_seed=5, gate=1e-3))
    with pytest.raises(ConfigError, match="other environment settings"):
        evaluate(_spec(("pd", "rl")), [loaded, other])


def _evaluate(out: Path, *args: str):
    # rl only: the feedback gains file (pushctl/defaults/feedback_gains.toml) is another issue's
    tiny = ["--object", "cube", "--profile", "chirp", "--trials", "2", "--out", str(out)]
    tiny += ["--controller", "rl"]
    return runner.invoke(app, ["evaluate", *tiny, *args])


def test_the_cli_takes_repeated_policies_and_any_workers_write_the_same_bytes(
    tmp_path: Path, policies: list[Path], ray_local: None
) -> None:
    both = ["--policy", str(policies[0]), "--policy", str(policies[1])]
    one = _evaluate(tmp_path / "one", *both, "--workers", "1")
    two = _evaluate(tmp_path / "two", *both, "--workers", "2")
    assert one.exit_code == 0, one.output
    assert two.exit_code == 0, two.output
    for name in ("trials.csv", "steps.csv"):
        first = (tmp_path / "one" / name).read_bytes()
        assert first.replace(b"/one;", b"/two;") == (tmp_path / "two" / name).read_bytes()
    trials = pd.read_csv(tmp_path / "one" / "trials.csv", comment="#")
    assert sorted(trials["policy_seed"].dropna().astype(int).unique()) == [3, 7]
    made_by = (tmp_path / "one" / "trials.csv").read_text().splitlines()[0]
    assert f"--policy {policies[0]} --policy {policies[1]} --scenario-block 0" in made_by
    assert f"policy {policies[0]}, made by: a test run; seed 7" in made_by
    assert f"policy {policies[1]}, made by: a test run; seed 3" in made_by
    twice = _evaluate(
        tmp_path / "twice", "--policy", str(policies[0]), "--policy", str(policies[0])
    )
    assert twice.exit_code == 2 and "names one file twice" in twice.output
    assert not (tmp_path / "twice").exists()


def test_a_further_policy_pushes_as_after_a_fresh_reset_on_every_plant(
    policies: list[Path],
) -> None:
    # The second policy pushes a copy of the environment as the first reset left it; its
    # rows and per-step quantities must be those of an evaluation of it alone (its own
    # reset), to the bit, on each engine and on the proxy (its generators copied too).
    loaded = [load_evaluation_policy(p) for p in policies]
    spec = TrialSpec(
        objects=("wedge",),
        profiles=("trapezoid",),
        plants=("sim", "proxy", "mujoco"),
        controllers=("rl",),
        trials=1,
    )
    both = evaluate(spec, loaded)
    alone = evaluate(spec, loaded[1])
    second = both.trials[both.trials["policy_seed"] == loaded[1].seed]
    pd.testing.assert_frame_equal(
        second.reset_index(drop=True), alone.trials.reset_index(drop=True), check_exact=True
    )
    first = evaluate(spec, loaded[0]).steps[list(STEP_COLUMNS)].to_numpy()
    mean = both.steps[list(STEP_COLUMNS)].to_numpy()
    assert np.array_equal(mean, np.mean([first, alone.steps[list(STEP_COLUMNS)].to_numpy()], 0))

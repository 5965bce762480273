"""What a policy file holds, as ``train`` and ``evaluate`` say it: the shipped seed-0 policy
is the feedback law (no actor beat it), a zeroed actor without a base law is PD-only, and a
trained one names the episode its run kept it at."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pandas as pd
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.cli.policy_kind import describe_policy, is_zero_residual, read_validation
from pushctl.rl.networks import ActorPolicy
from pushctl.rl.policy import load_policy, write_policy

SHIPPED = Path(__file__).resolve().parents[2] / "results" / "training"
LAW = "no actor beat the law: this policy is the law"


def test_the_shipped_seed_0_policy_is_the_law() -> None:
    path = SHIPPED / "seed-0" / "policy.pt"
    assert describe_policy(load_policy(path), read_validation(path)).startswith(LAW)


def test_a_trained_policy_names_the_episode_its_run_kept(tmp_path: Path) -> None:
    shipped = load_policy(SHIPPED / "seed-2" / "policy.pt")
    state = shipped.actor.state()  # a trained actor: the shipped (zero) one, every weight moved
    state["actor"] = {name: tensor + 0.01 for name, tensor in state["actor"].items()}
    path = tmp_path / "policy.pt"
    write_policy(path, state, shipped.env, shipped.made_by)
    assert not is_zero_residual(load_policy(path))
    rows = {"episode": [0, 250, 500], "updates": [0, 8880, 23880], "score": [1.0, 0.9, 0.95]}
    frame = pd.DataFrame({**rows, "kept": [True, True, False]})
    frame.to_csv(tmp_path / "validation.csv", index=False)
    described = describe_policy(load_policy(path), read_validation(path))
    assert "episode 250 (8880 updates)" in described and "feedback law" in described
    # another file of the run (the last actor) is not the kept one
    assert read_validation(tmp_path / "policy_last.pt") is None


def test_a_zeroed_actor_on_pd_alone_is_pd_only(tmp_path: Path) -> None:
    shipped = load_policy(SHIPPED / "seed-2" / "policy.pt")
    path = tmp_path / "policy.pt"
    zero = ActorPolicy.zero_residual(shipped.actor.state())
    write_policy(path, zero, replace(shipped.env, base_law="none"), shipped.made_by)
    assert describe_policy(load_policy(path)).startswith("no actor beat the zero residual")


def test_evaluate_says_the_policy_is_the_law(tmp_path: Path) -> None:
    policy = SHIPPED / "seed-0" / "policy.pt"
    tiny = ["--object", "cube", "--profile", "constant", "--trials", "1", "--plant", "sim"]
    args = ["evaluate", *tiny, "--controller", "rl", "--policy", str(policy)]
    result = CliRunner().invoke(app, [*args, "--out", str(tmp_path / "e")])
    assert result.exit_code == 0, result.output
    assert f"seed-0/policy.pt: {LAW}" in " ".join(result.output.split())

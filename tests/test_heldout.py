"""The held-out PD-vs-RL comparison: pairing, a policy that never acts equals PD-only, and
bad input."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pushctl.evaluation.heldout import heldout_table, main, summary
from pushctl.rl.config import DDPGConfig
from pushctl.rl.ddpg import DDPGAgent
from pushctl.rl.env_config import EnvConfig
from pushctl.rl.policy import load_policy, write_policy
from pushctl.rl.spaces import observation_entries, scales


def _policy_file(tmp_path: Path, gate_threshold: float, final_init: float = 0.5) -> Path:
    """An untrained actor with large outputs, saved with a short push."""
    entries = observation_entries(2)
    agent = DDPGAgent(
        len(entries),
        3,
        DDPGConfig(hidden=(8, 8), actor_final_init=final_init),
        seed=0,
        obs_scale=scales(entries),
    )
    path = tmp_path / f"policy_{gate_threshold}.pt"
    env = EnvConfig(duration=2.0, gate_threshold=gate_threshold)
    write_policy(path, agent.actor_state(), env, "# made by: test")
    return path


def test_a_policy_behind_a_shut_gate_equals_pd_only(tmp_path: Path) -> None:
    policy = load_policy(_policy_file(tmp_path, gate_threshold=1.0))
    table = heldout_table(policy, per_cell=2, objects=("cube",), profiles=("trapezoid",))
    assert list(table["controller"]) == ["pd", "rl", "pd", "rl"]
    metrics = ["translation_error_pct", "force_error", "torque_error", "slip_fraction"]
    pd_rows = table[table["controller"] == "pd"][metrics].to_numpy()
    rl_rows = table[table["controller"] == "rl"][metrics].to_numpy()
    np.testing.assert_array_equal(pd_rows, rl_rows)
    assert table.loc[0, "mu_ground"] != table.loc[2, "mu_ground"]  # two drawn plants


def test_an_acting_policy_changes_the_push_of_the_same_scenario(tmp_path: Path) -> None:
    policy = load_policy(_policy_file(tmp_path, gate_threshold=0.0))
    table = heldout_table(policy, per_cell=1, objects=("wedge",), profiles=("constant",))
    pd_row, rl_row = table.iloc[0], table.iloc[1]
    assert (pd_row["mu_ground"], pd_row["seed"]) == (rl_row["mu_ground"], rl_row["seed"])
    assert rl_row["translation_error_pct"] != pd_row["translation_error_pct"]
    cells = summary(table)
    assert ("wedge", "constant") in cells.index
    assert ("all", "all") in cells.index


def test_the_command_writes_the_rows_and_refuses_a_missing_policy(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["--policy", str(tmp_path / "none.pt")]) == 2
    assert "no policy file" in capsys.readouterr().err
    (tmp_path / "bad.pt").write_bytes(b"garbage")
    assert main(["--policy", str(tmp_path / "bad.pt")]) == 2
    assert "corrupt" in capsys.readouterr().err

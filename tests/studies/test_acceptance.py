"""The acceptance table: paired RL − PD differences per cell and seed."""

from __future__ import annotations

import numpy as np
import pandas as pd

from studies.acceptance import main, paired, passes


def _trials() -> pd.DataFrame:
    """Cube/constant, sim: PD errors 1..10 %; seed 0's RL half of PD's, seed 1's equal."""
    rng = np.random.default_rng(0)
    rows = []
    for trial in range(10):
        pd_error = 1.0 + trial + rng.uniform(0.0, 0.1)
        for controller, seed, value in (
            ("pd", None, pd_error),
            ("rl", 0, 0.5 * pd_error),
            ("rl", 1, pd_error),
        ):
            rows.append(
                {
                    "object": "cube",
                    "profile": "constant",
                    "plant": "sim",
                    "controller": controller,
                    "trial": trial,
                    "policy_seed": seed,
                    "translation_error_pct": value,
                    "angle_error_pct": value,
                    "force_error": value,
                }
            )
    return pd.DataFrame(rows)


def test_a_halving_policy_passes_and_an_equal_one_does_not() -> None:
    table = paired(_trials(), "sim")
    assert list(table["policy_seed"]) == [0, 1]
    np.testing.assert_allclose(table["translation_error_pct_ratio"], [0.5, 1.0])
    assert list(passes(table, "translation_error_pct")) == [True, False]


def test_the_command_prints_a_table_and_refuses_a_missing_file(tmp_path, capsys) -> None:
    path = tmp_path / "trials.csv"
    _trials().to_csv(path, index=False)
    assert main([str(path)]) == 0
    assert "| cube | constant | 0 | 0.50 | yes, 10/10 |" in capsys.readouterr().out
    assert main([str(tmp_path / "none.csv")]) == 2
    assert "no file" in capsys.readouterr().err


def test_the_landed_force_error_is_compared_where_the_trials_have_it(tmp_path, capsys) -> None:
    trials = _trials()
    assert "force_error_landed_ratio" not in paired(trials, "sim").columns
    trials["force_error_landed"] = trials["force_error"] * np.where(trials["trial"] < 3, 3.0, 1.0)
    table = paired(trials, "sim")
    np.testing.assert_allclose(table["force_error_landed_ratio"], table["force_error_ratio"])
    assert list(table["force_error_landed_lower_in"]) == [10, 0]
    path = tmp_path / "trials.csv"
    trials.to_csv(path, index=False)
    assert main([str(path)]) == 0
    assert "| force vs landed RL/pd | lower?, in |" in capsys.readouterr().out


def test_a_rescued_failure_widens_the_interval_but_not_the_count() -> None:
    """RL 2 points below PD-only in 19 trials of 20, and 100 points below in one (a push PD-only
    failed): the mean's interval reaches past zero, the count says 20 of 20."""
    rows = []
    for trial in range(20):
        pd_error = 5.0 + (0.5 if trial % 2 else -0.5) + (100.0 if trial == 0 else 0.0)
        rl_error = pd_error - (100.0 if trial == 0 else 2.0)
        for controller, seed, value in (("pd", None, pd_error), ("rl", 0, rl_error)):
            rows.append(
                {"object": "wedge", "profile": "constant", "plant": "sim",
                 "controller": controller, "trial": trial, "policy_seed": seed,
                 "translation_error_pct": value, "angle_error_pct": value, "force_error": value}
            )  # fmt: skip
    table = paired(pd.DataFrame(rows), "sim")
    assert not passes(table, "angle_error_pct").item()
    assert table["angle_error_pct_lower_in"].item() == 20
    assert table["angle_error_pct_trials"].item() == 20


def test_the_cell_summary_pools_the_policies_and_counts_failed_pushes(tmp_path, capsys) -> None:
    """RL's mean over both policies (halving and equal) is 0.75 of PD-only's; PD-only's
    errors pass 3 % translation from trial 2 on, so 8 of its 10 pushes failed, and 5 + 8 of
    RL's 20 (the halving policy's from trial 5 on, the equal one's as PD-only's)."""
    from studies.acceptance import cell_summary

    (row,) = cell_summary(_trials(), "sim").to_dict("records")
    assert (row["object"], row["profile"]) == ("cube", "constant")
    np.testing.assert_allclose(row["translation_error_pct_ratio"], 0.75)
    assert (row["pd_failed"], row["pd_pushes"]) == (8, 10)
    assert (row["rl_failed"], row["rl_pushes"]) == (8 + 5, 20)
    path = tmp_path / "trials.csv"
    _trials().to_csv(path, index=False)
    assert main([str(path)]) == 0
    assert "| cube | constant | 0.75 | 0.75 | 0.75 | 8/10 | 13/20 |" in capsys.readouterr().out

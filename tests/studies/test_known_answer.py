"""The known-answer study: the recovery statistic on made-up trials, the preset's world, and
(slow) the learned actor recovering most of the feedback law's error reduction."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from pushctl.rl.presets import load_preset
from studies.known_answer import METRICS, PRESET, recovery, run, scenarios

BAR = 0.7
"""The share of the law's error reduction over PD-only the learned actor must recover."""


def _trials(rl_share: float, n: int = 12) -> pd.DataFrame:
    """PD-only's errors 1..2, the law's a tenth of them, RL ``rl_share`` of the way."""
    rng = np.random.default_rng(0)
    pd_error = rng.uniform(1.0, 2.0, n)
    law = 0.1 * pd_error
    rl = pd_error - rl_share * (pd_error - law) + rng.normal(0.0, 0.01, n)
    return pd.DataFrame(
        {f"{name}_{metric}": values for name, values in (("pd", pd_error), ("law", law), ("rl", rl))
         for metric in METRICS}
    )  # fmt: skip


@pytest.mark.parametrize("share", [0.0, 0.5, 1.0])
def test_recovery_is_the_share_of_the_laws_reduction_inside_its_interval(share: float) -> None:
    result = recovery(_trials(share), "angle_error_pct")
    assert result["recovery"] == pytest.approx(share, abs=0.02)
    assert result["recovery_low"] <= result["recovery"] <= result["recovery_high"]
    assert result["recovery_high"] - result["recovery_low"] < 0.1
    assert result["law"] < result["pd"]


def test_the_preset_is_a_residual_on_pd_only_in_the_known_answer_world() -> None:
    preset = load_preset(str(PRESET))
    assert preset.env.base_law == "none"
    assert preset.env.ranges == "randomisation_known_answer"
    assert preset.env.residual_scale == 1.0 and not preset.env.policy_gated


def test_each_cell_pushes_its_own_seeds() -> None:
    options = scenarios(load_preset(str(PRESET)).env, 3)
    seeds = [option["scenario_seed"] for option in options]
    assert len(options) == 18 and len(set(seeds)) == 18


@pytest.mark.slow  # three seeds of the preset (160 episodes each) and 72 paired pushes: ~10 min
@pytest.mark.xfail(
    strict=True,
    reason="seeds 0 and 2 lose a wedge push that starts on one prong (docs/known-answer.md)",
)
def test_the_learned_actor_recovers_most_of_the_laws_reduction(tmp_path) -> None:
    _, table = run([0, 1, 2], tmp_path, trials=4)
    assert (table["recovery"] >= BAR).all(), table.to_string()

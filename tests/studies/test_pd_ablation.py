"""The ablation of the residual on PD-only (studies.pd_ablation): each variant changes its own
group of settings only, the unscaled variant trains with unit observation scales, and the
summary reads each run's kept and last actors."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from pushctl.rl.presets import load_preset
from studies.pd_ablation import BASE, VARIANTS, _unit_scales, preset_of, summary


def test_each_variant_changes_its_own_settings_only() -> None:
    base = load_preset(str(BASE))
    assert base.env.base_law == "none"
    changed = {
        "prior-0": ("ddpg", {"prior_weight": 0.0}),
        "prior-2": ("ddpg", {"prior_weight": 2.0}),
        "critic-parts": (
            "ddpg",
            {
                "twin_critics": True,
                "n_step": 3,
                "critic_layer_norm": True,
                "privileged_critic": True,
            },
        ),
        "eq17-metrics": ("env", {"w_normal": 1.0, "w_tangential": 1.0, "w_torque": 25.0}),
        "hold": ("env", {"policy_holds_off_contact": True}),
        "pose": ("env", {"w_metrics": 0.0, "w_pose": 100.0}),
        "pose-heading": ("env", {"w_metrics": 0.0, "w_pose": 100.0, "gate_length": 0.2}),
    }
    combined = preset_of("pose-prior-2")
    assert combined.env == preset_of("pose").env
    assert combined.ddpg == preset_of("prior-2").ddpg and combined.train == base.train
    for name in VARIANTS.keys() - {"pose-prior-2"}:
        preset = preset_of(name)
        part, changes = changed.get(name, ("ddpg", {}))
        expected = replace(base, **{part: replace(getattr(base, part), **changes)})
        assert preset == expected, name
    for name, file in (("pose", "pd-pose.toml"), ("pose-heading", "pd-pose-heading.toml")):
        same = load_preset(str(BASE.parent / file))
        assert preset_of(name) == replace(same, name=base.name), name


def test_the_unscaled_variant_trains_on_unit_scales() -> None:
    import pushctl.rl.train as train_module

    physical = train_module.scales
    with _unit_scales(True):
        assert np.all(train_module.scales(range(5)) == 1.0)
    assert train_module.scales is physical


def test_the_summary_reads_the_kept_and_the_last_actor(tmp_path: Path) -> None:
    directory = tmp_path / "hold" / "seed-2"
    directory.mkdir(parents=True)
    zero = [0.0] * 3
    pd.DataFrame(
        {
            "episode": [0, 20, 40],
            "translation_error_pct": [0.8, 0.5, 0.9],
            "angle_error_pct": [2.7, 1.8, 3.0],
            "kept": [False, True, False],
            "translation_diff": [0.0, -0.3, 0.1],
            "translation_diff_low": [0.0, -0.4, -0.1],
            "translation_diff_high": [0.0, -0.2, 0.3],
            "angle_diff": [0.0, -0.9, 0.3],
            "angle_diff_low": [0.0, -1.5, -0.2],
            "angle_diff_high": [0.0, -0.3, 0.8],
            "failed": zero,
        }
    ).to_csv(directory / "validation.csv", index=False)
    row = summary(tmp_path).iloc[0]
    assert (row["variant"], row["seed"]) == ("hold", 2)
    assert row["kept"].startswith("ep 20: -0.30 [-0.40, -0.20], -0.90")
    assert row["last"].startswith("ep 40: +0.10")
    assert row["better_on_both_means"] == "1 of 2"

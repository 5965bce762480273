"""The ablation presets and the `paper_v1` preset: each loads, differs from the `quick` preset
in what its name says only, and validates with the paired rule on 120 pushes."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from pushctl.rl.config import DDPGConfig
from pushctl.rl.presets import load_preset
from pushctl.task.env_config import EnvConfig

EXPERIMENTS = Path(__file__).resolve().parents[2] / "experiments"

CRITIC = dict(twin_critics=True, n_step=3, critic_layer_norm=True, critic_warmup_updates=2000)
VARIANTS = {
    "baseline": ({}, {}),
    "authority": (dict(residual_scale=1.0, policy_gated=False, observe_context=True), {}),
    "critic": (dict(residual_scale=1.0, policy_gated=False, observe_context=True), CRITIC),
    "asymmetric": (
        dict(residual_scale=1.0, policy_gated=False, observe_context=True),
        {**CRITIC, "privileged_critic": True},
    ),
}


@pytest.mark.parametrize("name", sorted(VARIANTS))
def test_each_variant_is_the_quick_preset_with_its_parts(name):
    quick, variant = (
        load_preset("quick"),
        load_preset(str(EXPERIMENTS / "ablation" / f"{name}.toml")),
    )
    env, ddpg = VARIANTS[name]
    assert variant.env == replace(quick.env, **env)
    assert variant.ddpg == replace(quick.ddpg, **ddpg)
    assert variant.train.episodes == quick.train.episodes
    assert variant.train.select_on == "paired" and variant.train.validation_per_cell == 20


def test_paper_v1_is_push_v1_with_every_critic_part():
    preset = load_preset(str(EXPERIMENTS / "train_paper_v1.toml"))
    assert preset.env == EnvConfig.v1()
    for part in ("twin_critics", "critic_layer_norm", "privileged_critic"):
        assert getattr(preset.ddpg, part) is True
    assert preset.ddpg.n_step > 1 and preset.ddpg.critic_warmup_updates > 0
    assert preset.train.select_on == "paired" and preset.train.validation_per_cell * 6 >= 120
    assert isinstance(preset.ddpg, DDPGConfig)


def test_the_pose_term_presets_are_the_known_answer_learner_on_every_unknown():
    known = load_preset(str(EXPERIMENTS / "train_known_answer.toml"))
    pose = load_preset(str(EXPERIMENTS / "ablation" / "pd-pose.toml"))
    heading = load_preset(str(EXPERIMENTS / "ablation" / "pd-pose-heading.toml"))
    assert pose.env == replace(known.env, ranges=EnvConfig().ranges)
    assert pose.ddpg == known.ddpg and pose.env.base_law == "none"
    assert heading.env == replace(pose.env, gate_length=0.2) and heading.ddpg == pose.ddpg
    assert heading.train == pose.train
    metrics = load_preset(str(EXPERIMENTS / "ablation" / "pd-metrics.toml"))
    assert metrics.env == replace(pose.env, w_pose=0.0, w_metrics=0.03)
    assert metrics.ddpg == pose.ddpg and metrics.train == pose.train

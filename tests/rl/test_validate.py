"""The validation set's PD-only baseline is the same push as the policy's, on either plant;
a collector's pushes from its kept resets are those after a fresh reset, bit for bit."""

from __future__ import annotations

import pytest
import torch

from pushctl.control.gains import load_gains
from pushctl.episode.ranges import PLANTS
from pushctl.rl.networks import Actor, ActorPolicy, initialise
from pushctl.rl.validate import ValidationPushes, Validator, validation_env, validation_metrics
from pushctl.task.env_config import EnvConfig


@pytest.mark.parametrize("plant", PLANTS)
def test_a_policy_behind_a_shut_gate_scores_exactly_pd_only(plant: str) -> None:
    """With the gate never open the residual never acts, so the policy's pushes are PD-only's,
    proxy effects (latency, friction, noisy estimates, camera) included."""
    config = EnvConfig(
        objects=("wedge",),
        profiles=("chirp",),
        duration=2.0,
        plant=plant,
        gate_threshold=1.0,
        stream="tuning",  # the mujoco plant is refused on the training stream
        landing="believed",  # re-landed, a shut gate pushes from elsewhere than PD-only
    )
    validator = Validator(config, load_gains(), per_cell=2)
    n_obs = validator.env.observation_space.shape[0]
    actor_state = ActorPolicy(Actor(n_obs, 3, [8])).state()
    score = validator.score(actor_state)
    assert score.force_error == score.pd_force_error
    assert score.translation_error_pct == score.pd_translation_error_pct


def test_the_tracking_rule_keeps_an_actor_that_tracks_better_whatever_its_force() -> None:
    from pushctl.rl.validate import ValidationScore

    values = dict(
        force_error=0.03,
        translation_error_pct=0.2,
        pd_force_error=0.02,
        pd_translation_error_pct=0.8,
        angle_error_pct=0.5,
        pd_angle_error_pct=2.0,
    )
    tracking = ValidationScore(**values, rule="tracking")
    assert tracking.beats_pd
    assert tracking.score == pytest.approx(0.25 + 0.25 + 1.5)
    assert not ValidationScore(**values).beats_pd  # the force error is above PD-only's
    worse_angle = ValidationScore(**{**values, "angle_error_pct": 2.5}, rule="tracking")
    assert not worse_angle.beats_pd


@pytest.mark.parametrize("plant", ["sim", "proxy"])
def test_pushes_from_kept_resets_equal_pushes_after_a_fresh_reset(plant: str) -> None:
    config = EnvConfig(objects=("cube", "wedge"), profiles=("chirp",), duration=1.0, plant=plant)
    gains = load_gains()
    options = Validator(config, gains, per_cell=2).options
    pushes = ValidationPushes(config, gains)
    n_obs = pushes.env.observation_space.shape[0]
    actors = []
    for seed in (1, 2):
        actor = Actor(n_obs, 3, [8])
        initialise(actor, torch.Generator().manual_seed(seed), final_bound=0.5)
        actors.append(ActorPolicy(actor.eval()).state())
    for actor_state in actors:  # the second actor's pushes start from the kept resets
        fresh = validation_metrics(validation_env(config, gains), actor_state, options)
        assert pushes.metrics(actor_state, options) == fresh
        assert pushes.metrics(actor_state, options[::-1]) == fresh[::-1]
    assert len(pushes._reset) == len(options)  # one reset per scenario, kept
    assert fresh != validation_metrics(validation_env(config, gains), actors[0], options)


def test_paired_test_against_the_law_by_hand():
    from pushctl.rl.validate import paired_test

    law = [(0.02, 1.0, 2.0), (0.02, 2.0, 3.0), (0.02, 3.0, 4.0), (0.02, 4.0, 50.0)]
    better = [(0.02, 0.5, 1.5), (0.02, 1.4, 2.6), (0.02, 2.5, 3.4), (0.02, 3.6, 49.5)]
    test = paired_test(better, law)
    assert test.n == 4 and test.law_failed == 1 and test.failed == 1
    assert test.translation_diff == pytest.approx(-0.5)
    # differences -0.5, -0.6, -0.5, -0.4: sd 0.0816, t(0.975, 3) = 3.182
    assert test.translation_high == pytest.approx(-0.5 + 3.1824 * 0.08165 / 2, abs=1e-3)
    assert test.beats_law
    worse = [(0.02, 0.5, 1.5), (0.02, 1.4, 2.6), (0.02, 2.5, 30.0), (0.02, 3.6, 49.5)]
    assert not paired_test(worse, law).beats_law  # one more failed push, and the angle CI
    assert not paired_test(law, law).beats_law  # zero differences: not below zero

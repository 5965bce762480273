"""The validation set's PD-only baseline is the same push as the policy's, on either plant."""

from __future__ import annotations

import pytest

from pushctl.control.gains import load_gains
from pushctl.episode.ranges import PLANTS
from pushctl.rl.env_config import EnvConfig
from pushctl.rl.networks import Actor, ActorPolicy
from pushctl.rl.validate import Validator


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

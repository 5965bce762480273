"""The feedback law takes each trial's reset over from the policy's environment
(PushEnv.reset_from): the same rows and per-step quantities, to the byte, as when its own
environment resets to the scenario, and the same environment state after it."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from pushctl.control.feedback import load_feedback_gains
from pushctl.control.gains import load_gains
from pushctl.controllers import PushSetup, paper_controllers
from pushctl.controllers.drive import build_controllers
from pushctl.errors import ConfigError, StateError
from pushctl.evaluation.trials import Job, run_trial
from pushctl.rl.policy import load_policy
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig

POLICY = Path(__file__).resolve().parents[2] / "results" / "training" / "seed-2" / "policy.pt"


def _envs(plant: str) -> tuple[PushEnv, dict]:
    """The policy's environment and the controllers, as `pushctl evaluate` builds them (the
    feedback law's generator seeded, so two can be compared after their resets)."""
    # today's landing whatever the shipped policy's (a policy trained before the re-landing
    # pushes from the approach's, and its trials are then not handed over)
    policy = load_policy(POLICY)
    config = replace(policy.env, stream="evaluation", plant=plant, landing=EnvConfig().landing)
    gains = load_gains()
    setup = PushSetup(config, gains, ((policy.actor, 2),), {"feedback": load_feedback_gains()})
    controllers = build_controllers(paper_controllers(), setup)
    controllers["feedback"].env.np_random = np.random.default_rng(5)
    return PushEnv(config, gains), controllers


@pytest.mark.parametrize(("plant", "obj", "profile"), [
    ("sim", "wedge", "chirp"), ("proxy", "cube", "trapezoid"), ("mujoco", "cube", "constant"),
])  # fmt: skip
def test_the_hand_over_gives_the_trial_of_a_fresh_reset_to_the_byte(
    plant: str, obj: str, profile: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    job = Job(obj, profile, plant, trial=0, seed=3)
    env, controllers = _envs(plant)
    feedback_env = controllers["feedback"].env
    assert feedback_env.episodes_differ(env) is None  # the shipped policy's env: handed over
    handed = run_trial(env, controllers, job)
    after_hand_over = feedback_env.np_random.integers(2**31 - 1)

    env, controllers = _envs(plant)
    feedback_env = controllers["feedback"].env
    monkeypatch.setattr(PushEnv, "episodes_differ", lambda self, other: "forced")
    fresh = run_trial(env, controllers, job)
    assert feedback_env.np_random.integers(2**31 - 1) == after_hand_over
    assert len(handed.rows) == len(fresh.rows) == 3
    for mine, theirs in zip(handed.rows, fresh.rows, strict=True):
        assert repr(mine) == repr(theirs)  # every value, NaN and float bits included
    for controller, quantities in fresh.steps.items():
        assert np.array_equal(handed.steps[controller], quantities, equal_nan=True)


def test_reset_from_refuses_an_advanced_episode_and_other_episode_settings() -> None:
    policy_env, controllers = _envs("sim")
    feedback_env = controllers["feedback"].env
    with pytest.raises(StateError, match="just reset"):
        feedback_env.reset_from(policy_env)
    policy_env.reset(options={"object": "cube", "profile": "constant", "scenario_seed": 1})
    other = PushEnv(
        replace(policy_env.config, residual_path="velocity", landing="believed"), load_gains()
    )
    assert other.episodes_differ(policy_env) == "residual_path ('velocity' against 'reference')"
    with pytest.raises(ConfigError, match="differ in residual_path"):
        other.reset_from(policy_env)
    policy_env.step(np.zeros(3))
    with pytest.raises(StateError, match="just reset"):
        feedback_env.reset_from(policy_env)
    training = PushEnv(EnvConfig(), load_gains())
    assert training.episodes_differ(feedback_env) == "stream ('training' against 'evaluation')"

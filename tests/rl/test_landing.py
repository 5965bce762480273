"""Where an environment's pushes start (EnvConfig.landing): re-landed on the plan's spot of
the object as measured, with PD-only's comparison push from where the approach landed."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from pushctl.episode.landed import spot_offset
from pushctl.errors import ConfigError
from pushctl.rl.policy import pd_only_episode
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.spaces import index, observation_entries

OPTIONS = {"object": "wedge", "profile": "chirp", "scenario_seed": 20007}


def _env(landing: str, plant: str = "sim") -> PushEnv:
    return PushEnv(EnvConfig(landing=landing, plant=plant, stream="tuning", duration=1.0))


def _pd_bytes(env: PushEnv) -> bytes:
    return pd_only_episode(env).finish().to_frame().to_numpy().tobytes()


def test_the_setting_is_checked_and_an_old_policy_keeps_the_approach_s_landing() -> None:
    with pytest.raises(ConfigError, match="landing must be one of believed, measured"):
        EnvConfig(landing="aimed")
    with pytest.raises(ConfigError, match="needs residual_path"):
        EnvConfig(residual_path="velocity")
    assert EnvConfig(residual_path="velocity", landing="believed").landing == "believed"
    assert EnvConfig().landing == "measured"
    saved = EnvConfig().to_dict()
    del saved["landing"]
    assert EnvConfig.from_saved(saved).landing == "believed"


@pytest.mark.parametrize("plant", ["sim", "proxy"])
def test_pd_only_pushes_from_the_approach_s_landing_to_the_byte(plant: str) -> None:
    """Re-landing changes the closed-loop push only: PD-only's push of a re-landed reset is
    byte for byte that of the same reset without it."""
    measured, believed = _env("measured", plant), _env("believed", plant)
    measured.reset(options=OPTIONS)
    believed.reset(options=OPTIONS)
    assert _pd_bytes(measured) == _pd_bytes(believed)
    assert measured.believed_start is not measured.episode
    assert believed.believed_start is believed.episode


def test_the_reset_re_lands_and_observes_the_offset_that_holds_the_plate() -> None:
    env = _env("measured")
    observation, _ = env.reset(options=OPTIONS)
    episode = env.episode
    assert episode is not None
    offset = episode.reference_offset
    assert np.linalg.norm(offset[:2]) > 1e-4  # this draw's placement error moves the plate
    # the observation carries the offset (plan frame x and y [m])
    where = index(observation_entries(2, reference_offset=True))
    observed = observation[[where["offset_x"], where["offset_y"]]]
    assert float(np.linalg.norm(observed)) == pytest.approx(np.linalg.norm(offset[:2]), rel=1e-5)
    before = abs(spot_offset(env.believed_start.trace(), 0))
    after = abs(spot_offset(episode.trace(), 0))
    assert after < 0.25 * before


def test_reset_from_hands_over_the_re_landing_and_pd_only_s_start() -> None:
    env, other = _env("measured"), _env("measured")
    env.reset(options=OPTIONS)
    other.reset_from(copy.deepcopy(env))
    assert other.episode is not None and env.episode is not None
    assert np.array_equal(other.episode.reference_offset, env.episode.reference_offset)
    assert _pd_bytes(other) == _pd_bytes(env)
    with pytest.raises(ConfigError, match="landing"):
        _env("believed").reset_from(env)


def test_the_landing_move_stays_within_the_offset_bound() -> None:
    env = PushEnv(EnvConfig(stream="tuning", duration=1.0, offset_limit_linear=2e-4))
    env.reset(options=OPTIONS)
    assert env.episode is not None
    offset = env.episode.reference_offset
    assert np.max(np.abs(offset[:2])) == pytest.approx(2e-4)
    assert math.isclose(offset[2], 0.0)

"""The feedback law's catch-up phase and its own gate (pushctl.control.feedback_gains): the
phase's gains and relaxed caps, the caps kept while a prong carries little load, the steady
law after the phase, the dead band, and the named gains files."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from pushctl.control.feedback import (
    STEADY_FEEDBACK_FILE,
    FeedbackGains,
    FeedbackLaw,
    load_feedback_gains,
)
from pushctl.errors import ConfigError

LEVER = np.array([-0.03, 0.0])
PRONGS = np.array([-0.035, 0.035])
LOADED = [0.5, 0.5]  # both prongs well loaded [N]
LIGHT = [0.5, 0.1]  # one prong loaded, the other touching under the catch-up's 0.2 N
CATCHUP = FeedbackGains(
    k=1.0,
    k_i=0.0,
    smoothing=0.0,
    catchup_time=3.0,
    catchup_k=3.0,
    catchup_k_i=0.0,
    catchup_lateral_ratio=0.15,
    catchup_turn_ratio=0.15,
    catchup_force=0.2,
)
SIDEWAYS = np.array([1e-3, 5e-3, 0.0])  # 5 mm across: k e_y far above either cap


def _law(gains: FeedbackGains = CATCHUP) -> FeedbackLaw:
    return FeedbackLaw(gains, LEVER, dt=0.01, prongs=PRONGS)


def test_the_catch_up_runs_its_gains_and_relaxed_caps_while_every_prong_is_loaded() -> None:
    """At 10 mm/s: the catch-up's caps allow 1.5 mm/s across (the steady 0.5), its k = 3 /s
    moves x at 3 mm/s per mm."""
    twist = _law().twist(SIDEWAYS, LOADED, speed=0.01, time=1.0)
    np.testing.assert_allclose(twist, [3e-3, 1.5e-3, 0.0])


def test_the_catch_up_keeps_the_steady_caps_while_a_prong_carries_little_load() -> None:
    """A prong above contact (50 mN) but under catchup_force: the gains are the phase's,
    the caps the steady ones (the guard against the single-prong spin)."""
    twist = _law().twist(SIDEWAYS, LIGHT, speed=0.01, time=1.0)
    np.testing.assert_allclose(twist, [3e-3, 5e-4, 0.0])


def test_the_turn_cap_is_relaxed_in_the_catch_up_only() -> None:
    """The farthest prong 35 mm from the centre: 0.15 · 10 mm/s / 35 mm = 42.9 mrad/s in
    the phase, 14.3 mrad/s after it."""
    error = np.array([0.0, 0.0, 0.05])
    during = _law().twist(error, LOADED, speed=0.01, time=2.99)[2]
    after = _law().twist(error, LOADED, speed=0.01, time=3.0)[2]
    assert during == pytest.approx(0.15 * 0.01 / 0.035)
    assert after == pytest.approx(0.05 * 0.01 / 0.035)


def test_after_the_catch_up_or_without_a_clock_the_law_is_the_steady_one() -> None:
    steady = _law(replace(CATCHUP, catchup_time=0.0)).twist(SIDEWAYS, LOADED, speed=0.01)
    np.testing.assert_allclose(steady, [1e-3, 5e-4, 0.0])
    later = _law().twist(SIDEWAYS, LOADED, speed=0.01, time=3.5)
    no_clock = _law().twist(SIDEWAYS, LOADED, speed=0.01)
    np.testing.assert_array_equal(later, steady)
    np.testing.assert_array_equal(no_clock, steady)


def test_the_laws_own_gate_outputs_zero_and_leaves_its_state_inside_the_dead_band() -> None:
    """gate_threshold 0.15 mm after the phase, catchup_gate 0 in it: a 0.1 mm error acts in
    the phase and not after, where the integral and the lag stay as they were."""
    gains = replace(CATCHUP, k_i=0.5, smoothing=0.1, gate_threshold=1.5e-4)
    law = _law(gains)
    small = np.array([1e-4, 0.0, 0.0])
    assert law.twist(small, LOADED, speed=0.01, time=1.0)[0] > 0.0
    integral, output = law.integral, law.output
    np.testing.assert_array_equal(law.twist(small, LOADED, speed=0.01, time=4.0), 0.0)
    np.testing.assert_array_equal(law.integral, integral)
    np.testing.assert_array_equal(law.output, output)
    big = np.array([2e-4, 0.0, 0.0])  # outside the band: the law acts again
    assert law.twist(big, LOADED, speed=0.01, time=4.0)[0] > 0.0
    assert gains.owns_gate and not CATCHUP.owns_gate


def test_a_bad_catch_up_setting_is_a_config_error() -> None:
    with pytest.raises(ConfigError, match="gate_threshold must be a finite number >= 0"):
        FeedbackGains(gate_threshold=-1.0)
    with pytest.raises(ConfigError, match="catchup_time must be a finite number >= 0"):
        FeedbackGains(catchup_time=math.nan)
    with pytest.raises(ConfigError, match="catchup_turn_ratio must be a number >= 0"):
        FeedbackGains(catchup_turn_ratio=-0.1)


def test_the_named_gains_files() -> None:
    """feedback_gains_v1.toml is the steady law; the default file has a catch-up phase, a
    guard above contact, and its own gate."""
    v1 = load_feedback_gains(STEADY_FEEDBACK_FILE)
    assert v1.catchup_time == 0.0 and not v1.owns_gate
    catchup = load_feedback_gains()
    assert catchup.catchup_time > 0.0 and catchup.owns_gate
    assert catchup.catchup_force > catchup.contact_force
    assert (catchup.k, catchup.k_i) == (v1.k, v1.k_i)  # the steady law after the phase


def test_the_feedback_environment_opens_its_gate_for_a_law_with_its_own() -> None:
    from pushctl.controllers.feedback import feedback_config
    from pushctl.task.env_config import EnvConfig

    config = EnvConfig()
    assert feedback_config(config).gate_threshold == config.gate_threshold
    assert feedback_config(config, CATCHUP).gate_threshold == config.gate_threshold
    owning = replace(CATCHUP, gate_threshold=1.5e-4)
    assert feedback_config(config, owning).gate_threshold == 0.0


def test_the_feedback_environment_never_holds_the_law_for_a_policy() -> None:
    """A policy trained with the contact hold is compared with the law as it is: the law's
    own hold seeks the unloaded prong, which the policy's hold would drop."""
    from pushctl.controllers.feedback import feedback_config
    from pushctl.task.env_config import EnvConfig

    held = EnvConfig(policy_holds_off_contact=True)
    assert not feedback_config(held).policy_holds_off_contact

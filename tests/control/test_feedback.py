"""The feedback baseline's PI law (pushctl.control.feedback): the P and I terms, the integral
frozen off contact, the twist carried to the pusher origin, and its gains file."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from pushctl.control.feedback import FeedbackGains, FeedbackLaw, load_feedback_gains
from pushctl.errors import ConfigError

LEVER = np.array([-0.03, 0.0])  # the pusher 30 mm behind the object's centre
# smoothing=0.0 below: the law itself, without the output lag (tested apart)
TOUCHING = np.array([0.2, 0.3])  # both prongs above the 50 mN threshold [N]


def test_the_p_term_and_the_integral_of_a_constant_error() -> None:
    law = FeedbackLaw(FeedbackGains(k=0.5, k_i=0.2, smoothing=0.0), LEVER, dt=0.01)
    error = np.array([1e-3, -2e-3, 0.0])
    for _ in range(100):  # 1 s
        twist = law.twist(error, TOUCHING)
    np.testing.assert_allclose(law.integral, error * 1.0, rtol=1e-12)
    np.testing.assert_allclose(twist[:2], (0.5 + 0.2 * 1.0) * error[:2], rtol=1e-12)
    assert twist[2] == 0.0


def test_off_contact_the_law_holds_still_by_default() -> None:
    """On the reference path the output is the offset's rate: zero while a prong is off."""
    law = FeedbackLaw(FeedbackGains(k=0.5, k_i=1.0, smoothing=0.0), LEVER, dt=0.01)
    np.testing.assert_array_equal(law.twist(np.array([2e-3, 0.0, 0.01]), [0.2, 0.0]), 0.0)
    np.testing.assert_array_equal(law.integral, np.zeros(3))


def test_the_integral_is_frozen_while_a_prong_carries_under_50_mN() -> None:
    gains = FeedbackGains(k=0.5, k_i=1.0, hold_off_contact=False, smoothing=0.0)
    assert gains.contact_force == 0.05
    law = FeedbackLaw(gains, LEVER, dt=0.01)
    error = np.array([2e-3, 0.0, 0.0])  # an object ahead of the plan, not touched yet
    twist = law.twist(error, np.array([0.2, 0.049]))
    np.testing.assert_array_equal(law.integral, np.zeros(3))
    assert twist[0] == pytest.approx(0.5 * 2e-3)  # the P term still acts
    law.twist(error, np.array([0.05, 0.05]))
    np.testing.assert_allclose(law.integral, 0.01 * error)


def test_the_proxys_force_noise_on_an_unloaded_prong_leaves_the_seek_at_full_rate() -> None:
    """The proxy's force estimate (σ = 20 mN at no load) on a prong that carries nothing:
    at the 50 mN threshold the seek ramps up and turns at its full rate; at a 10 mN threshold
    the prong reads loaded on about a third of the steps, each restarting the ramp, and the
    seek turns at a tenth of its rate (docs/residual-and-feedback.md §4)."""
    from pushctl.episode.proxy import ProxyEffects

    effects = ProxyEffects()
    assert effects.force_noise_floor == 0.02
    rng = np.random.default_rng(0)
    readings = [effects.noisy_forces(np.array([0.0, 0.5]), rng) for _ in range(300)]
    mean_rate = {}
    for threshold in (0.01, 0.05):
        gains = FeedbackGains(seek_rate=0.1, seek_ramp=0.2, smoothing=0.0, contact_force=threshold)
        law = FeedbackLaw(gains, LEVER, dt=0.01, prongs=np.array([-0.035, 0.035]))
        omega = [law.twist(np.zeros(3), reading)[2] for reading in readings]
        mean_rate[threshold] = float(np.mean(omega[100:]))
    assert mean_rate[0.05] > 0.09
    assert mean_rate[0.01] < 0.02  # measured 0.0105 rad/s, against 0.0948 at 50 mN


def test_an_angle_correction_moves_the_pusher_origin_as_a_point_of_the_object() -> None:
    """u_θ about the object's centre: the pusher origin at r moves at u_θ ẑ × r."""
    lever = np.array([-0.03, 0.01])
    law = FeedbackLaw(FeedbackGains(k=1.0, k_i=0.0, smoothing=0.0), lever, dt=0.01)
    twist = law.twist(np.array([0.0, 0.0, 0.02]), TOUCHING)
    omega = 0.02
    np.testing.assert_allclose(twist, [-omega * lever[1], omega * lever[0], omega], rtol=1e-12)


def test_the_sideways_rate_is_capped_at_a_share_of_the_plans_speed() -> None:
    """u_y = k e_y = 5 mm/s against a 10 mm/s plan: capped at 5 % of it, 0.5 mm/s, in
    either direction; without a speed (or with an infinite ratio) uncapped; x and the
    angle untouched."""
    error = np.array([1e-3, 5e-3, 0.0])
    capped = FeedbackLaw(FeedbackGains(k=1.0, lateral_ratio=0.05, smoothing=0.0), LEVER, dt=0.01)
    np.testing.assert_allclose(capped.twist(error, TOUCHING, speed=0.01), [1e-3, 5e-4, 0.0])
    np.testing.assert_allclose(capped.twist(-error, TOUCHING, speed=0.01), [-1e-3, -5e-4, 0.0])
    np.testing.assert_allclose(capped.twist(error, TOUCHING), error)
    free = FeedbackLaw(FeedbackGains(k=1.0, lateral_ratio=math.inf, smoothing=0.0), LEVER, dt=0.01)
    np.testing.assert_allclose(free.twist(error, TOUCHING, speed=0.01), error)
    with pytest.raises(ConfigError, match="lateral_ratio must be a number >= 0"):
        FeedbackGains(lateral_ratio=-0.1)


def test_the_turn_is_capped_so_the_farthest_prong_moves_at_a_share_of_the_plans_speed() -> None:
    """Prongs at ±35 mm, the pusher 10 mm left of the object's centre: the farthest prong is
    45 mm from it, so a 5 % cap at 10 mm/s allows 0.5 mm/s / 45 mm = 11.1 mrad/s; the
    pusher origin then moves as a point of the object at that turn."""
    lever = np.array([-0.03, 0.01])
    prongs = np.array([-0.035, 0.035])
    law = FeedbackLaw(
        FeedbackGains(k=1.0, turn_ratio=0.05, smoothing=0.0), lever, dt=0.01, prongs=prongs
    )
    cap = 0.05 * 0.01 / 0.045
    twist = law.twist(np.array([0.0, 0.0, 0.2]), TOUCHING, speed=0.01)
    np.testing.assert_allclose(twist, [-cap * lever[1], cap * lever[0], cap], rtol=1e-12)
    assert law.twist(np.array([0.0, 0.0, -0.2]), TOUCHING, speed=0.01)[2] == pytest.approx(-cap)
    small = law.twist(np.array([0.0, 0.0, 1e-3]), TOUCHING, speed=0.01)  # under the cap
    assert small[2] == pytest.approx(1e-3)
    assert law.twist(np.array([0.0, 0.0, 0.2]), TOUCHING)[2] == pytest.approx(0.2)  # no speed
    free = FeedbackLaw(
        FeedbackGains(k=1.0, turn_ratio=math.inf, smoothing=0.0), lever, dt=0.01, prongs=prongs
    )
    assert free.twist(np.array([0.0, 0.0, 0.2]), TOUCHING, speed=0.01)[2] == pytest.approx(0.2)
    with pytest.raises(ConfigError, match="turn_ratio must be a number >= 0"):
        FeedbackGains(turn_ratio=-1.0)


def test_the_output_follows_the_law_through_a_first_order_lag() -> None:
    """τ = 0.1 s, dt = 0.01 s: each call moves the output 1/11 of the way to the law's; a
    law that flips between a value and zero every step gives about half of it, steadily,
    instead of the flip."""
    gains = FeedbackGains(k=1.0, smoothing=0.1, lateral_ratio=math.inf, turn_ratio=math.inf)
    law = FeedbackLaw(gains, LEVER, dt=0.01)
    error = np.array([1e-3, 0.0, 0.0])
    first = law.twist(error, TOUCHING)
    np.testing.assert_allclose(first, error / 11.0, rtol=1e-12)
    outputs = [law.twist(error if i % 2 else 0.0 * error, TOUCHING)[0] for i in range(400)]
    assert 0.4e-3 < min(outputs[-20:]) < max(outputs[-20:]) < 0.6e-3
    assert FeedbackLaw(replace(gains, smoothing=0.0), LEVER, 0.01).twist(error, TOUCHING)[0] == (
        pytest.approx(1e-3)
    )
    with pytest.raises(ConfigError, match="smoothing must be a finite number >= 0"):
        FeedbackGains(smoothing=-0.1)


def test_with_one_prong_off_the_plate_turns_about_the_loaded_one_ramping_up() -> None:
    """Prongs at y = ∓30 mm, the first off: the plate turns about the second (which stays
    put) so the first moves forwards, at a rate ramped from 0 to 0.1 rad/s over 0.2 s; the
    ramp starts again after both prongs were loaded."""
    gains = FeedbackGains(seek_rate=0.1, seek_ramp=0.2, smoothing=0.0)
    law = FeedbackLaw(gains, LEVER, dt=0.01, prongs=np.array([-0.03, 0.03]))
    first_off = np.array([0.0, 0.2])
    twists = np.array([law.twist(np.zeros(3), first_off) for _ in range(30)])
    omega = twists[:, 2]
    np.testing.assert_allclose(omega[:20], 0.1 * np.arange(1, 21) * 0.01 / 0.2, rtol=1e-12)
    np.testing.assert_allclose(omega[20:], 0.1, rtol=1e-12)
    loaded_prong_x = twists[:, 0] - omega * 0.03  # the plate point at y = +30 mm
    free_prong_x = twists[:, 0] - omega * -0.03
    np.testing.assert_allclose(loaded_prong_x, 0.0, atol=1e-15)
    assert (free_prong_x > 0.0).all()
    law.twist(np.zeros(3), TOUCHING)
    assert law.twist(np.zeros(3), first_off)[2] == pytest.approx(0.1 * 0.01 / 0.2)
    at_once = FeedbackLaw(replace(gains, seek_ramp=0.0), LEVER, 0.01, np.array([-0.03, 0.03]))
    assert at_once.twist(np.zeros(3), first_off)[2] == pytest.approx(0.1)
    with pytest.raises(ConfigError, match="seek_ramp must be a finite number >= 0"):
        FeedbackGains(seek_ramp=-1.0)


def test_slide_reads_where_the_pusher_sits_across_the_push() -> None:
    """offset_y + e_y + e_θ · lever_x: a 2 mm offset, 0.5 mm of sideways error and 0.01 rad
    of heading error with the pusher 30 mm behind the centre put it 2.2 mm across."""
    law = FeedbackLaw(FeedbackGains(), LEVER, dt=0.01)
    error = np.array([1e-3, 0.5e-3, 0.01])
    offset = np.array([0.3e-3, 2e-3, 0.0])
    assert law.slide(error, offset) == pytest.approx(2e-3 + 0.5e-3 - 0.01 * 0.03)


def _object_stays(law: FeedbackLaw, error: np.ndarray, seconds: float) -> np.ndarray:
    """Run ``law`` for ``seconds`` on the reference path while the object does not follow
    the pusher (the error stays ``error``): the offset integrates the output, so the
    prongs slide along the face. Returns the offset (3,) [m, m, rad]."""
    offset = np.zeros(3)
    for _ in range(round(seconds / law.dt)):
        offset += law.dt * law.twist(error, TOUCHING, offset=offset)
    return offset


def test_the_slide_guard_stops_pushing_sideways_the_way_the_prongs_slid() -> None:
    """An object 1 mm to the side that does not follow the plate: the law pushes sideways
    at 1 mm/s until the prongs have slid 0.5 mm from where they landed, then stops pushing
    that way and stops integrating that error. Unguarded it slides on; without the offset
    in the observation the law has no guard."""
    gains = FeedbackGains(k=1.0, k_i=0.5, smoothing=0.0, lateral_ratio=math.inf)
    guarded = FeedbackLaw(replace(gains, slide_limit=0.5e-3, slide_filter=0.0), LEVER, 0.01)
    error = np.array([0.0, -1e-3, 0.0])
    offset = _object_stays(guarded, error, 2.0)
    assert -0.6e-3 < offset[1] < -0.5e-3  # stopped within a step or two of the limit
    integral = guarded.integral.copy()
    assert guarded.twist(error, TOUCHING, offset=offset)[1] == 0.0
    assert guarded.integral[1] == integral[1] and guarded.integral[0] == integral[0]
    free = FeedbackLaw(replace(gains, slide_limit=math.inf), LEVER, 0.01)
    assert _object_stays(free, error, 2.0)[1] < -3e-3  # unguarded, it slides on
    unseen = FeedbackLaw(replace(gains, slide_limit=0.5e-3, slide_filter=0.0), LEVER, 0.01)
    for _ in range(200):  # without the offset in the observation there is no guard
        twist = unseen.twist(error, TOUCHING)
    assert twist[1] < -1e-3


def test_the_slide_guard_reads_the_slide_through_its_lag_from_two_lags_after_landing() -> None:
    """With a 1 s lag the landing spot is taken 2 s after the prongs first both carry load
    (the proxy's camera has σ = 1 mm); until then the law pushes sideways unguarded, and
    it stops once the lagged slide has moved 0.5 mm on from there."""
    gains = FeedbackGains(k=1.0, k_i=0.0, smoothing=0.0, lateral_ratio=math.inf)
    law = FeedbackLaw(replace(gains, slide_limit=0.5e-3, slide_filter=1.0), LEVER, 0.01)
    error = np.array([0.0, 1e-3, 0.0])
    offset = _object_stays(law, error, 1.9)
    assert law.landed is None and offset[1] == pytest.approx(1.9e-3, rel=1e-6)
    offset = _object_stays(law, error, 6.0)
    assert law.landed is not None
    assert law.twist(error, TOUCHING, offset=offset)[1] == 0.0
    assert law.slide_now - law.landed >= 0.5e-3


def test_gains_file_round_trip_and_bad_values(tmp_path: Path) -> None:
    path = tmp_path / "gains.toml"
    path.write_text("[feedback]\nk = 0.7\nk_i = 0.1\ncontact_force = 0.01\n")
    assert load_feedback_gains(path) == FeedbackGains(0.7, 0.1, 0.01, hold_off_contact=True)
    path.write_text("[feedback]\nk = 0.7\nlateral_ratio = inf\n")
    assert load_feedback_gains(path).lateral_ratio == math.inf
    path.write_text("[feedback]\nslide_limit = inf\nslide_filter = 0.5\n")
    assert load_feedback_gains(path).slide_limit == math.inf
    path.write_text("[feedback]\nslide_limit = -1.0\n")
    with pytest.raises(ConfigError, match="slide_limit must be a number >= 0"):
        load_feedback_gains(path)
    path.write_text("[feedback]\nk = -1.0\n")
    with pytest.raises(ConfigError, match="feedback k must be a finite number >= 0"):
        load_feedback_gains(path)
    path.write_text("[feedback]\ngain = 1.0\n")
    with pytest.raises(ConfigError, match="unknown keys"):
        load_feedback_gains(path)
    path.write_text("[pd]\nk = 1.0\n")
    with pytest.raises(ConfigError, match="no \\[feedback\\] table"):
        load_feedback_gains(path)
    with pytest.raises(ConfigError, match="does not exist"):
        load_feedback_gains(tmp_path / "none.toml")


def test_the_tuned_law_cuts_pd_onlys_error_under_placement_and_mounting_error() -> None:
    """A tuning-stream push (sim) whose object sits 1.8 mm across and 0.5° off where the
    plan believes, with a 0.2° plate yaw: PD-only pushes it 1.5 % / 0.31 % off its path; the
    tuned feedback law through the reference path cuts the translation error at least 3×
    and the angle error at least 1.5×. (The fifth search's gains, k_i = 0, cut them 4.5× and
    2.0×; the fourth's, k_i = 0.014 /s², cut both more than 3×.)"""
    import copy

    from pushctl.episode.metrics import compute_metrics
    from pushctl.evaluation.tune_feedback import tuning_env
    from pushctl.rl.policy import finish_with_policy
    from pushctl.task.feedback_actor import FeedbackActor

    env = tuning_env()
    env.reset(options={"object": "cube", "profile": "constant", "scenario_seed": 1})
    unknowns = env.scenario.unknowns
    assert abs(unknowns.placement[1]) > 1e-3 and unknowns.mount_yaw != 0.0
    assert env.episode is not None
    alone = compute_metrics(copy.deepcopy(env.episode).finish())
    finish_with_policy(env, FeedbackActor(env, load_feedback_gains()))
    corrected = compute_metrics(env.episode.trace())
    assert alone.translation_error_pct > 1.0
    assert corrected.translation_error_pct < alone.translation_error_pct / 3
    assert corrected.angle_error_pct < alone.angle_error_pct / 1.5

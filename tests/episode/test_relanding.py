"""Re-landing the prongs on the plan's spot of the object as measured
(pushctl.episode.relanding, Episode.reland)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pushctl.episode.draw import draw_planned_scenario
from pushctl.episode.landed import landed, spot_offset
from pushctl.episode.proxy import ProxyEffects
from pushctl.episode.relanding import landing_shift
from pushctl.episode.runner import Episode
from pushctl.episode.trace import Trace
from pushctl.episode.unknowns import NO_UNKNOWNS, PlantUnknowns
from pushctl.errors import ConfigError, StateError

CONTACT = np.array([0.40, 0.05, 0.02])
YAW = math.radians(20.0)
TANGENT = np.array([-math.sin(YAW), math.cos(YAW), 0.0])
NORMAL = np.array([math.cos(YAW), math.sin(YAW), 0.0])
BELIEVED = np.array([0.45, 0.07, YAW])


def test_no_error_no_shift_and_a_move_across_the_plate_comes_back_whole() -> None:
    assert np.array_equal(landing_shift(BELIEVED, BELIEVED, CONTACT, YAW), np.zeros(3))
    moved = BELIEVED + [*(1.5e-3 * TANGENT[:2]), 0.0]
    np.testing.assert_allclose(landing_shift(BELIEVED, moved, CONTACT, YAW), 1.5e-3 * TANGENT)


def test_a_move_along_the_normal_is_left_to_the_creep() -> None:
    moved = BELIEVED + [*(2e-3 * NORMAL[:2]), 0.0]
    np.testing.assert_allclose(landing_shift(BELIEVED, moved, CONTACT, YAW), 0.0, atol=1e-15)


def test_a_turn_moves_the_spot_by_its_lever_across_the_plate() -> None:
    """The spot is fixed to the object: turning the object by dθ about its centre moves the
    spot by dθ × (its distance along the normal) across the plate, to first order."""
    dtheta = math.radians(1.0)
    lever = float((BELIEVED[:2] - CONTACT[:2]) @ NORMAL[:2])  # centre ahead of the plate
    shift = landing_shift(BELIEVED, BELIEVED + [0.0, 0.0, dtheta], CONTACT, YAW)
    assert float(shift @ TANGENT) == pytest.approx(-dtheta * lever, rel=1e-3)
    assert float(shift @ NORMAL) == pytest.approx(0.0, abs=1e-15)


def test_a_move_past_the_bound_is_shortened_along_its_own_direction() -> None:
    moved = BELIEVED + [*(5e-3 * TANGENT[:2]), 0.0]
    shift = landing_shift(BELIEVED, moved, CONTACT, YAW, bound=2e-3)
    assert np.max(np.abs(shift[:2])) == pytest.approx(2e-3)
    np.testing.assert_allclose(shift / np.linalg.norm(shift), TANGENT, atol=1e-12)


def _episode(unknowns: PlantUnknowns, effects: ProxyEffects | None = None) -> Episode:
    scenario, _, plan = draw_planned_scenario(1, "tuning", "cube", "constant", plant="sim")
    return Episode(scenario.with_unknowns(unknowns), plan=plan, effects=effects)


def _first_second(episode: Episode) -> Trace:
    """The push's first 100 steps (20 s pushes: a 1 s push turns too fast to stick)."""
    for _ in range(100):
        episode.step()
    return episode.trace()


def test_reland_puts_the_prongs_back_on_the_plan_s_spot_and_the_offset_holds_them() -> None:
    """The object 2 mm across from its believed pose: the approach lands the prongs about
    2 mm off the spot; re-landed, they push from within 0.2 mm of it, and the push's
    offset starts at the move (its bound, 3 mm, is not reached)."""
    error = PlantUnknowns(placement=(0.0, 0.002, 0.0))
    approach_only = _episode(error)
    approach_only.reset()
    off = landed(_first_second(approach_only))
    assert 1.5e-3 < abs(off) < 2.5e-3
    relanded = _episode(error)
    relanded.reset()
    relanded.reland()
    offset = relanded.reference_offset
    assert np.linalg.norm(offset[:2]) == pytest.approx(0.002, rel=0.02)
    assert offset[2] == 0.0
    trace = _first_second(relanded)
    assert abs(spot_offset(trace, 0)) < 2e-4
    assert abs(landed(trace)) < 2e-4


def test_reland_without_an_error_changes_no_spot() -> None:
    episode = _episode(NO_UNKNOWNS)
    episode.reset()
    episode.reland()
    np.testing.assert_allclose(episode.reference_offset, 0.0, atol=1e-12)
    assert abs(landed(_first_second(episode))) < 1e-4


def test_reland_only_before_the_push_and_only_on_the_reference_path() -> None:
    episode = _episode(NO_UNKNOWNS)
    with pytest.raises(StateError, match="just reset"):
        episode.reland()
    episode.reset()
    episode.step()
    with pytest.raises(StateError, match="just reset"):
        episode.reland()
    scenario, _, plan = draw_planned_scenario(1, "tuning", "cube", "constant", duration=1.0)
    velocity = Episode(scenario, plan=plan, residual_path="velocity")
    velocity.reset()
    with pytest.raises(ConfigError, match="reference residual path"):
        velocity.reland()


def test_on_the_proxy_the_camera_s_frames_of_the_push_stay_as_they_were() -> None:
    """The re-landing reads its frames from their own generator: the push's camera noise,
    and so PD-only's metrics of the same scenario, do not depend on it; its reading is
    noisy, so the move differs from the exact one, by about σ/√31 (0.18 mm)."""
    error = PlantUnknowns(placement=(0.0, 0.002, 0.0))
    plain, relanded = _episode(error, ProxyEffects()), _episode(error, ProxyEffects())
    plain.reset()
    relanded.reset()
    relanded.reland()
    assert np.array_equal(plain._proxy.camera, relanded._proxy.camera)
    exact = _episode(error)
    exact.reset()
    exact.reland()
    difference = np.linalg.norm(relanded.reference_offset - exact.reference_offset)
    assert 0.0 < difference < 1e-3

"""Where the prongs landed and the force error against the plant's needs there
(pushctl.episode.landed)."""

from __future__ import annotations

import numpy as np
import pytest

from pushctl.episode.draw import draw_planned_scenario
from pushctl.episode.landed import landed, landed_force_error
from pushctl.episode.metrics import compute_metrics
from pushctl.episode.runner import Episode
from pushctl.episode.unknowns import NO_UNKNOWNS, PlantUnknowns


def _episode(unknowns: PlantUnknowns) -> Episode:
    scenario, _, plan = draw_planned_scenario(3, "tuning", "cube", "constant", plant="sim")
    return Episode(scenario.with_unknowns(unknowns), plan=plan)


def test_a_shift_moves_the_prongs_across_the_face_and_none_repeats_plant_forces() -> None:
    """The reference is recomputed with fresh QPs: with no shift it must repeat the episode's
    own plant forces to the bit (ProxQP's answers must not depend on its heap's history),
    and a shift moves every prong by it along the face (the object-frame y)."""
    episode = _episode(PlantUnknowns(placement=(0.0, 0.002, 0.0), ground_variation=0.1))
    again = episode.plant_forces_at(0.0)
    assert np.array_equal(again.forces, episode.plant_forces.forces)
    moved = episode.plant_forces_at(1.5e-3)
    np.testing.assert_allclose(
        moved.prong_points[:, 1], episode.plant_forces.prong_points[:, 1] + 1.5e-3, atol=1e-15
    )
    assert np.array_equal(moved.prong_points[:, 0], episode.plant_forces.prong_points[:, 0])
    assert not np.array_equal(moved.forces, episode.plant_forces.forces)


def test_a_placement_across_the_face_lands_the_prongs_that_far_off_and_the_split_follows() -> None:
    """The object 2 mm across from where the plan believes: the approach aims at the belief,
    so the prongs land about 2 mm the other way on the face and stay there; the plant's
    needs there are far nearer PD-only's forces than the plan spot's (the split of the
    normal forces moves by 2 N s / d)."""
    episode = _episode(PlantUnknowns(placement=(0.0, 0.002, 0.0)))
    trace = episode.run()
    shift, error_landed = landed_force_error(episode, trace)
    assert shift == landed(trace)
    assert -2.3e-3 < shift < -1.7e-3
    error_plan_spot = compute_metrics(trace).force_error
    assert error_landed < 0.2 * error_plan_spot  # measured: 1.4 against 21.9 mN


def test_without_unknowns_the_prongs_land_on_the_plans_spot() -> None:
    episode = _episode(NO_UNKNOWNS)
    trace = episode.run()
    shift, error_landed = landed_force_error(episode, trace)
    assert abs(shift) < 1e-4
    assert error_landed == pytest.approx(compute_metrics(trace).force_error, abs=1e-4)

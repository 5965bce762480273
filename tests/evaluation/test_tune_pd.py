"""The PD gain search: its moves, and that it keeps the best candidate it has seen."""

import math

import pytest

from pushctl.control import PDGains
from pushctl.episode import Scenario
from pushctl.evaluation import tune_pd as search
from pushctl.types import PlanarPose


def test_neighbours_move_each_gain_by_the_factor():
    moves = search.neighbours((300.0, 30.0, 15.0), 2.0)
    assert (600.0, 30.0, 15.0) in moves and (150.0, 30.0, 15.0) in moves
    assert (0.0, 30.0, 15.0) in moves  # K_p may drop to zero
    assert (300.0, 60.0, 15.0) in moves and (300.0, 15.0, 15.0) in moves
    assert (300.0, 30.0, 30.0) in moves and (300.0, 30.0, 7.5) in moves
    assert len(moves) == 7


def test_from_zero_stiffness_the_search_tries_a_small_one():
    moves = search.neighbours((0.0, 30.0, 15.0), 2.0)
    assert (search.KP_FROM_ZERO, 30.0, 15.0) in moves
    assert all(move[0] in (0.0, search.KP_FROM_ZERO) for move in moves)


def test_the_search_returns_the_grid_and_refinement_and_keeps_the_best():
    scenario = Scenario(
        object="cube", profile="constant", goal=PlanarPose(0.55, 0.01, 0.2), duration=1.0
    )
    grid = {"kp": (0.0,), "kv": (30.0,), "kx": (5.0, 50.0)}
    candidates = search.tune_pd([scenario], max_rounds=1, grid=grid)
    points = [(c.gains.kp, c.gains.kv, c.gains.kx_linear) for c in candidates]
    assert points[:2] == [(0.0, 30.0, 5.0), (0.0, 30.0, 50.0)]
    assert len(points) == len(set(points)) > 2  # refinement added new points, none twice
    best = search.best_candidate(candidates)
    assert best.objective == min(c.objective for c in candidates)
    assert all(math.isfinite(c.objective) for c in candidates)
    for c in candidates:  # every candidate inside the bounds
        values = (c.gains.kp, c.gains.kv, c.gains.kx_linear)
        for key, value in zip(("kp", "kv", "kx"), values, strict=True):
            low, high = search.BOUNDS[key]
            assert low <= value <= high


def test_per_case_must_be_positive():
    with pytest.raises(ValueError, match="per_case"):
        search.tuning_scenarios(0, ("cube",), ("constant",), 0)


def test_base_gains_other_than_the_searched_ones_are_kept():
    base = PDGains(ik_damping=0.01, posture_gain=0.5)
    gains = search._gains(1.0, 2.0, 3.0, base)
    assert (gains.ik_damping, gains.posture_gain) == (0.01, 0.5)
    assert (gains.kp, gains.kv, gains.kx_linear, gains.kx_angular) == (1.0, 2.0, 3.0, 3.0)

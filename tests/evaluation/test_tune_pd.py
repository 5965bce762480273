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


def test_pd_sweep_rows_and_summary():
    from pushctl.evaluation.pd_sweep import run_sweep, summary

    gains = PDGains(kp=30.0, kv=300.0, kx_linear=42.0, kx_angular=42.0)
    frame = run_sweep(2, "training", "sim", gains, ("cube",), ("chirp",), duration=1.0)
    assert list(frame["seed"]) == [0, 1]
    assert frame["mu_contact"].between(0.30, 0.50).all()  # the sim ranges
    assert (frame["goal_theta_deg"].abs() >= 10.0).all()
    table = summary(frame)
    assert (
        table.loc[("cube", "chirp"), "translation_error_pct"]
        == frame["translation_error_pct"].mean()
    )
    assert 0.0 <= table.loc[("cube", "chirp"), "episodes_slip_over_1pct"] <= 1.0


def test_pd_sweep_provenance_names_its_arguments_not_its_output():
    """Two sweeps into two places write the same first line (docs/design.md §8)."""
    import argparse

    from pushctl.evaluation.pd_sweep import sweep_command

    args = argparse.Namespace(plant="proxy", seeds=3, stream="tuning", out="elsewhere.csv")
    command = sweep_command(args)
    assert (
        command == "python -m pushctl.evaluation.pd_sweep --plant proxy --seeds 3 --stream tuning"
    )
    assert "elsewhere" not in command


def test_pd_sweep_refuses_an_existing_output_before_it_works(tmp_path, capsys):
    """The sweep writes over a file only with --force, and refuses before any episode runs."""
    from pushctl.evaluation import pd_sweep

    out = tmp_path / "sweep.csv"
    out.write_text("kept\n")
    with pytest.raises(SystemExit) as exit_info:
        pd_sweep.main(["--seeds", "1", "--out", str(out)])
    assert exit_info.value.code == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "--force" in error and str(out) in error
    assert out.read_text() == "kept\n"

"""The world step's cold path in one compiled call (:func:`cold_contact_step`) gives, to the
bit, what the separate calls it replaces gave: assemble, :func:`solve_box_mlcp` with the
previous impulses as warm start, apply the impulses; and its refine-and-re-solve loop in one
compiled call (:func:`cold_slip_step`), and the whole step in one (:func:`slip_step`), give
what the Python loop gave, ProxQP's continuation included."""

from __future__ import annotations

import hashlib
from dataclasses import replace

import numpy as np
import pytest

import pushctl.contact.substep as substep_module
from pushctl.contact.cold_step import HELD, PIVOTED, UNVERIFIED, cold_contact_step
from pushctl.contact.kernels import apply_impulses, assemble
from pushctl.contact.mlcp import DEFAULT_TOL, solve_box_mlcp
from pushctl.contact.world import MAX_SLIP_ITERATIONS
from pushctl.rl.env import PushEnv
from pushctl.rl.env_config import EnvConfig

python_cold_path = substep_module.SubstepSolver._cold_path_in_python


def in_parts(self, inputs, prongs, guess):
    """``SubstepSolver._compiled_step`` declining every step: the step is made in parts."""
    return None


def _recorded_calls(monkeypatch, steps: int = 60) -> list[tuple]:
    """The arguments of every cold_contact_step call of a random-action push on the training
    environment (plant unknowns on, objects slipping), copied when made (the cold path run
    as the Python loop, whose every solve is one such call)."""
    calls: list[tuple] = []
    solve = substep_module.cold_contact_step

    def record(*args):
        calls.append(tuple(a.copy() if isinstance(a, np.ndarray) else a for a in args))
        return solve(*args)

    monkeypatch.setattr(substep_module, "cold_contact_step", record)
    monkeypatch.setattr(substep_module.SubstepSolver, "_compiled_step", in_parts)
    monkeypatch.setattr(substep_module.SubstepSolver, "_cold_path", python_cold_path)
    env = PushEnv(EnvConfig(action_repeat=10, gate_threshold=0.0, duration=6.0))
    rng = np.random.default_rng(0)
    for seed in (0, 2):
        env.reset(seed=seed)
        for _ in range(steps):
            env.step(rng.uniform(-1.0, 1.0, 3).astype(np.float32))
    monkeypatch.setattr(substep_module, "cold_contact_step", solve)
    monkeypatch.undo()
    return calls


def _separate_calls(args: tuple) -> tuple:
    """What World._solve_step did before: the problem assembled, solve_box_mlcp, the
    impulses applied."""
    state, guess, has_guess = args[:18], args[18], args[19]
    D, b, lo, hi, findex, mu, v_arm_free, Minv_At_arm, Minv_At_obj, _ = assemble(*state)
    result = solve_box_mlcp(
        D, b, lo, hi, findex, mu, warm_start=guess if has_guess else None, validate=False
    )
    velocity, h = args[8], args[14]
    v_arm, v_obj, forces = apply_impulses(
        result.p, v_arm_free, Minv_At_arm, velocity, Minv_At_obj, h
    )
    return result, v_arm, v_obj, forces


def test_the_compiled_cold_path_is_the_separate_calls_to_the_bit(monkeypatch) -> None:
    calls = _recorded_calls(monkeypatch)
    seen = {"held": 0, "pivoted": 0, "no guess": 0}
    for args in calls:
        how, p, w, residual, pivots, v_arm, v_obj, forces = cold_contact_step(*args)
        assert how != UNVERIFIED
        result, v_arm_0, v_obj_0, forces_0 = _separate_calls(args)
        for got, expected in ((p, result.p), (w, result.w), (v_arm, v_arm_0),
                              (v_obj, v_obj_0), (forces, forces_0)):  # fmt: skip
            assert got.tobytes() == expected.tobytes()
        assert float(residual) == result.residual and pivots == result.iterations
        assert result.method == ("active-set" if how == PIVOTED else "warm-start")
        seen["held" if how == HELD else "pivoted"] += 1
        seen["no guess"] += not args[19]
    # the warm active set held (after the compiled slip loop's failure, or without it) and
    # failed (the pivoting ran) many times; a new contact set (no guess) at least once
    assert seen["held"] > 20 and seen["pivoted"] > 20 and seen["no guess"] >= 1, seen


def test_nothing_verified_leaves_it_to_the_caller(monkeypatch) -> None:
    """With no pivots allowed the pivoting verifies nothing: UNVERIFIED, and the Python
    fallback (solve_after_pivoting) then solves the problem."""
    from pushctl.contact.mlcp import solve_after_pivoting

    args = next(a for a in _recorded_calls(monkeypatch, steps=20) if a[19])
    budget_zero = (*args[:-1], 0)
    how, *_ = cold_contact_step(*budget_zero)
    if how != UNVERIFIED:
        pytest.skip("this problem verifies from its start without a pivot")
    D, b, lo, hi, findex, mu, *_ = assemble(*args[:18])
    threshold = DEFAULT_TOL * max(1.0, float(np.abs(b).max()))
    result = solve_after_pivoting(D, b, lo, hi, findex, mu, args[18], threshold, 0)
    assert result.converged and result.residual <= threshold


def _slipping_pushes(slip_iterations: int = MAX_SLIP_ITERATIONS) -> tuple[str, object]:
    """Digest of two random-action pushes on the training environment (observations,
    rewards, traces) and the last one's WorldStats; the pushes' worlds with at most
    ``slip_iterations`` re-solves a step (the resets with the default)."""
    env = PushEnv(EnvConfig(action_repeat=10, gate_threshold=0.0, duration=6.0))
    rng = np.random.default_rng(5)
    digest = hashlib.sha256()
    for seed in (0, 2):
        obs, _ = env.reset(seed=seed)
        assert env.episode is not None
        world = env.episode.world
        world.config = replace(world.config, slip_iterations=slip_iterations)  # type: ignore[union-attr]
        digest.update(obs.tobytes())
        for _ in range(40):
            obs, reward, *_ = env.step(rng.uniform(-1.0, 1.0, 3).astype(np.float32))
            digest.update(obs.tobytes())
            digest.update(np.float64(reward).tobytes())
        assert env.episode is not None
        digest.update(env.episode.trace().to_frame().to_numpy().tobytes())
    assert env.episode is not None
    return digest.hexdigest(), env.episode.world.stats


@pytest.mark.parametrize(
    ("pivot_budget", "slip_iterations"),
    [(None, MAX_SLIP_ITERATIONS), (1, MAX_SLIP_ITERATIONS), (None, 2)],
)
def test_the_compiled_step_is_the_python_loop_to_the_bit(
    monkeypatch, pivot_budget, slip_iterations
):
    """The step as one compiled call (slip_step: the warm loop, then the cold loop where a
    warm solve fails) and as its parts (warm_slip_step, then cold_slip_step), each against
    the Python loop they replace. With a budget of one pivot the pivoting often verifies
    nothing, so ProxQP's continuation runs (slip_step then declines the step, which is
    made in parts): from the first solve and from a re-solve inside the loop. With a
    shorter loop (``slip_iterations`` 2) they still agree."""
    if pivot_budget is not None:
        monkeypatch.setattr(substep_module, "_PIVOT_BUDGET", pivot_budget)
    proxqp_step = substep_module.SubstepSolver._proxqp_step
    continued: list[bool] = []
    went_cold: list[bool] = []
    slip_step = substep_module.slip_step

    def counted(self, h, tau, damping, guess, pivots):
        continued.append(True)
        return proxqp_step(self, h, tau, damping, guess, pivots)

    def watched(*args):
        outcome = slip_step(*args)
        went_cold.append(outcome[-1])
        return outcome

    monkeypatch.setattr(substep_module.SubstepSolver, "_proxqp_step", counted)
    monkeypatch.setattr(substep_module, "slip_step", watched)
    compiled, stats = _slipping_pushes(slip_iterations)
    compiled_continuations = len(continued)
    monkeypatch.setattr(substep_module.SubstepSolver, "_compiled_step", in_parts)
    in_parts_digest, in_parts_stats = _slipping_pushes(slip_iterations)
    monkeypatch.setattr(substep_module.SubstepSolver, "_cold_path", python_cold_path)
    python, python_stats = _slipping_pushes(slip_iterations)
    assert compiled == in_parts_digest == python
    assert stats == in_parts_stats == python_stats
    assert stats.slip_iterations > 50 and stats.slip_unsettled > 0  # the loop ran, both ends
    assert sum(went_cold) > 20  # slip_step's cold loop ran
    if pivot_budget is not None:
        assert compiled_continuations > 20  # ProxQP took over many times


def test_a_step_keeping_its_first_solution_needs_no_new_friction_bounds(monkeypatch) -> None:
    """A step that does not settle restores its boxes only (``_restore_slip_boxes``): the
    object has not moved, so the friction field's bounds it would compute again are the
    ones the step began with, and the warm start they scale is scaled by exactly 1. The
    same pushes with the field queried again there give the same bits and counts."""
    solver = substep_module.SubstepSolver
    queries: list[bool] = []
    update = solver._update_friction_bounds

    def counted(self) -> None:
        queries.append(True)
        update(self)

    monkeypatch.setattr(solver, "_update_friction_bounds", counted)
    skipped, stats = _slipping_pushes()
    skipped_queries = len(queries)
    restore = solver._restore_slip_boxes

    def with_new_bounds(self) -> None:  # what _start_slip_state does
        self._update_friction_bounds()
        restore(self)

    monkeypatch.setattr(solver, "_restore_slip_boxes", with_new_bounds)
    queries.clear()
    again, again_stats = _slipping_pushes()
    assert stats.slip_unsettled > 0  # steps that keep their first solution were met
    assert len(queries) > skipped_queries  # and the field was queried again at them
    assert skipped == again and stats == again_stats

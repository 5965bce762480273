"""The compiled world step (one :func:`slip_step` call, ProxQP's continuation where the
pivoting verifies nothing) gives, to the bit, what the Python oracle gives: a loop of
``solve_box_mlcp`` calls with the friction boxes refined between them."""

from __future__ import annotations

import hashlib
from dataclasses import replace

import numpy as np
import pytest
from step_oracle import oracle_solve

import pushctl.contact.mlcp as mlcp_module
import pushctl.contact.step_solver as step_solver_module
from pushctl.contact.step_solver import StepSolver
from pushctl.contact.world_config import MAX_SLIP_ITERATIONS
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig


def slipping_pushes(slip_iterations: int) -> tuple[str, object]:
    """Digest of two random-action pushes on the training environment (plant unknowns on,
    objects slipping; observations, rewards, traces) and the last one's WorldStats."""
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
        digest.update(env.episode.trace().to_frame().to_numpy().tobytes())
    assert env.episode is not None
    return digest.hexdigest(), env.episode.world.stats


@pytest.mark.parametrize(
    ("pivot_budget", "slip_iterations"),
    [
        (None, MAX_SLIP_ITERATIONS),
        (1, MAX_SLIP_ITERATIONS),
        (None, 2),
    ],
)
def test_the_compiled_step_is_the_python_oracle_to_the_bit(
    monkeypatch, pivot_budget, slip_iterations
) -> None:
    """With a budget of one pivot the pivoting often verifies nothing, so ProxQP's
    continuation runs, from a first solve and from re-solves inside the loop; with a
    shorter loop (``slip_iterations`` 2) they still agree.

    The budget is patched where each side reads it, before the runs, rather than set on
    the world after ``reset()``: ``reset()`` builds the world and runs the approach, whose
    contact steps would otherwise pivot with the default budget on one side and with one
    pivot on the other (and end on different signed zeros, then part ways)."""
    if pivot_budget is not None:

        def budget(max_iterations: int = 50) -> int:
            return pivot_budget

        monkeypatch.setattr(step_solver_module, "cold_pivot_budget", budget)  # StepSolver
        monkeypatch.setattr(mlcp_module, "cold_pivot_budget", budget)  # solve_box_mlcp
    proxqp_solve = StepSolver._proxqp_solve
    continued: list[int] = []

    def counted(self, state, guess, pivots):
        continued.append(guess is None or len(guess) == 0)
        return proxqp_solve(self, state, guess, pivots)

    monkeypatch.setattr(StepSolver, "_proxqp_solve", counted)
    compiled, stats = slipping_pushes(slip_iterations)
    monkeypatch.setattr(StepSolver, "solve", oracle_solve)
    python, python_stats = slipping_pushes(slip_iterations)
    assert compiled == python
    assert stats == python_stats
    assert stats.slip_iterations > 50 and stats.slip_unsettled > 0  # the loop ran, both ends
    if pivot_budget is not None:
        assert len(continued) > 20  # ProxQP took over many times

"""The world step's contact solve written as a plain Python loop: the oracle that the
compiled step (:func:`pushctl.contact.compiled.step.slip_step`) is checked against, bit for
bit. Each solve is one :func:`~pushctl.contact.mlcp.solve_box_mlcp` call on the problem
assembled with the current friction boxes; the boxes are refined between solves as the
compiled loop refines them."""

from __future__ import annotations

import numpy as np

from pushctl.contact.compiled.assembly import apply_impulses, assemble, refine_slip, slip_state
from pushctl.contact.mlcp import solve_box_mlcp
from pushctl.contact.step_solver import SLIP_COS_TOLERANCE, SolvedStep, StepSolver


def oracle_solve(solver: StepSolver, state: tuple, prongs: tuple[int, ...]) -> SolvedStep:
    """:meth:`StepSolver.solve` as a Python loop of ``solve_box_mlcp`` calls."""
    model, config = solver.model, solver.config
    pose, velocity = state[7], state[8]
    if solver.friction_field is not None:
        solver._update_friction_bounds(pose)
    guess = solver.last_p if prongs == solver.last_prongs else None
    slip_state(pose, velocity, model.support_points, model.slip_directions, model.sliding)
    solution = first = _solve(solver, state, guess)
    latest_p = solution[0].p
    for attempt in range(config.slip_iterations + 1):
        if not refine_slip(
            pose, solution[2], model.support_points, model.slip_directions, model.sliding,
            SLIP_COS_TOLERANCE, solution[0].p, model.friction_limits, model.h,
            config.stick_fraction,
        ):  # fmt: skip
            break
        if attempt == config.slip_iterations:  # not settled: the first solution, its boxes
            solution = first
            slip_state(pose, velocity, model.support_points, model.slip_directions,
                       model.sliding)  # fmt: skip
            solver.stats.slip_unsettled += 1
            break
        solver.stats.slip_iterations += 1
        solution = _solve(solver, state, solution[0].p)
        latest_p = solution[0].p
    result, v_arm, v_obj, forces = solution
    solver.last_prongs, solver.last_p = prongs, np.ascontiguousarray(latest_p)
    return SolvedStep(
        v_arm, v_obj, pose + model.h * v_obj, forces, result.residual, result.converged,
        result.iterations,
    )  # fmt: skip


def _solve(solver: StepSolver, state: tuple, guess: np.ndarray | None):
    """One solve with the current boxes, counted in the stats: (MLCPResult, v_arm (nv,),
    v_obj (3,), forces (k, 2))."""
    D, b, lo, hi, findex, mu, v_arm_free, Minv_At_arm, Minv_At_obj, _ = assemble(
        *state, *solver.model
    )
    result = solve_box_mlcp(D, b, lo, hi, findex, mu, warm_start=guess, validate=False)
    stats = solver.stats
    stats.solves += 1
    stats.fallbacks += not result.converged
    stats.warm_starts += result.method == "warm-start"
    stats.max_residual = max(stats.max_residual, result.residual)
    v_arm, v_obj, forces = apply_impulses(
        result.p, v_arm_free, Minv_At_arm, state[8], Minv_At_obj, solver.model.h
    )
    return result, v_arm, v_obj, forces

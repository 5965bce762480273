"""The world step's MLCP when the previous active set no longer holds, in one compiled call.

:func:`~pushctl.contact.kernels.warm_contact_step` (assemble, the solve on the previous
impulses' active set, the new velocities) covers most steps. When its active set fails, the
step used to leave the compiled code: assemble the same problem again in Python's call,
hand it to :func:`~pushctl.contact.mlcp.solve_box_mlcp`, which tried the same warm active
set again before its compiled pivoting, and apply the impulses in a third call. On the
training environment with the plant unknowns, whose objects slip on the friction field,
that path ran 1.7 times a push step. :func:`cold_contact_step` is the same calls in the
same order in one compiled call (the same bits: tests/contact/test_cold_step.py); only when
the pivoting finds nothing that verifies does the caller go on in Python with ProxQP
(:func:`~pushctl.contact.mlcp.solve_after_pivoting`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from pushctl.contact.kernels import (
    active_set_step,
    apply_impulses,
    arm_part,
    assemble_on,
    refine_slip,
)
from pushctl.contact.pivot_kernels import cold_pivot

HELD, FROM_WARM, PIVOTED, EMPTY, UNVERIFIED = 0, 1, 2, 3, -1
"""How :func:`cold_contact_step` solved: the warm active set held, or the pivoting from it
verified (both ``solve_box_mlcp``'s method ``warm-start``), the pivoting from another start
(``active-set``), no rows at all (``solve_box_mlcp``'s ``proxqp+active-set`` without a
warm start, ``warm-start`` with one), or nothing verified (the caller continues)."""


@njit(cache=True)
def cold_contact_step(
    contacts, jacobians, M, nle, v_arm, tau, joint_damping, pose, velocity, obj_mass_inv,
    support_points, friction_limits, slip_directions, sliding, h, stabilisation, tie_break,
    mu_contact, guess, has_guess, tol, max_pivots,
):  # fmt: skip
    """:func:`assemble`, then :func:`solve_box_mlcp`'s steps up to and including its compiled
    pivoting (the active set of ``guess`` (n,) if ``has_guess``, then the pivoting from it,
    from all rows free and from p = 0, at most ``max_pivots`` each), then
    :func:`apply_impulses`.

    Returns ``(how, p, w, residual, pivots, v_arm, v_obj, forces)``: ``how`` one of
    :data:`HELD`, :data:`FROM_WARM`, :data:`PIVOTED`, :data:`EMPTY` or
    :data:`UNVERIFIED` (then p is the
    pivoting's best point, not the step's: the caller solves on).
    """
    arm = arm_part(contacts, jacobians, M, nle, v_arm, tau, joint_damping, h)
    return cold_solve(
        arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
        slip_directions, sliding, h, stabilisation, tie_break, mu_contact, guess, has_guess,
        tol, max_pivots,
    )  # fmt: skip


@njit(cache=True)
def cold_solve(
    arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
    slip_directions, sliding, h, stabilisation, tie_break, mu_contact, guess, has_guess, tol,
    max_pivots,
):  # fmt: skip
    """:func:`cold_contact_step` from the step's
    :func:`~pushctl.contact.kernels.arm_part` ``arm``."""
    D, b, lo, hi, findex, mu, v_arm_free, Minv_At_arm, Minv_At_obj, _ = assemble_on(
        arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
        slip_directions, sliding, h, stabilisation, tie_break, mu_contact,
    )  # fmt: skip
    n = b.shape[0]
    if n == 0:
        p = np.zeros(0)
        va, vo, f = apply_impulses(p, v_arm_free, Minv_At_arm, velocity, Minv_At_obj, h)
        return EMPTY, p, np.zeros(0), 0.0, 0, va, vo, f
    threshold = tol * max(1.0, np.max(np.abs(b)))
    if has_guess:
        p, w, residual, verified = active_set_step(D, b, lo, hi, findex, mu, guess, threshold)
        if verified:
            va, vo, f = apply_impulses(p, v_arm_free, Minv_At_arm, velocity, Minv_At_obj, h)
            return HELD, p, w, residual, 0, va, vo, f
    start = guess if has_guess else np.zeros(n)
    p, w, residual, verified, pivots, which = cold_pivot(
        D, b, lo, hi, findex, mu, start, has_guess, threshold, max_pivots
    )
    how = UNVERIFIED
    if verified:
        how = FROM_WARM if which == 0 else PIVOTED
    va, vo, f = apply_impulses(p, v_arm_free, Minv_At_arm, velocity, Minv_At_obj, h)
    return how, p, w, residual, pivots, va, vo, f


COLD_SETTLED, COLD_UNSETTLED, COLD_UNVERIFIED = 1, 2, 3
"""Outcomes of :func:`cold_slip_step`."""


@njit(cache=True)
def _counts_as_warm(how, has_guess):
    """Whether ``SubstepSolver._record`` counts a solve of ``how`` as a warm start (its
    MLCPResult's method is ``warm-start``)."""
    return how == HELD or how == FROM_WARM or (how == EMPTY and has_guess)


@njit(cache=True)
def cold_slip_step(
    contacts, jacobians, M, nle, v_arm, tau, joint_damping, pose, velocity, obj_mass_inv,
    support_points, friction_limits, slip_directions, sliding, h, stabilisation, tie_break,
    mu_contact, guess, has_guess, tol, max_pivots, cos_tolerance, max_iterations, start,
    has_first, first_residual, first_v_arm, first_v_obj, first_forces,
):  # fmt: skip
    """``World._substep``'s cold path in one compiled call: :func:`cold_contact_step` from
    ``guess``, then the refine-and-re-solve loop of the friction boxes from loop index
    ``start``, each re-solve a :func:`cold_contact_step` from the previous impulses: the
    calls of ``SubstepSolver._solve_step`` and ``_settle_slip`` in the same order, so the
    same bits (tests/contact/test_cold_step.py). In a slipping push most steps on this path
    solve seven times; each Python round trip cost about as much as its compiled solve.

    ``has_first``: the step already has the solution it keeps if the loop does not settle
    (the warm path's first solve: ``first_residual`` and the three arrays, its iterations
    0); otherwise the first solve here is that solution.

    Returns ``(status, attempt, solves, warm_starts, worst, iterations, kept, last_p,
    used_guess, pivots)``: ``kept`` = ``(residual, v_arm, v_obj, forces, pivots)`` of the
    solution the step keeps; ``last_p`` the latest verified solve's impulses (the next warm
    start; empty if none); ``solves``, ``warm_starts`` (as ``_record`` counts them),
    ``worst`` (their largest residual) and ``iterations`` (the re-solves) of the verified
    solves. ``status`` ``COLD_SETTLED``: ``kept`` is the latest solve;
    ``COLD_UNSETTLED``: not settled after ``max_iterations``, ``kept`` is the first
    solution (the caller restores its boxes); ``COLD_UNVERIFIED``: the solve at loop index
    ``attempt`` (``start − 1``: the first one) verified nothing; it was made from
    ``used_guess`` after ``pivots`` pivots, and ``kept`` is the first solution if there is
    one: the caller solves it with ProxQP and continues the loop in Python.
    """
    arm = arm_part(contacts, jacobians, M, nle, v_arm, tau, joint_damping, h)
    how, p, w, res, pivots, va, vo, f = cold_solve(
        arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
        slip_directions, sliding, h, stabilisation, tie_break, mu_contact, guess, has_guess,
        tol, max_pivots,
    )  # fmt: skip
    if has_first:
        first = (first_residual, first_v_arm, first_v_obj, first_forces, 0)
    else:
        first = (res, va, vo, f, pivots)
    if how == UNVERIFIED:
        return COLD_UNVERIFIED, start - 1, 0, 0, 0.0, 0, first, p[:0], guess, pivots
    solves, warm, worst, iterations = 1, int(_counts_as_warm(how, has_guess)), res, 0
    solution, last_p = (res, va, vo, f, pivots), p
    for attempt in range(start, max_iterations + 1):
        if not refine_slip(pose, solution[2], support_points, slip_directions, sliding,
                           cos_tolerance):  # fmt: skip
            return COLD_SETTLED, attempt, solves, warm, worst, iterations, solution, last_p, \
                guess, 0  # fmt: skip
        if attempt == max_iterations:
            break
        iterations += 1
        how, p, w, res, pivots, va, vo, f = cold_solve(
            arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
            slip_directions, sliding, h, stabilisation, tie_break, mu_contact, last_p, True,
            tol, max_pivots,
        )  # fmt: skip
        if how == UNVERIFIED:
            return COLD_UNVERIFIED, attempt, solves, warm, worst, iterations, first, last_p, \
                last_p, pivots  # fmt: skip
        solves += 1
        warm += _counts_as_warm(how, True)
        worst = max(worst, res)
        solution, last_p = (res, va, vo, f, pivots), p
    return COLD_UNSETTLED, max_iterations, solves, warm, worst, iterations, first, last_p, \
        guess, 0  # fmt: skip

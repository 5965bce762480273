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
(:func:`~pushctl.contact.mlcp.solve_after_pivoting`). :func:`cold_slip_step` adds the
refine-and-re-solve loop of the friction boxes, and :func:`slip_step` the warm loop before
it: a step whose prongs touched as before is one call, whichever active set holds.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from pushctl.contact.kernels import (
    SLIP_SETTLED,
    SLIP_UNSETTLED,
    SLIP_WARM_FAILED,
    active_set_step,
    apply_impulses,
    arm_part,
    assemble_on,
    refine_slip,
    warm_slip_loop,
    write_solve,
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
    problem = assemble_on(
        arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
        slip_directions, sliding, h, stabilisation, tie_break, mu_contact,
    )  # fmt: skip
    D, b, lo, hi, findex, mu, v_arm_free, Minv_At_arm, Minv_At_obj, _ = problem
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
    return pivoted_solve(problem, velocity, h, guess, has_guess, tol, max_pivots)


@njit(cache=True)
def pivoted_solve(problem, velocity, h, guess, has_guess, tol, max_pivots):
    """The rest of :func:`cold_solve` once the active set of ``guess`` failed (or there is
    none): the compiled pivoting on the :func:`~pushctl.contact.kernels.assemble_on` output
    ``problem`` (n ≥ 1 rows), then :func:`apply_impulses`. Returns as :func:`cold_solve`."""
    D, b, lo, hi, findex, mu, v_arm_free, Minv_At_arm, Minv_At_obj, _ = problem
    threshold = tol * max(1.0, np.max(np.abs(b)))
    start = guess if has_guess else np.zeros(b.shape[0])
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
    mu_contact, guess, has_guess, tol, max_pivots, cos_tolerance, stick_fraction,
    max_iterations, start, has_first, first_residual, first_v_arm, first_v_obj, first_forces,
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
    solve = cold_solve(
        arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
        slip_directions, sliding, h, stabilisation, tie_break, mu_contact, guess, has_guess,
        tol, max_pivots,
    )  # fmt: skip
    if has_first:
        first = (first_residual, first_v_arm, first_v_obj, first_forces, 0)
    else:
        first = (solve[3], solve[5], solve[6], solve[7], solve[4])
    return cold_slip_loop(
        arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
        slip_directions, sliding, h, stabilisation, tie_break, mu_contact, guess, has_guess,
        tol, max_pivots, cos_tolerance, stick_fraction, max_iterations, start, solve, first,
    )  # fmt: skip


@njit(cache=True)
def cold_slip_loop(
    arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
    slip_directions, sliding, h, stabilisation, tie_break, mu_contact, guess, has_guess, tol,
    max_pivots, cos_tolerance, stick_fraction, max_iterations, start, solve, first,
):  # fmt: skip
    """The loop of :func:`cold_slip_step` after its first solve ``solve`` (what
    :func:`cold_solve` returned, from ``guess`` if ``has_guess``), with ``first``
    ``(residual, v_arm, v_obj, forces, pivots)`` the solution the step keeps if the loop
    does not settle. Returns as :func:`cold_slip_step`."""
    how, p, w, res, pivots, va, vo, f = solve
    if how == UNVERIFIED:
        return COLD_UNVERIFIED, start - 1, 0, 0, 0.0, 0, first, p[:0], guess, pivots
    solves, warm, worst, iterations = 1, int(_counts_as_warm(how, has_guess)), res, 0
    solution, last_p = (res, va, vo, f, pivots), p
    for attempt in range(start, max_iterations + 1):
        if not refine_slip(pose, solution[2], support_points, slip_directions, sliding,
                           cos_tolerance, last_p, friction_limits, h,
                           stick_fraction):  # fmt: skip
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


STEP_SETTLED, STEP_UNSETTLED, STEP_UNVERIFIED = 1, 2, 3
"""Outcomes of :func:`slip_step`: the step's solution is the latest solve; not settled, it is
the first (the caller restores its boxes); a solve that the pivoting did not verify was met
(nothing is written: the caller makes the step again, in parts)."""


@njit(cache=True)
def slip_step(
    contacts, jacobians, M, nle, v_arm, tau, joint_damping, pose, velocity, obj_mass_inv,
    support_points, friction_limits, slip_directions, sliding, h, stabilisation, tie_break,
    mu_contact, guess, tol, cos_tolerance, stick_fraction, max_iterations, max_pivots, out_v_arm,
    out_v_obj, out_forces, out_last_p, out_pose,
):  # fmt: skip
    """A whole step from the previous impulses ``guess`` (m,) in one compiled call: the warm
    loop of :func:`~pushctl.contact.kernels.warm_slip_step` and, where one of its warm
    solves fails, :func:`cold_slip_step`'s loop from there: the calls of the two kernels in
    the same order, so the same bits (tests/contact/test_cold_step.py).

    What it saves over the two calls: :func:`cold_slip_step` began by computing again the
    arm's part, the problem and the warm active set's solve that had just failed, and the
    round trip through Python cost about as much. In a push with a random action every step,
    about 60 % of the steps take this path (docs/reproducibility-and-speed.md, tenth pass).

    Writes into the caller's arrays as :func:`~pushctl.contact.kernels.warm_slip_step`
    (``out_pose``: the pose after the step with the kept velocity) and returns ``(status,
    solves, warm_starts, residual, iterations, worst, pivots, cold)``: ``status`` one of
    :data:`STEP_SETTLED`, :data:`STEP_UNSETTLED`, :data:`STEP_UNVERIFIED`; the counts of
    verified solves, warm starts among them (as ``SubstepSolver._record`` counts them) and
    re-solves, the largest residual of the verified solves, ``residual`` and ``pivots`` of
    the kept solve, and whether the cold loop ran.
    """
    outs = (out_v_arm, out_v_obj, out_forces, out_last_p, out_pose)
    status, solves, attempt, iterations, worst, first, last, arm, problem = warm_slip_loop(
        contacts, jacobians, M, nle, v_arm, tau, joint_damping, pose, velocity, obj_mass_inv,
        support_points, friction_limits, slip_directions, sliding, h, stabilisation,
        tie_break, mu_contact, guess, tol, cos_tolerance, stick_fraction, max_iterations,
    )  # fmt: skip
    if status == SLIP_SETTLED:
        residual = write_solve(last, last[0], pose + h * last[4], *outs)
        return STEP_SETTLED, solves, solves, residual, iterations, worst, 0, False
    if status == SLIP_UNSETTLED:
        residual = write_solve(first, last[0], pose + h * first[4], *outs)
        return STEP_UNSETTLED, solves, solves, residual, iterations, worst, 0, False
    # a warm solve failed on `problem`: the cold loop, its first solve pivoting on it
    if status == SLIP_WARM_FAILED:
        failed_guess, start, iterations = last[0], attempt + 1, iterations + 1
    else:
        failed_guess, start = guess, 0
    solve = pivoted_solve(problem, velocity, h, failed_guess, True, tol, max_pivots)
    if status == SLIP_WARM_FAILED:  # the step keeps its first warm solve if not settled
        kept_first = (first[2], first[3], first[4], first[5], 0)
    else:
        kept_first = (solve[3], solve[5], solve[6], solve[7], solve[4])
    cold_status, _, cold_solves, cold_warm, cold_worst, cold_iterations, kept, last_p, _, _ = (
        cold_slip_loop(
            arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
            slip_directions, sliding, h, stabilisation, tie_break, mu_contact, failed_guess,
            True, tol, max_pivots, cos_tolerance, stick_fraction, max_iterations, start, solve,
            kept_first,
        )
    )  # fmt: skip
    if cold_status == COLD_UNVERIFIED:
        return STEP_UNVERIFIED, 0, 0, 0.0, 0, 0.0, 0, True
    residual, v_arm_kept, v_obj_kept, forces_kept, pivots = kept
    out_v_arm[:] = v_arm_kept
    out_v_obj[:] = v_obj_kept
    out_forces[:] = forces_kept
    out_last_p[:] = last_p
    out_pose[:] = pose + h * v_obj_kept
    worst = max(worst, cold_worst)  # 0.0 without a verified warm solve; residuals are >= 0
    status = STEP_SETTLED if cold_status == COLD_SETTLED else STEP_UNSETTLED
    iterations += cold_iterations
    return status, solves + cold_solves, solves + cold_warm, residual, iterations, worst, \
        pivots, True  # fmt: skip

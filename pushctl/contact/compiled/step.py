"""A world (sub)step's MLCP solves and the refinement of its friction boxes, in one compiled
call.

A step is solved with each support point's friction box aligned with its velocity before
the step (:func:`~pushctl.contact.compiled.assembly.slip_state`); where the solved velocity
leaves a box's direction, the box is turned (:func:`~pushctl.contact.compiled.assembly.
refine_slip`) and the step solved again from the previous impulses, until the directions
agree or ``max_iterations`` re-solves are spent (the step then keeps its first solution).

Each solve (:func:`solve_on`) is :func:`~pushctl.contact.mlcp.solve_box_mlcp`'s compiled
part: the active set of the warm start, then block principal pivoting from it and from two
fixed starts. Only a solve that the pivoting does not verify leaves the compiled code:
:func:`slip_step` then returns :data:`NEEDS_PROXQP`, the caller solves that problem with
ProxQP (:func:`~pushctl.contact.mlcp.solve_after_pivoting`) and hands the solution back to
:func:`resume_step`, which goes on with the loop. Every path makes the same arithmetic in
the same order as ``solve_box_mlcp`` called once per solve (the oracle in tests/contact).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from pushctl.contact.compiled.assembly import (
    active_set_step_with,
    apply_impulses,
    arm_part,
    assemble_on,
    refine_slip,
    rows_on,
    slip_state,
)
from pushctl.contact.compiled.object_space import (
    MAX_ITERATIONS,
    row_diagonals,
    solve_object_space,
)
from pushctl.contact.compiled.pivoting import cold_pivot_with

HELD, FROM_WARM, PIVOTED, EMPTY, UNVERIFIED = 0, 1, 2, 3, -1
"""How :func:`solve_on` solved: the warm start's active set held, or the pivoting from it
verified (both ``solve_box_mlcp``'s method ``warm-start``), the pivoting from another start
(``active-set``), no rows at all, or nothing verified."""

SETTLED, UNSETTLED, NEEDS_PROXQP = 1, 2, 3
"""Outcomes of :func:`slip_step` and :func:`resume_step`: the boxes agree with the latest
solve, which the step keeps; not settled after ``max_iterations`` re-solves, the step keeps
its first solve (the caller restores its boxes); a solve the pivoting did not verify."""


@njit(cache=True)
def solve_on(problem, velocity, h, guess, has_guess, tol, max_pivots, reduce):
    """The MLCP of the :func:`~pushctl.contact.compiled.assembly.assemble_on` output
    ``problem`` from ``guess`` (m,) if ``has_guess``: its active set, then at most
    ``max_pivots`` pivots from each of three starts; the impulses applied.

    Returns ``(how, p (m,), residual, pivots, v_arm (nv,), v_obj (3,), forces (k, 2) [N])``
    with ``how`` one of :data:`HELD`, :data:`FROM_WARM`, :data:`PIVOTED`, :data:`EMPTY`,
    :data:`UNVERIFIED` (then p is the pivoting's best point, not a solution). ``reduce``:
    solve each active set with its rows at a fixed bound eliminated first (the fixed
    friction models; the slip box solves in full)."""
    D, b, lo, hi, findex, mu, v_arm_free, Minv_At_arm, Minv_At_obj, _ = problem
    n = b.shape[0]
    if n == 0:
        p = np.zeros(0)
        va, vo, f = apply_impulses(p, v_arm_free, Minv_At_arm, velocity, Minv_At_obj, h)
        return EMPTY, p, 0.0, 0, va, vo, f
    threshold = tol * max(1.0, np.max(np.abs(b)))
    if has_guess:
        p, _, residual, verified = active_set_step_with(
            D, b, lo, hi, findex, mu, guess, threshold, reduce
        )
        if verified:
            va, vo, f = apply_impulses(p, v_arm_free, Minv_At_arm, velocity, Minv_At_obj, h)
            return HELD, p, residual, 0, va, vo, f
    start = guess if has_guess else np.zeros(n)
    p, _, residual, verified, pivots, which = cold_pivot_with(
        D, b, lo, hi, findex, mu, start, has_guess, threshold, max_pivots, reduce
    )
    how = UNVERIFIED
    if verified:
        how = FROM_WARM if which == 0 else PIVOTED
    va, vo, f = apply_impulses(p, v_arm_free, Minv_At_arm, velocity, Minv_At_obj, h)
    return how, p, residual, pivots, va, vo, f


@njit(cache=True)
def counts_as_warm(how, has_guess):
    """Whether a solve of ``how`` is a warm start (``solve_box_mlcp``'s ``warm-start``)."""
    return how == HELD or how == FROM_WARM or (how == EMPTY and has_guess)


@njit(cache=True)
def slip_step(
    contacts, jacobians, M, nle, v_arm, tau, joint_damping, pose, velocity, obj_mass_inv,
    support_points, friction_limits, slip_directions, sliding, h, stabilisation, tie_break,
    mu_contact, guess, has_guess, tol, max_pivots, cos_tolerance, stick_fraction,
    max_iterations, out_v_arm, out_v_obj, out_forces, out_p, out_pose,
):  # fmt: skip
    """A whole (sub)step: the boxes from ``velocity``, the first solve from ``guess`` (m,)
    (the previous step's impulses, if ``has_guess``), then the refine-and-re-solve loop.

    Writes the kept solve's ``out_v_arm`` (nv,), ``out_v_obj`` (3,), ``out_forces`` (k, 2)
    [N], the latest verified impulses ``out_p`` (m,) (the next step's warm start) and the
    pose after the step ``out_pose`` (3,) = ``pose + h v_obj``. Returns ``(status, attempt,
    solves, warm_starts, worst, iterations, residual, pivots, failed_pivots)``: the verified
    solves, the warm starts among them, their largest residual, the re-solves; the kept
    solve's residual and pivots. On :data:`NEEDS_PROXQP` the solve at loop index
    ``attempt`` (−1: the first solve) was made from the impulses in ``out_p`` (from
    ``guess`` for the first) and verified nothing in ``failed_pivots`` pivots; the outputs,
    ``residual`` and ``pivots`` are the first solve's: the caller solves that problem and
    calls :func:`resume_step`.
    """
    slip_state(pose, velocity, support_points, slip_directions, sliding)
    arm = arm_part(contacts, jacobians, M, nle, v_arm, tau, joint_damping, h)
    problem = assemble_on(
        arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
        slip_directions, sliding, h, stabilisation, tie_break, mu_contact,
    )  # fmt: skip
    how, p, residual, pivots, va, vo, f = solve_on(
        problem, velocity, h, guess, has_guess, tol, max_pivots, False
    )
    if how == UNVERIFIED:
        return NEEDS_PROXQP, -1, 0, 0, 0.0, 0, 0.0, 0, pivots
    status, attempt, solves, warm, worst, iterations, kept_residual, kept_pivots, failed = settle(
        arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
        slip_directions, sliding, h, stabilisation, tie_break, mu_contact, tol, max_pivots,
        cos_tolerance, stick_fraction, max_iterations, 0, p, residual, pivots, va, vo, f,
        residual, pivots, va, vo, f, out_v_arm, out_v_obj, out_forces, out_p, out_pose,
    )  # fmt: skip
    warm += counts_as_warm(how, has_guess)
    return status, attempt, solves + 1, warm, max(worst, residual), iterations, kept_residual, \
        kept_pivots, failed  # fmt: skip


@njit(cache=True)
def resume_step(
    contacts, jacobians, M, nle, v_arm, tau, joint_damping, pose, velocity, obj_mass_inv,
    support_points, friction_limits, slip_directions, sliding, h, stabilisation, tie_break,
    mu_contact, tol, max_pivots, cos_tolerance, stick_fraction, max_iterations, start, p,
    residual, pivots, va, vo, f, first_residual, first_pivots, first_va, first_vo, first_f,
    out_v_arm, out_v_obj, out_forces, out_p, out_pose,
):  # fmt: skip
    """:func:`slip_step`'s loop from loop index ``start``, after the caller solved the
    solve that needed ProxQP: its impulses ``p``, ``residual``, ``pivots`` and velocities
    and forces ``va``, ``vo``, ``f``; ``first_*`` the step's first solve. The boxes are as
    that solve was made with. Writes and returns as :func:`slip_step`; its counts are of
    the solves made here (the caller counted its own)."""
    arm = arm_part(contacts, jacobians, M, nle, v_arm, tau, joint_damping, h)
    return settle(
        arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
        slip_directions, sliding, h, stabilisation, tie_break, mu_contact, tol, max_pivots,
        cos_tolerance, stick_fraction, max_iterations, start, p, residual, pivots, va, vo, f,
        first_residual, first_pivots, first_va, first_vo, first_f, out_v_arm, out_v_obj,
        out_forces, out_p, out_pose,
    )  # fmt: skip


@njit(cache=True)
def settle(
    arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
    slip_directions, sliding, h, stabilisation, tie_break, mu_contact, tol, max_pivots,
    cos_tolerance, stick_fraction, max_iterations, start, p, residual, pivots, va, vo, f,
    first_residual, first_pivots, first_va, first_vo, first_f, out_v_arm, out_v_obj,
    out_forces, out_p, out_pose,
):  # fmt: skip
    """The refine-and-re-solve loop from loop index ``start`` with ``p``, ``residual``,
    ``pivots``, ``va``, ``vo``, ``f`` the latest solve and ``first_*`` the first; ``arm``
    the step's :func:`~pushctl.contact.compiled.assembly.arm_part`. Writes and returns as
    :func:`slip_step` (counts of the re-solves made here)."""
    solves, warm, worst, iterations = 0, 0, 0.0, 0
    for attempt in range(start, max_iterations + 1):
        if not refine_slip(pose, vo, support_points, slip_directions, sliding, cos_tolerance,
                           p, friction_limits, h, stick_fraction):  # fmt: skip
            _write(va, vo, f, p, pose, h, out_v_arm, out_v_obj, out_forces, out_p, out_pose)
            return SETTLED, attempt, solves, warm, worst, iterations, residual, pivots, 0
        if attempt == max_iterations:
            break
        iterations += 1
        problem = assemble_on(
            arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
            slip_directions, sliding, h, stabilisation, tie_break, mu_contact,
        )  # fmt: skip
        how, new_p, new_residual, new_pivots, new_va, new_vo, new_f = solve_on(
            problem, velocity, h, p, True, tol, max_pivots, False
        )
        if how == UNVERIFIED:
            _write(first_va, first_vo, first_f, p, pose, h, out_v_arm, out_v_obj, out_forces,
                   out_p, out_pose)  # fmt: skip
            return NEEDS_PROXQP, attempt, solves, warm, worst, iterations, first_residual, \
                first_pivots, new_pivots  # fmt: skip
        solves += 1
        warm += counts_as_warm(how, True)
        worst = max(worst, new_residual)
        p, residual, pivots, va, vo, f = new_p, new_residual, new_pivots, new_va, new_vo, new_f
    _write(first_va, first_vo, first_f, p, pose, h, out_v_arm, out_v_obj, out_forces, out_p,
           out_pose)  # fmt: skip
    return UNSETTLED, max_iterations, solves, warm, worst, iterations, first_residual, \
        first_pivots, 0  # fmt: skip


@njit(cache=True)
def fixed_problem(
    contacts, jacobians, M, nle, v_arm, tau, joint_damping, pose, velocity, obj_mass_inv,
    support_points, friction_limits, slip_directions, sliding, h, stabilisation, tie_break,
    mu_contact, ground_compliance,
):  # fmt: skip
    """:func:`~pushctl.contact.compiled.assembly.assemble`'s MLCP for ground friction fixed
    to the table (the world's ``polygon`` and ``axis_box`` models: ``slip_directions`` the
    rows' table directions, ``sliding`` all False so both rows of a pair carry the bound),
    with the relative diagonal term ``ground_compliance`` on the ground rows."""
    arm = arm_part(contacts, jacobians, M, nle, v_arm, tau, joint_damping, h)
    problem = assemble_on(
        arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
        slip_directions, sliding, h, stabilisation, tie_break, mu_contact,
    )  # fmt: skip
    D = problem[0]
    for i in range(2 * contacts.shape[0], D.shape[0]):
        D[i, i] *= 1.0 + ground_compliance
    return problem


@njit(cache=True)
def fixed_step(
    contacts, jacobians, M, nle, v_arm, tau, joint_damping, pose, velocity, obj_mass_inv,
    support_points, friction_limits, slip_directions, sliding, h, stabilisation, tie_break,
    mu_contact, ground_compliance, guess, has_guess, tol, max_pivots, out_v_arm, out_v_obj,
    out_forces, out_p, out_pose,
):  # fmt: skip
    """A whole (sub)step with ground friction fixed to the table (:func:`fixed_problem`):
    one solve from ``guess`` (m,) if ``has_guess``, nothing to refine. Without an arm it is
    solved in the object's velocity space
    (:func:`~pushctl.contact.compiled.object_space.solve_object_space`), densely
    (:func:`solve_on`) where that does not verify or with an arm. Writes the outputs as
    :func:`slip_step`. Returns ``(status, warm, residual, pivots)``: :data:`SETTLED` or
    :data:`NEEDS_PROXQP` (then ``pivots`` are the failed pivoting's and nothing is
    written), whether the solve was a warm start, its residual and the active sets solved
    after the first (dense: pivots)."""
    if has_guess and M.shape[0] == 0 and support_points.shape[0]:
        arm = arm_part(contacts, jacobians, M, nle, v_arm, tau, joint_damping, h)
        A_obj, b, lo, hi, findex, mu = rows_on(
            arm, contacts, pose, velocity, support_points, friction_limits, slip_directions,
            sliding, h, stabilisation, mu_contact,
        )  # fmt: skip
        n_prong = 2 * contacts.shape[0]
        diag = row_diagonals(A_obj, obj_mass_inv, arm[3], n_prong, tie_break, ground_compliance)
        threshold = tol * max(1.0, np.max(np.abs(b)))
        p, residual, verified, iterations = solve_object_space(
            n_prong, arm[3], A_obj, b, lo, hi, findex, mu, obj_mass_inv, diag, guess,
            threshold, MAX_ITERATIONS,
        )  # fmt: skip
        if verified:
            Minv_At_obj = A_obj.T * obj_mass_inv.reshape(3, 1)
            va, vo, f = apply_impulses(p, arm[1], arm[2], velocity, Minv_At_obj, h)
            _write(va, vo, f, p, pose, h, out_v_arm, out_v_obj, out_forces, out_p, out_pose)
            return SETTLED, int(iterations == 0), residual, iterations
    problem = fixed_problem(
        contacts, jacobians, M, nle, v_arm, tau, joint_damping, pose, velocity, obj_mass_inv,
        support_points, friction_limits, slip_directions, sliding, h, stabilisation,
        tie_break, mu_contact, ground_compliance,
    )  # fmt: skip
    how, p, residual, pivots, va, vo, f = solve_on(
        problem, velocity, h, guess, has_guess, tol, max_pivots, True
    )
    if how == UNVERIFIED:
        return NEEDS_PROXQP, 0, 0.0, pivots
    _write(va, vo, f, p, pose, h, out_v_arm, out_v_obj, out_forces, out_p, out_pose)
    return SETTLED, int(counts_as_warm(how, has_guess)), residual, pivots


@njit(cache=True)
def _write(va, vo, f, p, pose, h, out_v_arm, out_v_obj, out_forces, out_p, out_pose):
    """The kept solve's velocities and forces, the next warm start ``p`` and the pose after
    the step (semi-implicit Euler with the kept ``vo``) into the caller's arrays."""
    out_v_arm[:] = va
    out_v_obj[:] = vo
    out_forces[:] = f
    out_p[:] = p
    out_pose[:] = pose + h * vo

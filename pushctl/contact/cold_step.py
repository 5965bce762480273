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

from pushctl.contact.kernels import active_set_step, apply_impulses, assemble
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
    D, b, lo, hi, findex, mu, v_arm_free, Minv_At_arm, Minv_At_obj, _ = assemble(
        contacts, jacobians, M, nle, v_arm, tau, joint_damping, pose, velocity, obj_mass_inv,
        support_points, friction_limits, slip_directions, sliding, h, stabilisation, tie_break,
        mu_contact,
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

"""The MLCP of one world step, assembled in compiled code, and the friction boxes of the
ground refined against a solved step.

At the sizes of one step (n ≈ 8–16 rows, nv = 7) a step costs the number of Python-level
numpy calls, not the arithmetic, so the step's small dense algebra is done
here in loops (:mod:`~pushctl.contact.compiled.algebra`). :func:`active_set_step` is the
compiled twin of :mod:`pushctl.contact.active_set`'s ``labels_at``/``solve_labels``/
``evaluate`` (the tests compare the two).

The kernels that take a step's state take it as the parameters named by
:data:`~pushctl.contact.step_solver.STEP_STATE` followed by those of
:class:`~pushctl.contact.step_solver.ContactModel` (shapes and units in :func:`assemble`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from pushctl.contact.compiled.algebra import matmul, matvec, plus_diagonal, spd_solve
from pushctl.contact.compiled.pivoting import lu_or_min_norm, solve_reduced

SLIP_SPEED = 1e-6
"""A support point moving slower than this [m/s] counts as sticking: both its friction rows
get the full bound. Faster, friction acts only against the slip (the cross row's bound is 0),
so the box is isotropic in the plane and does not lock the yaw of a sliding object."""


@njit(cache=True)
def active_set_step(D, b, lo, hi, findex, mu, guess, threshold):
    """:func:`active_set_step_with` solving the active set in full."""
    return active_set_step_with(D, b, lo, hi, findex, mu, guess, threshold, False)


@njit(cache=True)
def active_set_step_with(D, b, lo, hi, findex, mu, guess, threshold, reduce):
    """Solve the box-friction MLCP on the active set that ``guess`` (n,) implies, and verify;
    with ``reduce`` the rows at a fixed bound are eliminated first
    (:func:`~pushctl.contact.compiled.pivoting.solve_reduced`).

    Same definitions as :func:`pushctl.contact.active_set.labels_at`, ``solve_labels`` and
    ``evaluate``: a row within 1e-9·max(1, ‖guess‖∞) of a bound is at it (lower first);
    friction rows (``findex ≥ 0``) have bounds ±mu·|p_n| and at a bound are tied to their
    normal row; free rows have w = 0. A singular system is solved in the minimum-norm least
    squares sense. Returns ``(p (n,), w (n,), residual, verified)`` with ``residual`` the
    ∞-norm of the natural map and ``verified = residual ≤ threshold``.
    """
    n = b.shape[0]
    atol = 1e-9 * max(1.0, np.max(np.abs(guess)))
    if reduce:
        p = _reduced_at(D, b, lo, hi, findex, mu, guess, atol)
        return _verified(D, b, lo, hi, findex, mu, p, threshold)
    A = np.zeros((n, n))
    rhs = np.zeros(n)
    for i in range(n):
        f = findex[i]
        width = mu[i] * abs(guess[f]) if f >= 0 else 0.0
        lower = -width if f >= 0 else lo[i]
        upper = width if f >= 0 else hi[i]
        if guess[i] <= lower + atol:
            label = -1
        elif guess[i] >= upper - atol:
            label = 1
        else:
            label = 0
        if label == 0:
            A[i, :] = D[i, :]
            rhs[i] = -b[i]
        elif f >= 0:  # p_t − s·mu·p_n = 0
            A[i, i] = 1.0
            A[i, f] -= label * mu[i]
        else:
            A[i, i] = 1.0
            rhs[i] = lo[i] if label < 0 else hi[i]
    p = lu_or_min_norm(A, rhs)
    return _verified(D, b, lo, hi, findex, mu, p, threshold)


@njit(cache=True)
def _reduced_at(D, b, lo, hi, findex, mu, guess, atol):
    """:func:`active_set_step_with`'s labels of ``guess``, solved by ``solve_reduced``."""
    n = b.shape[0]
    labels = np.zeros(n, dtype=np.int64)
    lo_f, hi_f, mu_f = lo.copy(), hi.copy(), np.zeros(n)
    fi = np.zeros(n, dtype=np.int64)
    for i in range(n):
        f = findex[i]
        width = mu[i] * abs(guess[f]) if f >= 0 else 0.0
        if f >= 0:
            lo_f[i], hi_f[i], mu_f[i], fi[i] = 0.0, 0.0, mu[i], f
        lower = -width if f >= 0 else lo[i]
        upper = width if f >= 0 else hi[i]
        if guess[i] <= lower + atol:
            labels[i] = -1
        elif guess[i] >= upper - atol:
            labels[i] = 1
    return solve_reduced(D, b, lo_f, hi_f, mu_f, fi, labels)


@njit(cache=True)
def _verified(D, b, lo, hi, findex, mu, p, threshold):
    """(p, w = D p + b, the natural map's ∞-norm, whether it is ≤ ``threshold``)."""
    n = b.shape[0]
    w = matvec(D, p) + b
    residual = 0.0
    for i in range(n):
        f = findex[i]
        width = mu[i] * abs(p[f]) if f >= 0 else 0.0
        lower = -width if f >= 0 else lo[i]
        upper = width if f >= 0 else hi[i]
        r = abs(p[i] - min(max(p[i] - w[i], lower), upper))
        if not r <= residual:  # also catches NaN
            residual = r if r == r else np.inf
    return p, w, residual, residual <= threshold


@njit(cache=True)
def _set_row(A_obj, row, ex, ey, rx, ry):
    """Object part of a row along (ex, ey) at offset (rx, ry): (e_x, e_y, r × e)."""
    A_obj[row, 0], A_obj[row, 1], A_obj[row, 2] = ex, ey, rx * ey - ry * ex


@njit(cache=True)
def assemble(
    contacts, jacobians, M, nle, v_arm, tau, joint_damping, pose, velocity, obj_mass_inv,
    support_points, friction_limits, slip_directions, sliding, h, stabilisation, tie_break,
    mu_contact,
):  # fmt: skip
    """The MLCP of one step (impulses p = h λ) and what is needed to apply its solution.

    Inputs: ``contacts`` (p, 5) and ``jacobians`` (p, 3, nv) of the prongs in contact (see
    :func:`prong_contacts`); arm ``M`` (nv, nv) with armature, ``nle`` (nv,) = c + g, ``v_arm``
    (nv,), ``tau`` (nv,), ``joint_damping`` (nv,) [N·m·s/rad] applied implicitly; object
    ``pose`` (3,), ``velocity`` (3,), ``obj_mass_inv`` (3,) = (1/m, 1/m, 1/I_z);
    ``support_points`` (S, 2) object frame, ``friction_limits`` (S,) = μ_g N_j [N],
    ``slip_directions`` (S, 2) and ``sliding`` (S,) bool: each point's friction box (see
    :func:`slip_state`): along the slip direction ±μ_g N_j, across it 0 while sliding (the
    friction is isotropic: only the component against the slip is bounded), ±μ_g N_j while
    sticking.

    Returns ``D (m, m), b (m,), lo, hi, findex, mu, v_arm_free (nv,), Minv_At_arm (nv, 2p),
    Minv_At_obj (3, m), A_arm (2p, nv)`` with ``m = 2p + 2S`` and
    ``(M + h K_d) v_arm_free = M v + h (τ − nle)``. Normal rows get the stabilisation bias
    (a positive gap may close within the step, a fraction ``stabilisation`` of a
    penetration is removed per step) and, with the tangential rows, the relative diagonal
    term ``tie_break``: the prongs' tangential rows are identical, and it makes their split
    of the friction unique (the minimum-norm one) whichever path solves the MLCP.
    """
    arm = arm_part(contacts, jacobians, M, nle, v_arm, tau, joint_damping, h)
    return assemble_on(
        arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
        slip_directions, sliding, h, stabilisation, tie_break, mu_contact,
    )  # fmt: skip


@njit(cache=True)
def arm_part(contacts, jacobians, M, nle, v_arm, tau, joint_damping, h):
    """The arm's part of :func:`assemble`, the same for every solve of one step (refining
    the friction boxes changes only the ground rows): ``(A_arm (2p, nv), v_arm_free (nv,),
    Minv_At_arm (nv, 2p), A_arm Minv_At_arm (2p, 2p), A_arm v_arm_free (2p,))`` (arguments
    as in :func:`assemble`). The step's loops compute it once, not once per solve: it was
    more than half of a solve's assembly.

    With no arm (``M`` (0, 0)) and prongs in contact, ``v_arm`` (2p,) holds the prongs'
    prescribed velocities and the part is :func:`prescribed_part`'s (nv = 2p)."""
    n_contacts, nv = contacts.shape[0], M.shape[0]
    n_prong = 2 * n_contacts
    if nv == 0 and n_contacts and v_arm.shape[0] == n_prong:
        return prescribed_part(contacts, v_arm)
    A_arm = np.zeros((n_prong, nv))
    for i in range(n_contacts):
        nx, ny = contacts[i, 1], contacts[i, 2]
        row = 2 * i
        for j in range(nv):
            A_arm[row, j] = -(nx * jacobians[i, 0, j] + ny * jacobians[i, 1, j])
            A_arm[row + 1, j] = ny * jacobians[i, 0, j] - nx * jacobians[i, 1, j]
    v_arm_free = np.zeros(nv)
    Minv_At_arm = np.zeros((nv, n_prong))
    arm_D, arm_b = np.zeros((n_prong, n_prong)), np.zeros(n_prong)
    if nv:
        M_tilde = plus_diagonal(M, h, joint_damping)
        rhs = np.empty((nv, 1 + n_prong))
        rhs[:, 0] = matvec(M, v_arm) + h * (tau - nle)
        rhs[:, 1:] = A_arm.T
        solution = spd_solve(M_tilde, rhs)
        v_arm_free = solution[:, 0].copy()
        Minv_At_arm = np.ascontiguousarray(solution[:, 1:])
        if n_prong:
            arm_D = matmul(A_arm, Minv_At_arm)
            arm_b = matvec(A_arm, v_arm_free)
    return A_arm, v_arm_free, Minv_At_arm, arm_D, arm_b


@njit(cache=True)
def prescribed_part(contacts, prong_velocity):
    """:func:`arm_part` for prongs whose motion is prescribed (a pusher with no arm): the
    velocities ``prong_velocity`` (2p,) [m/s] of the p prongs in contact, (x, y) per prong,
    world frame, are the pusher's free velocity and no impulse changes them (no inverse
    mass). The rows' pusher part maps them to −(e_n·v_i) and −(e_t·v_i), so the rows measure
    the object's contact point's velocity relative to the prong, as with an arm."""
    n_contacts = contacts.shape[0]
    n_prong = 2 * n_contacts
    A = np.zeros((n_prong, n_prong))
    for i in range(n_contacts):
        nx, ny = contacts[i, 1], contacts[i, 2]
        row = 2 * i
        A[row, row], A[row, row + 1] = -nx, -ny
        A[row + 1, row], A[row + 1, row + 1] = ny, -nx
    v_free = prong_velocity.copy()
    zeros = np.zeros((n_prong, n_prong))
    return A, v_free, zeros, zeros.copy(), matvec(A, v_free)


@njit(cache=True)
def assemble_on(
    arm, contacts, pose, velocity, obj_mass_inv, support_points, friction_limits,
    slip_directions, sliding, h, stabilisation, tie_break, mu_contact,
):  # fmt: skip
    """:func:`assemble` from the step's :func:`arm_part` ``arm`` (the other arguments as
    there): the object's and the ground's rows (:func:`rows_on`), then D with the arm's
    blocks added."""
    A_arm, v_arm_free, Minv_At_arm, arm_D, arm_b = arm
    A_obj, b, lo, hi, findex, mu = rows_on(
        arm, contacts, pose, velocity, support_points, friction_limits, slip_directions,
        sliding, h, stabilisation, mu_contact,
    )  # fmt: skip
    n_prong = 2 * contacts.shape[0]
    Minv_At_obj = A_obj.T * obj_mass_inv.reshape(3, 1)
    D = matmul(A_obj, Minv_At_obj)
    if v_arm_free.shape[0] and n_prong:
        D[:n_prong, :n_prong] += arm_D
    for i in range(n_prong):
        D[i, i] *= 1.0 + tie_break
    return D, b, lo, hi, findex, mu, v_arm_free, Minv_At_arm, Minv_At_obj, A_arm


@njit(cache=True)
def rows_on(
    arm, contacts, pose, velocity, support_points, friction_limits, slip_directions, sliding,
    h, stabilisation, mu_contact,
):  # fmt: skip
    """The rows of :func:`assemble_on` without D: ``(A_obj (m, 3), b (m,), lo, hi, findex,
    mu)``, the object part of each row (prongs' normal and tangential rows, then each support
    point's pair along and across its box direction), its free velocity with the arm's part
    and the stabilisation bias, the bounds and friction indices (arguments as in
    :func:`assemble`)."""
    v_arm_free, arm_b = arm[1], arm[4]
    n_contacts, n_support = contacts.shape[0], support_points.shape[0]
    n_prong = 2 * n_contacts
    m = n_prong + 2 * n_support
    A_obj = np.zeros((m, 3))
    bias = np.zeros(m)
    lo, hi = np.zeros(m), np.zeros(m)
    findex, mu = np.full(m, -1, dtype=np.int64), np.zeros(m)
    for i in range(n_contacts):
        gap, nx, ny, rx, ry = (
            contacts[i, 0],
            contacts[i, 1],
            contacts[i, 2],
            contacts[i, 3],
            contacts[i, 4],
        )
        row = 2 * i
        # Velocity of the object's contact point relative to the prong along e_n, e_t.
        _set_row(A_obj, row, nx, ny, rx, ry)
        _set_row(A_obj, row + 1, -ny, nx, rx, ry)
        bias[row] = gap / h if gap >= 0.0 else stabilisation * gap / h
        hi[row] = np.inf
        findex[row + 1], mu[row + 1] = row, mu_contact
    c, s = math.cos(pose[2]), math.sin(pose[2])
    for j in range(n_support):
        sx, sy = support_points[j, 0], support_points[j, 1]
        rx, ry = c * sx - s * sy, s * sx + c * sy
        dx, dy = slip_directions[j, 0], slip_directions[j, 1]
        row = n_prong + 2 * j
        _set_row(A_obj, row, dx, dy, rx, ry)
        _set_row(A_obj, row + 1, -dy, dx, rx, ry)
        bound = h * friction_limits[j]
        cross = 0.0 if sliding[j] else bound
        lo[row], hi[row], lo[row + 1], hi[row + 1] = -bound, bound, -cross, cross
    b = matvec(A_obj, velocity) + bias
    if v_arm_free.shape[0] and n_prong:
        b[:n_prong] += arm_b
    return A_obj, b, lo, hi, findex, mu


@njit(cache=True)
def _support_velocity(pose, velocity, sx, sy):
    """World velocity (2,) of the object point at (sx, sy) (object frame)."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    rx, ry = c * sx - s * sy, s * sx + c * sy
    return velocity[0] - velocity[2] * ry, velocity[1] + velocity[2] * rx


@njit(cache=True)
def slip_state(pose, velocity, support_points, slip_directions, sliding):
    """Each support point's friction box at the start of a step, from the object's
    ``velocity`` (3,): a point moving faster than ``SLIP_SPEED`` slides along its velocity
    (``slip_directions[j]`` set to it, ``sliding[j]`` True); a slower one sticks and keeps
    its last direction. Updates ``slip_directions`` (S, 2) and ``sliding`` (S,) in place."""
    for j in range(support_points.shape[0]):
        ux, uy = _support_velocity(pose, velocity, support_points[j, 0], support_points[j, 1])
        speed = math.hypot(ux, uy)
        sliding[j] = speed > SLIP_SPEED
        if sliding[j]:
            slip_directions[j, 0], slip_directions[j, 1] = ux / speed, uy / speed


@njit(cache=True)
def refine_slip(
    pose, velocity, support_points, slip_directions, sliding, cos_tolerance, p, friction_limits,
    h, stick_fraction,
):  # fmt: skip
    """Compare a step's result with the sliding boxes it was solved with and turn them
    towards it. Returns True if any box changed (the step should be solved again).

    The stick rule (``stick_fraction`` > 0, ``WorldConfig.stick_fraction``; 0 turns it
    off): a sliding point that moves after the step and whose along-row friction impulse
    in the step's impulses ``p`` (m,) (ground rows last, two per point, along first) came
    out below ``stick_fraction`` of its bound ``h`` · ``friction_limits[j]`` [N·s] is not
    sliding (Coulomb's friction is at its
    bound while a point slides): it gets the rest box. Without the rule the along row held
    such a point and the free cross row let it move across the box at 90°, which turning the
    box did not change.

    A sliding point whose new velocity (from ``velocity`` (3,), the step's result) leaves
    its slip direction by more than acos(``cos_tolerance``) gets the bisector of the two
    directions (averaging, not replacing: the plain update oscillates between two boxes
    when the true direction lies between them); if the two are opposite the point sticks.
    A point that stopped is left alone: its solution already satisfies the sticking box.
    """
    changed = False
    ground = p.shape[0] - 2 * support_points.shape[0]
    for j in range(support_points.shape[0]):
        if not sliding[j]:
            continue
        ux, uy = _support_velocity(pose, velocity, support_points[j, 0], support_points[j, 1])
        speed = math.hypot(ux, uy)
        if speed <= SLIP_SPEED:
            continue
        if abs(p[ground + 2 * j]) < stick_fraction * h * friction_limits[j]:
            sliding[j] = False
            changed = True
            continue
        dx, dy = slip_directions[j, 0], slip_directions[j, 1]
        if (ux * dx + uy * dy) / speed >= cos_tolerance:
            continue
        changed = True
        bx, by = dx + ux / speed, dy + uy / speed
        norm = math.hypot(bx, by)
        if norm < 1e-3:
            sliding[j] = False
        else:
            slip_directions[j, 0], slip_directions[j, 1] = bx / norm, by / norm
    return changed


@njit(cache=True)
def apply_impulses(p, v_arm_free, Minv_At_arm, velocity, Minv_At_obj, h):
    """New velocities and the prongs' forces from the MLCP solution p (m,) [N·s]:
    ``(v_arm (nv,), v_obj (3,), forces (n_contacts, 2) [N])``."""
    n_prong = Minv_At_arm.shape[1]
    p_prong = p[:n_prong].copy()
    v_arm = v_arm_free + matvec(Minv_At_arm, p_prong)
    v_obj = velocity + matvec(Minv_At_obj, p)
    return v_arm, v_obj, p_prong.reshape(-1, 2) / h

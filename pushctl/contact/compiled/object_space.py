"""The MLCP of ground friction fixed to the table, solved in the object's velocity space.

With the ``polygon`` and ``axis_box`` models every ground row i has a relative compliance
c_i = ``ground_compliance`` · (A_i M⁻¹ A_iᵀ) on its diagonal, so its impulse is a function
of the object's velocity change z = M⁻¹ Aᵀ p (3,) alone:

    w_i = A_i z + b_i + c_i p_i,   p_i = clip(−(A_i z + b_i) / c_i, lo_i, hi_i).

For an active set (each ground row free or at a bound, each prong row as in
:mod:`~pushctl.contact.compiled.pivoting`) the MLCP is one linear system in z and the
prongs' impulses, of size 3 + 2k whatever the number of ground rows:

    (M + Σ_free A_iᵀ A_i / c_i) z − A_Pᵀ p_P = Σ_bound A_iᵀ p_i − Σ_free A_iᵀ b_i / c_i,

with the prong rows' own equations (w = 0 where free, p at a bound or tied to its normal
row). For the prongs' labels the ground rows are settled first: each takes the region of
its unclipped impulse at the last point (a semismooth Newton step), damped where the step
would raise the force imbalance; then the prongs' labels move as in the dense pivoting
(a prong off its face has no friction), each joint state of the prongs (off, sticking,
sliding either way) tried at most once. A solve costs O(n) where the dense pivoting's
costs O(n²) plus an LU of its free rows, and D is never formed: with 16 facets a support
point has 8 rows, many of them free.

The solution is the MLCP's (D plus the diagonal terms is positive definite: the same p as
the dense pivoting's to round-off). Where an iteration does not verify within
:data:`MAX_ITERATIONS` solves or meets a singular system, the caller solves the problem
densely.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from pushctl.contact.compiled.algebra import lu_solve
from pushctl.contact.compiled.pivoting import (
    _labels_at,
    _next_labels,
    _visited,
    friction_bounds,
)

MAX_ITERATIONS = 30
"""Active sets solved from the warm start's before the caller's dense solve takes over."""


@njit(cache=True)
def row_diagonals(A_obj, obj_mass_inv, arm_D, n_prong, tie_break, ground_compliance):
    """The diagonal terms (m,) the fixed models add to D: ``tie_break`` times D's own
    diagonal on the prong rows (with the arm's block ``arm_D`` (2k, 2k), if any), and
    ``ground_compliance`` times it on the ground rows."""
    m = A_obj.shape[0]
    diag = np.empty(m)
    for i in range(m):
        k = 0.0
        for c in range(3):
            k += A_obj[i, c] * (A_obj[i, c] * obj_mass_inv[c])
        if i < n_prong:
            if arm_D.shape[0]:
                k += arm_D[i, i]
            diag[i] = tie_break * k
        else:
            diag[i] = ground_compliance * k
    return diag


@njit(cache=True)
def solve_object_space(n_prong, arm_D, A_obj, b, lo, hi, findex, mu, obj_mass_inv, diag,
                       guess, threshold, max_iterations):  # fmt: skip
    """The MLCP with rows ``A_obj`` (m, 3), free velocity ``b`` (m,), bounds and friction
    indices as :func:`~pushctl.contact.compiled.assembly.rows_on` gives them (the first
    ``n_prong`` = 2k rows the prongs', the rest the ground's), the prong block ``arm_D`` (2k, 2k) or
    (0, 0) and the diagonal terms ``diag`` (m,) (:func:`row_diagonals`), from the active
    set of ``guess`` (m,).

    Returns ``(p (m,), residual, verified, iterations)``: the natural-map residual of the
    last active set's p, whether it is at most ``threshold``, and the active sets solved
    after the first."""
    m = b.shape[0]
    lo_f, hi_f, mu_f, fi = friction_bounds(lo, hi, findex, mu)
    labels = _labels_at(lo_f, hi_f, mu_f, fi, guess)
    p, w, r = np.zeros(m), np.zeros(m), np.zeros(m)
    states = 4 ** (n_prong // 2)
    prong_history = np.empty((states + 1, n_prong), dtype=np.int64)
    solves, outer, residual = 0, 0, np.inf
    while solves <= max_iterations:
        prong_history[outer, :] = labels[:n_prong]
        z_last = np.zeros(3)
        for inner in range(max_iterations + 1):  # the ground rows for these prong labels
            z, ok = _solve_labels(arm_D, A_obj, b, lo_f, hi_f, mu_f, fi, obj_mass_inv, diag,
                                  labels, n_prong, p)  # fmt: skip
            solves += 1
            if not ok:
                return p, np.inf, False, solves - 1
            if _ground_agrees(A_obj, b, lo_f, hi_f, diag, n_prong, labels, z) or (
                solves > max_iterations
            ):
                break
            if inner > 0:  # damped: the least force imbalance between the last point and z
                z = _damped(arm_D, A_obj, b, lo_f, hi_f, mu_f, fi, obj_mass_inv, diag, labels,
                            n_prong, z_last, z)  # fmt: skip
            z_last[:] = z
            for i in range(n_prong, m):  # the region of each ground row's unclipped impulse
                q = -(A_obj[i, 0] * z[0] + A_obj[i, 1] * z[1] + A_obj[i, 2] * z[2] + b[i])
                q /= diag[i]
                labels[i] = -1 if q < lo_f[i] else (1 if q > hi_f[i] else 0)
        residual = _impulses(arm_D, A_obj, b, lo_f, hi_f, mu_f, fi, diag, labels, n_prong,
                             z, p, w, r)  # fmt: skip
        if residual <= threshold:
            return p, residual, True, solves - 1
        new = _next_labels(lo_f, hi_f, mu_f, fi, labels, p, w, r, threshold, -1)
        for i in range(1, n_prong, 2):  # a prong off its face has no friction: p_t = 0
            if new[i - 1] != 0:
                new[i] = 1
        outer += 1
        if solves > max_iterations or outer > states:
            break
        if _visited(prong_history, outer, new[:n_prong]):
            if not _unvisited_state(prong_history, outer, new, n_prong, states):
                break
        labels[:n_prong] = new[:n_prong]
    return p, residual, False, solves - 1


@njit(cache=True)
def _unvisited_state(history, count, labels, n_prong, states):
    """The first of the prongs' ``states`` joint states not in ``history[:count]`` into
    ``labels[:n_prong]``: per prong off its face (normal row at 0, no friction), sticking,
    sliding either way; False if every one was tried."""
    for state in range(states):
        code = state
        for k in range(n_prong // 2):
            which = code % 4
            code //= 4
            normal, tangential = (-1, 1) if which == 0 else (0, (0, 1, -1)[which - 1])
            labels[2 * k], labels[2 * k + 1] = normal, tangential
        if not _visited(history, count, labels[:n_prong]):
            return True
    return False


@njit(cache=True)
def _ground_agrees(A_obj, b, lo_f, hi_f, diag, n_prong, labels, z):
    """Whether every ground row's unclipped impulse at z lies in its label's region."""
    for i in range(n_prong, b.shape[0]):
        q = -(A_obj[i, 0] * z[0] + A_obj[i, 1] * z[1] + A_obj[i, 2] * z[2] + b[i]) / diag[i]
        label = -1 if q < lo_f[i] else (1 if q > hi_f[i] else 0)
        if label != labels[i]:
            return False
    return True


@njit(cache=True)
def _damped(arm_D, A_obj, b, lo_f, hi_f, mu_f, fi, obj_mass_inv, diag, labels, n_prong, z0,
            z1):  # fmt: skip
    """The point z0 + α (z1 − z0), α = 1, 1/2, …, 1/64, first to lower the force
    imbalance (:func:`_imbalance`) below z0's; z1 if none does."""
    start = _imbalance(arm_D, A_obj, b, lo_f, hi_f, mu_f, fi, obj_mass_inv, diag, labels,
                       n_prong, z0)  # fmt: skip
    alpha = 1.0
    z = z1.copy()
    for _ in range(7):
        for c in range(3):
            z[c] = z0[c] + alpha * (z1[c] - z0[c])
        if _imbalance(arm_D, A_obj, b, lo_f, hi_f, mu_f, fi, obj_mass_inv, diag, labels,
                      n_prong, z) < start:  # fmt: skip
            return z
        alpha *= 0.5
    return z1.copy()


@njit(cache=True)
def _imbalance(arm_D, A_obj, b, lo_f, hi_f, mu_f, fi, obj_mass_inv, diag, labels, n_prong, z):
    """‖M z − A_Pᵀ p_P(z) − Σ_ground A_iᵀ clip(−(A_i z + b_i)/c_i)‖² in M⁻¹'s norm, with
    p_P(z) the prongs' impulses their labels give at z."""
    force = np.zeros(3)
    for c in range(3):
        force[c] = z[c] / obj_mass_inv[c]
    if n_prong:
        S, rhs = np.zeros((n_prong, n_prong)), np.zeros(n_prong)
        for i in range(n_prong):
            _prong_equation(arm_D, A_obj, b, lo_f, hi_f, mu_f, fi, diag, labels, i, S, rhs, i)
            if labels[i] == 0:
                rhs[i] -= A_obj[i, 0] * z[0] + A_obj[i, 1] * z[1] + A_obj[i, 2] * z[2]
        x, _ = lu_solve(S, rhs)
        for i in range(n_prong):
            for c in range(3):
                force[c] -= A_obj[i, c] * x[i]
    for i in range(n_prong, b.shape[0]):
        v = A_obj[i, 0] * z[0] + A_obj[i, 1] * z[1] + A_obj[i, 2] * z[2] + b[i]
        impulse = min(max(-v / diag[i], lo_f[i]), hi_f[i])
        for c in range(3):
            force[c] -= A_obj[i, c] * impulse
    return (
        force[0] ** 2 * obj_mass_inv[0]
        + force[1] ** 2 * obj_mass_inv[1]
        + force[2] ** 2 * obj_mass_inv[2]
    )


@njit(cache=True)
def _prong_equation(arm_D, A_obj, b, lo_f, hi_f, mu_f, fi, diag, labels, i, S, rhs, row):
    """Prong row i's equation in its impulses, into row ``row`` of ``S`` (its prong
    columns from ``row - i``) and ``rhs``: w_i = 0 less the A_i z part where free, the
    bound where at one, p_t − s·mu·p_n = 0 for a friction row at its bound."""
    first = row - i
    if labels[i] == 0:
        if arm_D.shape[0]:
            for j in range(arm_D.shape[0]):
                S[row, first + j] = arm_D[i, j]
        S[row, row] += diag[i]
        rhs[row] = -b[i]
    elif mu_f[i] > 0.0:
        S[row, row] = 1.0
        S[row, first + fi[i]] -= labels[i] * mu_f[i]
    else:
        S[row, row] = 1.0
        rhs[row] = lo_f[i] if labels[i] < 0 else hi_f[i]


@njit(cache=True)
def _solve_labels(arm_D, A_obj, b, lo_f, hi_f, mu_f, fi, obj_mass_inv, diag, labels, n_prong, p):
    """z (3,) of the active set ``labels`` and the prongs' impulses into ``p[:n_prong]``;
    returns (z, whether the system was regular)."""
    s = 3 + n_prong
    S, rhs = np.zeros((s, s)), np.zeros(s)
    for c in range(3):
        S[c, c] = 1.0 / obj_mass_inv[c]
    for i in range(n_prong, b.shape[0]):
        if labels[i] == 0:
            for r in range(3):
                scaled = A_obj[i, r] / diag[i]
                for c in range(3):
                    S[r, c] += scaled * A_obj[i, c]
                rhs[r] -= scaled * b[i]
        else:
            bound = lo_f[i] if labels[i] < 0 else hi_f[i]
            for r in range(3):
                rhs[r] += A_obj[i, r] * bound
    for i in range(n_prong):
        row = 3 + i
        for r in range(3):
            S[r, row] = -A_obj[i, r]
        _prong_equation(arm_D, A_obj, b, lo_f, hi_f, mu_f, fi, diag, labels, i, S, rhs, row)
        if labels[i] == 0:
            for c in range(3):
                S[row, c] = A_obj[i, c]
    x, ok = lu_solve(S, rhs)
    for i in range(n_prong):
        p[i] = x[3 + i]
    return x[:3].copy(), ok


@njit(cache=True)
def _impulses(arm_D, A_obj, b, lo_f, hi_f, mu_f, fi, diag, labels, n_prong, z, p, w, r):
    """The ground rows' impulses of the active set ``labels`` at z into ``p``, every row's
    w = D p + b into ``w`` and natural-map residual into ``r`` (m,); returns the largest
    (inf if any is NaN)."""
    m = b.shape[0]
    for i in range(m):
        v = A_obj[i, 0] * z[0] + A_obj[i, 1] * z[1] + A_obj[i, 2] * z[2] + b[i]
        if i >= n_prong:
            if labels[i] == 0:
                p[i] = -v / diag[i]
            else:
                p[i] = lo_f[i] if labels[i] < 0 else hi_f[i]
        elif arm_D.shape[0]:
            for j in range(n_prong):
                v += arm_D[i, j] * p[j]
        w[i] = v + diag[i] * p[i]
    residual = 0.0
    for i in range(m):
        width = mu_f[i] * abs(p[fi[i]])
        value = abs(p[i] - min(max(p[i] - w[i], lo_f[i] - width), hi_f[i] + width))
        r[i] = value
        if not value <= residual:
            residual = value if value == value else np.inf
    return residual

"""Compiled pivoting for the box-friction MLCP's cold path (numba).

When the last step's active set no longer holds (a prong starts or stops slipping, a
contact opens), :func:`pivot_solve` searches for the new one by block principal pivoting —
the same labels, linear systems, verification and moves as the plain-numpy reference
:func:`pushctl.contact.active_set.finish` (see that module for the equations), compiled so
that one pivot is one call, not dozens of numpy calls. Its answer is a
deterministic function of its inputs: the last bits do not depend on the process's heap
history, as an iterative solver's (ProxQP's) do. :func:`pushctl.contact.mlcp.solve_box_mlcp`
uses it first and falls back to the ProxQP fixed point only when it does not verify.

The search (Júdice & Pires, 1994): flip every infeasible row at once (block pivot) while the
number of infeasible rows keeps falling, allowing ``_BLOCK_RETRIES`` block pivots that do
not improve it; then single pivots of the least-index infeasible row (Murty), which cannot
cycle on a P-matrix. An active set already visited is never solved again: the next
infeasible row is flipped alone instead.
"""

from __future__ import annotations

import llvmlite.binding
import numpy as np
from numba import njit, types
from numba.extending import get_cython_function_address

from pushctl.contact.compiled.algebra import lu_solve, lu_solve_in_place

RANK_RCOND = 1e-11
"""Relative threshold of the rank decision in the minimum-norm solve of a singular system."""

_BLOCK_RETRIES = 3
"""Block pivots allowed that do not reduce the number of infeasible rows."""

# LAPACK's dgelsy, the routine the numpy reference calls (through scipy), called from compiled
# code by symbol name (so that numba can cache the callers on disk): the minimum-norm solve
# then gives the reference's bits, at a third of the cost of numba's np.linalg.lstsq.
llvmlite.binding.add_symbol(
    "pushctl_dgelsy", get_cython_function_address("scipy.linalg.cython_lapack", "dgelsy")
)
_INT = types.CPointer(types.int32)
_FLOAT = types.CPointer(types.float64)
_dgelsy = types.ExternalFunction(
    "pushctl_dgelsy",
    types.void(
        _INT, _INT, _INT, _FLOAT, _INT, _FLOAT, _INT, _INT, _FLOAT, _INT, _FLOAT, _INT, _INT
    ),  # noqa: E501
)


@njit(cache=True)
def _min_norm(A: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Minimum-norm least-squares x (n,) of A x = rhs, A (n, n) singular: LAPACK dgelsy
    with the workspace and rank threshold of :func:`pushctl.contact.active_set._min_norm_solve`."""
    n = A.shape[0]
    a = A.T.copy()  # column-major, as Fortran reads it
    x = rhs.copy()
    size = np.array([n], dtype=np.int32)
    one = np.array([1], dtype=np.int32)
    lwork = np.array([3 * n + 64 * (n + 1)], dtype=np.int32)
    rank, info = np.zeros(1, dtype=np.int32), np.zeros(1, dtype=np.int32)
    jpvt = np.zeros(n, dtype=np.int32)
    rcond = np.array([RANK_RCOND])
    work = np.empty(lwork[0])
    _dgelsy(
        size.ctypes, size.ctypes, one.ctypes, a.ctypes, size.ctypes, x.ctypes, size.ctypes,
        jpvt.ctypes, rcond.ctypes, rank.ctypes, work.ctypes, lwork.ctypes, info.ctypes,
    )  # type: ignore[call-overload]  # fmt: skip  # numba's typed signature
    return x


@njit(cache=True)
def lu_or_min_norm(A: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """x (n,) with A x = rhs for an active set's system: LU with partial pivoting
    (:func:`lu_solve`), or the minimum-norm least-squares solution where it finds the
    system singular (as :func:`pushctl.contact.active_set.solve_labels`)."""
    x, ok = lu_solve(A, rhs)
    return x if ok else _min_norm(A, rhs)


@njit(cache=True)
def _solve_labels(D, b, lo, hi, mu, fi, labels, work):
    """p (n,) of the active set ``labels`` (n,): as :func:`~pushctl.contact.active_set.
    solve_labels` (``lo``/``hi`` 0 and ``mu`` > 0 on friction rows, ``mu`` 0 elsewhere).
    The system is built and factorised in ``work`` (n, n), the caller's, overwritten: one
    array for all of a pivoting's solves, where each solve made four (the system, its
    right-hand side and the LU's copies of both). A singular system is built again for the
    minimum-norm solve, which needs it unfactorised."""
    n = b.shape[0]
    p = np.empty(n)
    _labels_system(D, b, lo, hi, mu, fi, labels, work, p)
    if lu_solve_in_place(work, p):
        return p
    A, rhs = np.empty((n, n)), np.empty(n)
    _labels_system(D, b, lo, hi, mu, fi, labels, A, rhs)
    return _min_norm(A, rhs)


@njit(cache=True)
def _labels_system(D, b, lo, hi, mu, fi, labels, A, rhs):
    """The linear system of the active set ``labels`` (:func:`_solve_labels`), written into
    ``A`` (n, n) and ``rhs`` (n,), every entry."""
    n = b.shape[0]
    for i in range(n):
        label = labels[i]
        if label == 0:
            A[i, :] = D[i, :]
            rhs[i] = -b[i]
        else:
            A[i, :] = 0.0
            A[i, i] = 1.0
            A[i, fi[i]] -= label * mu[i]  # friction rows: p_t − s·mu·p_n = 0
            rhs[i] = lo[i] if label < 0 else hi[i]


@njit(cache=True)
def _evaluate(D, b, lo, hi, mu, fi, p, threshold, w, r):
    """w = D p + b and the natural map's |r| per row, into ``w``, ``r`` (n,); returns
    (residual = max r, inf if any is NaN, number of rows with r > threshold)."""
    n = b.shape[0]
    residual, bad = 0.0, 0
    for i in range(n):
        total = b[i]
        for j in range(n):
            total += D[i, j] * p[j]
        w[i] = total
    for i in range(n):
        width = mu[i] * abs(p[fi[i]])
        value = abs(p[i] - min(max(p[i] - w[i], lo[i] - width), hi[i] + width))
        r[i] = value
        if not value <= residual:
            residual = value if value == value else np.inf
        if not value <= threshold:
            bad += 1
    return residual, bad


@njit(cache=True)
def _next_labels(lo, hi, mu, fi, labels, p, w, r, threshold, only):
    """The labels after a pivot from ``labels`` (n,) at the candidate (p, w, r): every
    infeasible row moved to its target (``only`` < 0: a block pivot) or only row ``only``.
    Targets and the re-signing of zero-width friction rows as in
    :func:`pushctl.contact.active_set._moves`."""
    n = labels.shape[0]
    new = labels.copy()
    for i in range(n):  # _resign_friction
        if mu[i] > 0.0 and labels[i] * w[i] > threshold and r[i] <= threshold:
            new[i] = -labels[i]
    for i in range(n):
        if not r[i] > threshold or (only >= 0 and i != only):
            continue
        if labels[i] != 0:
            new[i] = 0
            continue
        width = mu[i] * abs(p[fi[i]])
        lower, upper = lo[i] - width, hi[i] + width
        target = -1 if (p[i] < lower or (p[i] <= upper and w[i] > 0.0)) else 1
        if target < 0 and lower == -np.inf:
            target = 1
        if target > 0 and upper == np.inf:
            target = 0
        new[i] = target
    return new


@njit(cache=True)
def _visited(history, count, labels) -> bool:
    for k in range(count):
        same = True
        for i in range(labels.shape[0]):
            if history[k, i] != labels[i]:
                same = False
                break
        if same:
            return True
    return False


@njit(cache=True)
def solve_reduced(D, b, lo, hi, mu, fi, labels):
    """p (n,) of the active set ``labels`` (n,) (arrays as :func:`_solve_labels`) with the
    rows at a fixed bound eliminated first: their impulses are their bounds, and only the
    free rows and the friction rows at a bound (tied to their normal row) are solved, an
    LU of that size (the minimum-norm solve where it is singular). The same solution as
    :func:`_solve_labels` to round-off, at a fraction of its cost when most rows sit at a
    bound (sliding support points of the fixed friction models)."""
    n = b.shape[0]
    p = np.zeros(n)
    index = np.full(n, -1, dtype=np.int64)
    m = 0
    for i in range(n):
        if labels[i] != 0 and mu[i] == 0.0:
            p[i] = lo[i] if labels[i] < 0 else hi[i]
        else:
            index[i] = m
            m += 1
    A, rhs = np.zeros((m, m)), np.zeros(m)
    for i in range(n):
        k = index[i]
        if k < 0:
            continue
        if labels[i] == 0:
            total = -b[i]
            for j in range(n):
                if index[j] >= 0:
                    A[k, index[j]] = D[i, j]
                else:
                    total -= D[i, j] * p[j]
            rhs[k] = total
        else:  # a friction row at a bound: p_t − s·mu·p_n = 0
            A[k, k] = 1.0
            f = fi[i]
            if index[f] >= 0:
                A[k, index[f]] -= labels[i] * mu[i]
            else:
                rhs[k] = labels[i] * mu[i] * p[f]
    if m:
        x = lu_or_min_norm(A, rhs)
        for i in range(n):
            if index[i] >= 0:
                p[i] = x[index[i]]
    return p


@njit(cache=True)
def pivot_solve(D, b, lo, hi, mu, fi, labels, threshold, max_pivots):
    """:func:`pivot_solve_with` solving each active set in full."""
    return pivot_solve_with(D, b, lo, hi, mu, fi, labels, threshold, max_pivots, False)


@njit(cache=True)
def pivot_solve_with(D, b, lo, hi, mu, fi, labels, threshold, max_pivots, reduce):
    """Pivot from the active set ``labels`` (n,) until the natural-map residual is at most
    ``threshold``, or ``max_pivots`` linear solves after the first; each active set solved
    in full (:func:`_solve_labels`) or, with ``reduce``, by :func:`solve_reduced`.

    Arrays as in :class:`pushctl.contact.active_set.BoxProblem`: D (n, n), b (n,), ``lo``,
    ``hi`` (n,) with 0 on friction rows, ``mu`` (n,) 0 on non-friction rows, ``fi`` (n,) the
    normal row of each friction row (any index elsewhere). Returns ``(p (n,), w (n,),
    residual, verified, pivots)`` of the lowest-residual active set met.
    """
    n = b.shape[0]
    history = np.empty((max_pivots + 1, n), dtype=labels.dtype)  # rows read once written
    w, r = np.zeros(n), np.zeros(n)
    work = np.empty((0, 0)) if reduce else np.empty((n, n))
    if reduce:
        p = solve_reduced(D, b, lo, hi, mu, fi, labels)
    else:
        p = _solve_labels(D, b, lo, hi, mu, fi, labels, work)
    residual, bad = _evaluate(D, b, lo, hi, mu, fi, p, threshold, w, r)
    best_p, best_w, best_residual = p, w.copy(), residual
    history[0, :] = labels
    fewest, retries, pivots = bad, _BLOCK_RETRIES, 0
    while residual > threshold and pivots < max_pivots and residual < np.inf:
        block = retries > 0
        trial = _next_labels(lo, hi, mu, fi, labels, p, w, r, threshold, -1)
        if not block or _visited(history, pivots + 1, trial):
            # Murty: the least-index infeasible row alone; the next one if that was visited.
            found = False
            for i in range(n):
                if r[i] > threshold:
                    trial = _next_labels(lo, hi, mu, fi, labels, p, w, r, threshold, i)
                    if not _visited(history, pivots + 1, trial):
                        found = True
                        break
            if not found:
                break
        pivots += 1
        history[pivots, :] = trial
        labels = trial
        if reduce:
            p = solve_reduced(D, b, lo, hi, mu, fi, labels)
        else:
            p = _solve_labels(D, b, lo, hi, mu, fi, labels, work)
        residual, bad = _evaluate(D, b, lo, hi, mu, fi, p, threshold, w, r)
        if residual < best_residual:
            best_p, best_w, best_residual = p, w.copy(), residual
        if bad < fewest:
            fewest, retries = bad, _BLOCK_RETRIES
        elif block:
            retries -= 1
    return best_p, best_w, best_residual, best_residual <= threshold, pivots


@njit(cache=True)
def _labels_at(lo, hi, mu, fi, p):
    """As :func:`pushctl.contact.active_set.labels_at` with the friction widths at p."""
    n = p.shape[0]
    atol = 1e-9 * max(1.0, np.max(np.abs(p))) if n else 0.0
    labels = np.zeros(n, dtype=np.int64)
    for i in range(n):
        c = mu[i] * abs(p[fi[i]]) - atol
        if p[i] <= lo[i] - c:
            labels[i] = -1
        elif p[i] >= hi[i] + c:
            labels[i] = 1
    return labels


@njit(cache=True)
def friction_bounds(lo, hi, findex, mu):
    """The box of a cold solve in the pivoting's form, from the MLCP's ``lo``, ``hi`` (m,),
    ``findex`` (m,) (the normal row of each friction row, −1 for none) and ``mu`` (m,):
    ``(lo, hi, mu, fi)``, a friction row's fixed bounds 0 and its ``mu`` and normal index
    kept (its bounds follow ±mu·p_normal), every other row's bounds as given, mu 0."""
    m = lo.shape[0]
    lo_f, hi_f, mu_f = lo.copy(), hi.copy(), np.zeros(m)
    fi = np.zeros(m, dtype=np.int64)
    for i in range(m):
        if findex[i] >= 0:
            lo_f[i], hi_f[i], mu_f[i], fi[i] = 0.0, 0.0, mu[i], findex[i]
    return lo_f, hi_f, mu_f, fi


@njit(cache=True)
def cold_pivot(D, b, lo, hi, findex, mu, start, has_start, threshold, max_pivots):
    """:func:`cold_pivot_with` solving each active set in full."""
    return cold_pivot_with(D, b, lo, hi, findex, mu, start, has_start, threshold, max_pivots, False)


@njit(cache=True)
def cold_pivot_with(D, b, lo, hi, findex, mu, start, has_start, threshold, max_pivots, reduce):
    """The compiled cold path: :func:`pivot_solve_with` (``reduce`` passed on) from the
    active set of ``start`` (n,) if ``has_start``, then from every row free, then from
    that of p = 0, until one verifies.

    Takes the arrays of :func:`pushctl.contact.mlcp.solve_box_mlcp` as they are (friction
    rows ``findex ≥ 0``, their own lo/hi ignored). Returns ``(p, w, residual, verified,
    pivots, which)``: ``which`` is the index of the start that verified (0: ``start``, 1:
    all free, 2: p = 0), or −1 with
    the lowest-residual point met when none did; ``pivots`` counts all linear solves after
    each start's first.
    """
    n = b.shape[0]
    lo_f, hi_f, mu_f, fi = friction_bounds(lo, hi, findex, mu)
    total = 0
    best_p, best_w, best_residual = np.zeros(n), np.zeros(n), np.inf
    for which in range(0 if has_start else 1, 3):
        # each start's labels made when it is tried: most calls verify from the first
        if which == 0:
            labels = _labels_at(lo_f, hi_f, mu_f, fi, start)
        elif which == 1:
            labels = np.zeros(n, dtype=np.int64)
        else:
            labels = _labels_at(lo_f, hi_f, mu_f, fi, np.zeros(n))
        p, w, residual, verified, pivots = pivot_solve_with(
            D, b, lo_f, hi_f, mu_f, fi, labels, threshold, max_pivots, reduce
        )
        total += pivots
        if verified:
            return p, w, residual, True, total, which
        if residual < best_residual:
            best_p, best_w, best_residual = p, w, residual
    return best_p, best_w, best_residual, False, total, -1

"""Compiled kernels of the per-step hot path (numba).

At the sizes of one simulation step (n ≈ 8–16 rows, nv = 7) the cost of the step is the
number of Python-level numpy calls, about 1 µs each, not the arithmetic. These kernels do a
step's small dense algebra in one compiled call each. They implement nothing the rest of
the package does not also do in plain numpy (:mod:`pushctl.contact.active_set` holds the
reference implementation of the active-set solve; the tests compare the two), and they are
compiled once and cached on disk (``cache=True``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

SINGULAR_PIVOT = 1e-11
"""An LU pivot below this fraction of the largest one marks a system singular."""


@njit(cache=True)
def _lu_solve(A: np.ndarray, rhs: np.ndarray):
    """Solve A x = rhs (A (n, n), rhs (n,)) by LU with partial pivoting, in place on copies.

    Returns ``(x, ok)``; ``ok`` is False when a pivot falls below ``SINGULAR_PIVOT`` times the
    largest one, and the caller then needs a minimum-norm solve.
    """
    n = A.shape[0]
    M = A.copy()
    x = rhs.copy()
    largest = 0.0
    smallest = np.inf
    for k in range(n):
        pivot_row = k
        pivot = abs(M[k, k])
        for i in range(k + 1, n):
            if abs(M[i, k]) > pivot:
                pivot, pivot_row = abs(M[i, k]), i
        if pivot_row != k:
            for j in range(n):
                M[k, j], M[pivot_row, j] = M[pivot_row, j], M[k, j]
            x[k], x[pivot_row] = x[pivot_row], x[k]
        largest = max(largest, pivot)
        smallest = min(smallest, pivot)
        if pivot == 0.0:
            return x, False
        for i in range(k + 1, n):
            factor = M[i, k] / M[k, k]
            if factor != 0.0:
                for j in range(k + 1, n):
                    M[i, j] -= factor * M[k, j]
                x[i] -= factor * x[k]
    for k in range(n - 1, -1, -1):
        total = x[k]
        for j in range(k + 1, n):
            total -= M[k, j] * x[j]
        x[k] = total / M[k, k]
    return x, smallest > SINGULAR_PIVOT * largest


@njit(cache=True)
def active_set_step(D, b, lo, hi, findex, mu, guess, threshold):
    """Solve the box-friction MLCP on the active set that ``guess`` (n,) implies, and verify.

    Same definitions as :func:`pushctl.contact.active_set.labels_at`, ``solve_labels`` and
    ``evaluate``: a row within 1e-9·max(1, ‖guess‖∞) of a bound is at it (lower first);
    friction rows (``findex ≥ 0``) have bounds ±mu·|p_n| and at a bound are tied to their
    normal row; free rows have w = 0. A singular system is solved in the minimum-norm least
    squares sense. Returns ``(p (n,), w (n,), residual, verified)`` with ``residual`` the
    ∞-norm of the natural map and ``verified = residual ≤ threshold``.
    """
    n = b.shape[0]
    atol = 1e-9 * max(1.0, np.max(np.abs(guess)))
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
    p, ok = _lu_solve(A, rhs)
    if not ok:
        p = np.linalg.lstsq(A, rhs, rcond=1e-11)[0]
    w = D @ p + b
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

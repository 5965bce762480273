"""Small dense algebra by loops, compiled (numba): what the step's kernels need at their
sizes (n ≈ 8–16 rows, nv = 7).

Not numba's BLAS and LAPACK calls (``@``, ``np.linalg.solve``): at these sizes a library
call costs more than its arithmetic (OpenBLAS and LAPACK took about a fifth of a world
step's time, perf-sampled), and OpenBLAS picks its
kernels by CPU, so its sums rounded differently from one machine to another
(:mod:`pushctl.machine`). A loop's sum has one order everywhere.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

SINGULAR_PIVOT = 1e-11
"""An LU pivot below this fraction of the largest one marks a system singular
(:func:`lu_solve`): the active-set solves then take the minimum-norm solution."""


@njit(cache=True)
def matvec(A, x):
    """A (n, k) @ x (k,), summed in column order."""
    n, k = A.shape
    out = np.empty(n)
    for i in range(n):
        total = 0.0
        for j in range(k):
            total += A[i, j] * x[j]
        out[i] = total
    return out


@njit(cache=True)
def matmul(A, B):
    """A (n, k) @ B (k, m), each entry summed in the order of k."""
    n, k = A.shape
    m = B.shape[1]
    out = np.zeros((n, m))
    for i in range(n):
        for t in range(k):
            a = A[i, t]
            for j in range(m):
                out[i, j] += a * B[t, j]
    return out


@njit(cache=True)
def plus_diagonal(M, h, d):
    """M + h diag(d) (n, n), a new array: the arm's mass matrix with its implicit joint
    damping ``d`` (n,) over a step ``h``, the matrix :func:`spd_solve` then solves with."""
    A = M.copy()
    for i in range(d.size):
        A[i, i] += h * d[i]
    return A


@njit(cache=True)
def spd_solve(A, B):
    """X (n, m) with A X = B for A (n, n) symmetric positive definite (the arm's mass matrix
    with implicit damping): Cholesky, then two triangular solves per column of B."""
    n = A.shape[0]
    L = np.zeros((n, n))
    for j in range(n):
        d = A[j, j]
        for k in range(j):
            d -= L[j, k] * L[j, k]
        d = math.sqrt(d)
        L[j, j] = d
        for i in range(j + 1, n):
            t = A[i, j]
            for k in range(j):
                t -= L[i, k] * L[j, k]
            L[i, j] = t / d
    X = B.copy()
    m = B.shape[1]
    for c in range(m):
        for i in range(n):
            t = X[i, c]
            for k in range(i):
                t -= L[i, k] * X[k, c]
            X[i, c] = t / L[i, i]
        for i in range(n - 1, -1, -1):
            t = X[i, c]
            for k in range(i + 1, n):
                t -= L[k, i] * X[k, c]
            X[i, c] = t / L[i, i]
    return X


@njit(cache=True)
def lu_solve(A: np.ndarray, rhs: np.ndarray):
    """Solve A x = rhs (A (n, n), rhs (n,)) by LU with partial pivoting, in place on copies
    (:func:`lu_solve_in_place`).

    Returns ``(x, ok)``; ``ok`` is False when a pivot falls below ``SINGULAR_PIVOT`` times the
    largest one, and the caller then needs a minimum-norm solve.
    """
    x = rhs.copy()
    return x, lu_solve_in_place(A.copy(), x)


@njit(cache=True)
def lu_solve_in_place(M: np.ndarray, x: np.ndarray) -> bool:
    """:func:`lu_solve` overwriting ``M`` (n, n) with its factors and ``x`` (n,), the
    right-hand side, with the solution; returns ``ok``. For a caller that builds the system
    in an array of its own (the cold path's pivoting: one LU per pivot, without copies)."""
    n = M.shape[0]
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
            return False
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
    return smallest > SINGULAR_PIVOT * largest

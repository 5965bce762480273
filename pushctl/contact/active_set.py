"""Exact active-set finish for the box-friction MLCP (helper of :mod:`pushctl.contact.mlcp`).

An *active set* labels every row ``-1`` (at its lower bound), ``0`` (free) or ``+1`` (at its
upper bound). For a friction row the bound is ``∓mu_i·p_n`` with ``n = findex[i]``, so a
friction row at a bound is tied linearly to its normal row. Given the labels, the MLCP is a
square linear system in all ``n`` impulses:

- free row ``i``:               ``(D p + b)_i = 0``                 (``w_i = 0``)
- fixed-bound row at a bound:   ``p_i = lo_i`` or ``p_i = hi_i``
- friction row at a bound:      ``p_i − s_i·mu_i·p_n = 0``          (``s_i = ±1``)

It is non-symmetric once friction rows are tied, and singular whenever the free rows of ``D``
are (identical tangential rows of two prongs, 8 ground rows on 3 object DOF). A non-singular
system is solved by LU; a singular one by the minimum-norm least-squares solution (complete
orthogonal factorisation), which breaks the tie reproducibly — the same labels always give
the same p, and identical rows get equal shares. (A diagonal regulariser with iterative
refinement was tried first: refinement amplifies the rounding error along the null space, and
identical rows came out unequal by up to 1e-3 relative.)

:func:`finish` solves the system, verifies complementarity through the natural-map residual,
and pivots when the verification fails: block principal pivoting (Júdice & Pires, 1994) —
flip every infeasible row at once — backed up by single least-index pivots (Murty) in a
best-first search that never revisits an active set, so it cannot cycle.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from scipy.linalg.lapack import dgelsy, dgetrf, dgetrs

from pushctl.contact.compiled.algebra import SINGULAR_PIVOT
from pushctl.contact.compiled.pivoting import RANK_RCOND


@dataclass(slots=True)
class BoxProblem:
    """A validated MLCP in the form the solvers use. All vectors are ``(n,)``.

    ``lo``/``hi`` hold the fixed bounds, with 0 on friction rows, and ``mu`` holds the
    friction coefficient on friction rows and 0 elsewhere, so that the bounds at ``p`` are
    ``lo − mu·|p[fi]|`` and ``hi + mu·|p[fi]|``. ``fi[i]`` is the normal row of friction row
    ``i`` and 0 otherwise (any index does there, since mu is 0). ``threshold`` is the
    accepted natural-map residual (``tol · scale``).

    Precomputed indices for :func:`solve_labels`: ``diag_flat`` and ``coupling_flat`` (n,)
    address ``(i, i)`` and ``(i, fi[i])`` in a flattened (n, n) matrix; ``rhs_flat`` (3n,)
    is ``[lo, −b, hi]`` and ``rhs_base + n·label`` picks each row's right-hand side.
    """

    D: np.ndarray
    b: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    mu: np.ndarray
    fi: np.ndarray
    diag_flat: np.ndarray
    coupling_flat: np.ndarray
    rhs_flat: np.ndarray
    rhs_base: np.ndarray
    threshold: float


@dataclass(slots=True)
class Candidate:
    """A point p (n,), its w = D p + b (n,), the natural map's magnitude r (n,), ≥ 0, per row,
    and ``residual = max r``."""

    p: np.ndarray
    w: np.ndarray
    r: np.ndarray
    residual: float


@dataclass(slots=True)
class FinishOutcome:
    """Best candidate of a finish, whether it verified, and how many pivots it took."""

    best: Candidate
    converged: bool
    pivots: int


def bounds_at(prob: BoxProblem, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bounds (n,), (n,) with the friction bounds ±mu·|p_n| evaluated at p."""
    c = prob.mu * np.abs(p[prob.fi])
    return prob.lo - c, prob.hi + c


def evaluate(prob: BoxProblem, p: np.ndarray) -> Candidate:
    """w, the natural map ``p − Π_[lo(p), hi(p)](p − w)`` (as |r|) and its ∞-norm at p (n,).

    A non-finite p gets an infinite residual, so it never wins a comparison.
    """
    w = prob.D.dot(p)
    w += prob.b
    c = prob.mu * np.abs(p[prob.fi])
    r = p - w
    np.maximum(r, prob.lo - c, out=r)
    np.minimum(r, prob.hi + c, out=r)
    np.subtract(p, r, out=r)
    np.abs(r, out=r)
    # Plain Python on a short list beats numpy reductions at these sizes; the sum catches
    # NaN, which max() over a list would skip.
    values = r.tolist()
    residual = max(values)
    if not math.isfinite(sum(values)):
        residual = math.inf
    return Candidate(p=p, w=w, r=r, residual=residual)


def labels_at(prob: BoxProblem, p: np.ndarray, width: np.ndarray | None = None) -> np.ndarray:
    """Active set (n,) of ints that the finite point p (n,) implies: rows within ``atol`` of a
    bound are at it.

    The friction half-widths ``width`` (n,) default to ``mu·|p_n|``; pass the ones a QP was
    solved with to read off that QP's active set. The tolerance is relative to ‖p‖∞ because
    the point comes from an iterative solver (ProxQP) or from the previous time step; a row
    labelled at a bound by mistake is corrected by the pivoting in :func:`finish`. Lower wins
    when both hold (a friction row whose normal impulse is 0 has lo = hi = 0).
    """
    atol = 1e-9 * max(1.0, max(map(abs, p.tolist())))
    c = prob.mu * np.abs(p[prob.fi]) if width is None else width.copy()
    c -= atol
    labels = (p >= prob.hi + c).astype(np.intp)
    labels[p <= prob.lo - c] = -1
    return labels


def solve_labels(prob: BoxProblem, labels: np.ndarray) -> np.ndarray:
    """The impulses p (n,) that the active set ``labels`` (n,) implies, see the module doc.

    Runs on every simulation step: flat indices and LAPACK's getrf/getrs/gelsy are called
    directly because numpy's 2-D fancy indexing and ``linalg`` wrappers cost more than the
    solve itself at n ≈ 12.
    """
    free = labels == 0
    A = prob.D * free[:, None]
    flat = A.ravel()
    flat[prob.diag_flat[~free]] = 1.0
    # Friction rows at a bound: p_t − s·mu·p_n = 0 (mu is 0 on other rows).
    flat[prob.coupling_flat] -= labels * prob.mu
    rhs = prob.rhs_flat[prob.rhs_base + labels * labels.shape[0]]
    lu, piv, info = dgetrf(A)
    pivots = np.abs(lu.diagonal()).tolist()
    if info == 0 and min(pivots) > SINGULAR_PIVOT * max(pivots):
        return dgetrs(lu, piv, rhs)[0]
    return _min_norm_solve(A, rhs)


def _min_norm_solve(A: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Minimum-norm least-squares solution x (n,) of A x = rhs for a singular A (n, n).

    LAPACK gelsy: QR with column pivoting, then a complete orthogonal factorisation of the
    numerically full-rank part (rank decided with ``RANK_RCOND``); the null-space component of
    the solution is exactly zero, so identical rows get equal shares to rounding.
    """
    n = A.shape[0]
    # Workspace for block size up to 64 (LAPACK's optimum is MN + 2N + NB·(N + 1)); a fixed
    # formula saves the workspace query.
    lwork = 3 * n + 64 * (n + 1)
    x = dgelsy(A, rhs, np.zeros(n, dtype=np.int32), RANK_RCOND, lwork)[1]
    return x[:n]


def _targets(prob: BoxProblem, labels: np.ndarray, cand: Candidate) -> np.ndarray:
    """The label (n,) each row would move to if it is infeasible.

    Bound rows go free (w has the wrong sign). Free rows go to the bound they cross, or, when
    w_i ≠ 0 is left over from an inconsistent system, to the bound that w pushes them to.
    """
    lo, hi = bounds_at(prob, cand.p)
    p, w = cand.p, cand.w
    below = (p < lo) | ((p <= hi) & (w > 0.0))
    target = np.where(below, -1, 1)
    # No row can sit at an infinite bound: take the other one, or stay free.
    target[(target < 0) & np.isneginf(lo)] = 1
    target[(target > 0) & np.isposinf(hi)] = 0
    target[labels != 0] = 0
    return target


def finish(prob: BoxProblem, labels: np.ndarray, max_pivots: int) -> FinishOutcome:
    """Solve the active set ``labels`` (n,) exactly and pivot until it verifies.

    Verified means natural-map residual ≤ ``prob.threshold``. Pivoting is a best-first
    search over active sets, each visited at most once: the most promising one seen so far
    (fewest infeasible rows, then lowest residual) offers its next move — first the block
    pivot of Júdice & Pires (flip every infeasible row), then single pivots in least-index
    order (Murty), then single pivots to the other bound. While block pivots keep reducing
    the infeasible rows this is plain block principal pivoting; when they stop, it backs up
    to single pivots instead of cycling. Each move costs one linear solve and counts as one
    pivot; at most ``max_pivots`` are made. The lowest-residual candidate is returned either
    way.
    """
    cand = evaluate(prob, solve_labels(prob, labels))
    best = cand
    if cand.residual <= prob.threshold:
        return FinishOutcome(best=best, converged=True, pivots=0)
    seen = {labels.tobytes()}
    heap = [(_score(prob, cand), 0, _moves(prob, labels, cand))]
    pivots = 0
    while heap and pivots < max_pivots:
        trial = next(heap[0][2], None)
        if trial is None:
            heapq.heappop(heap)
            continue
        key = trial.tobytes()
        if key in seen:
            continue
        seen.add(key)
        pivots += 1
        cand = evaluate(prob, solve_labels(prob, trial))
        if cand.residual < best.residual:
            best = cand
        if cand.residual <= prob.threshold:
            return FinishOutcome(best=best, converged=True, pivots=pivots)
        if cand.residual < math.inf:
            heapq.heappush(heap, (_score(prob, cand), pivots, _moves(prob, trial, cand)))
    return FinishOutcome(best=best, converged=False, pivots=pivots)


def _score(prob: BoxProblem, cand: Candidate) -> tuple[int, float]:
    """How promising an active set is: (number of infeasible rows, residual)."""
    return int(np.count_nonzero(cand.r > prob.threshold)), cand.residual


def _moves(prob: BoxProblem, labels: np.ndarray, cand: Candidate) -> Iterator[np.ndarray]:
    """The pivots (n,) to try from ``labels``, most promising first (see :func:`finish`)."""
    bad = np.flatnonzero(cand.r > prob.threshold).tolist()
    target = _targets(prob, labels, cand)
    base = _resign_friction(prob, labels, cand)
    block = base.copy()
    block[bad] = target[bad]
    yield block
    for i in bad:
        single = base.copy()
        single[i] = target[i]
        yield single
    lo, hi = bounds_at(prob, cand.p)
    for i in bad:
        other = -target[i] if target[i] != 0 else -labels[i]
        if other != 0 and math.isfinite(lo[i] if other < 0 else hi[i]):
            single = base.copy()
            single[i] = other
            yield single


def _resign_friction(prob: BoxProblem, labels: np.ndarray, cand: Candidate) -> np.ndarray:
    """Labels (n,) with friction rows of zero width turned to the side their w asks for.

    A friction row whose normal impulse is 0 has bounds [0, 0]: the natural map cannot see
    that its w has the wrong sign for its label (w < 0 at the lower bound), yet the label
    decides ``p_t = ∓mu·p_n`` once the normal row goes free — keeping the wrong one makes the
    pivoting cycle between "normal free, pushing the wrong way" and "normal at 0".
    """
    wrong = (labels * cand.w > prob.threshold) & (cand.r <= prob.threshold) & (prob.mu > 0.0)
    if not wrong.any():
        return labels
    labels = labels.copy()
    labels[wrong] = -labels[wrong]
    return labels

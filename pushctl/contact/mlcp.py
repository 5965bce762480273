"""Box-friction MLCP solver: ProxSuite's dense ProxQP, a fixed point on the friction bounds,
and an exact active-set finish (docs/design.md §3 "MLCP solver").

The problem, in impulses p [N·s] and velocities w [m/s or rad/s] (one entry per constraint
row): find p (n,) with ``w = D p + b``, ``lo ≤ p ≤ hi`` and w complementary to the bounds —
``w_i ≥ 0`` where ``p_i`` is at its lower bound, ``w_i ≤ 0`` at its upper bound, ``w_i = 0``
strictly between. A row with ``findex[i] ≥ 0`` is a friction row (ODE/Bullet box-friction
convention): its bounds are ``±mu_i·|p[findex[i]]|`` and its own lo/hi are ignored.

Method:

1. ``warm_start`` given (e.g. the last time step's p): solve the active set it implies
   exactly in one compiled call
   (:func:`pushctl.contact.compiled.assembly.active_set_step`); return at
   once if it verifies (``method="warm-start"``).
2. Compiled block principal pivoting (:func:`pushctl.contact.compiled.pivoting.pivot_solve`,
   at most ``_COLD_PIVOTS`` pivots each) from the warm start's active set
   (``method="warm-start"``), then from "every row free" and from the active set of p = 0
   (``method="active-set"``). This is the cold path of a simulation (a prong starts or stops
   slipping): about 90 % of such steps end here, with an answer that is a
   deterministic function of the inputs.
3. Otherwise the warm start's active set is pivoted by the plain-numpy best-first search (up
   to four pivots, :mod:`pushctl.contact.active_set`, ``method="warm-start"``), and then,
   with the friction bounds frozen, the MLCP is the KKT system of the box QP ``min ½ pᵀDp +
   bᵀp s.t. lo ≤ p ≤ hi``, solved by ProxQP; an outer fixed point re-solves it (warm-
   started) with the bounds of the last solution until they stop moving. The plain fixed
   point cycles on a few percent of instances (residuals 1e-5..1e-2), so the active set it
   settles on (or cycles through) is solved exactly and pivoted; if that fails, the fixed
   point goes on under-relaxed and its active sets are tried in turn
   (``method="proxqp+active-set"``).
4. If nothing verifies, the iterate with the lowest residual is returned with
   ``converged=False`` (``method="fallback"``). If no finite iterate exists at all, p is 0
   clipped to the fixed bounds (friction rows 0): the result is never NaN.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from pushctl.contact.active_set import (
    BoxProblem,
    Candidate,
    evaluate,
    finish,
    labels_at,
)
from pushctl.contact.compiled.assembly import active_set_step
from pushctl.contact.compiled.pivoting import cold_pivot
from pushctl.contact.mlcp_checks import validated_arrays, warm_vector
from pushctl.errors import MLCPInputError
from pushctl.machine.proxqp_build import proxqp

DEFAULT_TOL = 1e-9
"""Natural-map residual accepted by default, relative to max(1, ‖b‖∞)."""

_QP_EPS_ABS = 1e-11
"""ProxQP's absolute accuracy; the exact finish does the rest."""

_WARM_PIVOTS = 4
"""Pivots allowed from a warm start's active set before the cold path takes over."""

_COLD_PIVOTS = 30
"""Pivots of the compiled search from each of its starting active sets (the 30 was chosen on
problems recorded from random-action pushes: 76 of 93 cold solves verify from the warm
start within it, 89 of 93 with the two other starts; more rarely helps)."""

_HANDOVER_PIVOTS = 4
"""Pivots allowed when the fixed point's active set repeats, before iterating on."""

_CYCLE_MEMORY = 8
"""Iterates remembered to recognise a cycle of the fixed point."""

_RELAXATION = (1.0, 0.5, 0.25)
"""Fraction of each friction-bound update taken, per phase of the fixed point: the plain
fixed point first, then damped ones where it cycles."""


@dataclass(frozen=True, slots=True)
class MLCPResult:
    """Solution of one box-friction MLCP.

    - ``p``: (n,) impulses [N·s] (or whatever unit the rows have).
    - ``w``: (n,) ``D p + b`` at the returned p.
    - ``residual``: ∞-norm of the natural map ``p − Π_[lo(p), hi(p)](p − w)``, with the
      friction bounds ``±mu·|p_n|`` evaluated at the returned p.
    - ``iterations``: fixed-point iterations (ProxQP solves) + active-set pivots.
    - ``converged``: ``residual ≤ tol · max(1, ‖b‖∞)`` (the scale keeps the test relative for
      large free velocities; below 1 it is absolute).
    - ``method``: ``"warm-start"`` (the warm start's active set, pivoted, verified),
      ``"active-set"`` (compiled pivoting from a fixed start, verified),
      ``"proxqp+active-set"`` (fixed point + exact finish verified) or
      ``"fallback"`` (nothing verified: the lowest-residual iterate, ``converged=False``).
    """

    p: np.ndarray
    w: np.ndarray
    residual: float
    iterations: int
    converged: bool
    method: str


def cold_pivot_budget(max_iterations: int = 50) -> int:
    """Pivots of :func:`solve_box_mlcp`'s compiled cold path from each start, for its
    ``max_iterations`` (the default's: 30)."""
    return min(_COLD_PIVOTS, max_iterations)


def solve_box_mlcp(
    D: np.ndarray,
    b: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    findex: np.ndarray,
    mu: np.ndarray,
    *,
    warm_start: np.ndarray | None = None,
    tol: float = DEFAULT_TOL,
    max_iterations: int = 50,
    validate: bool = True,
) -> MLCPResult:
    """Solve the box-friction MLCP ``w = D p + b`` with p in ``[lo(p), hi(p)]`` ⊥ w.

    Args:
        D: (n, n) symmetric positive semi-definite matrix (e.g. ``A M⁻¹ Aᵀ`` [1/kg]); may be
            singular. Symmetry is assumed, not checked.
        b: (n,) free velocity of the rows (plus stabilisation) [m/s].
        lo, hi: (n,) fixed bounds of non-friction rows [N·s]; ±inf allowed, ``lo ≤ hi``.
            Ignored on friction rows.
        findex: (n,) int: −1 for a non-friction row, else the index of the normal row whose
            impulse scales this friction row's bounds. A normal row is not a friction row
            itself and needs ``lo ≥ 0`` (so that ``mu·p_n`` is a bound, not its negative).
        mu: (n,) friction coefficients [-], ``≥ 0`` and finite on friction rows; ignored
            elsewhere.
        warm_start: (n,) optional previous p, e.g. the last time step's.
        tol: accepted natural-map residual relative to ``scale = max(1, ‖b‖∞)``.
        max_iterations: bound on the fixed-point iterations of each relaxation phase and on
            the pivots of each exact finish (the warm start's finish gets at most 4 pivots).
        validate: check the arrays (the default). A caller that builds them itself, like the
            world step, may pass False to skip the checks; the
            arrays must then be float64/integer numpy arrays of the right shapes and meaning.

    Returns:
        An :class:`MLCPResult`; never NaN. Ties (a singular D admits many p) are broken by the
        minimum-norm solution of the final active set's linear system, so identical rows get
        equal shares and the same active set always gives the same p. With ``n = 0`` the
        result is empty and converged.

    Raises:
        MLCPInputError: arrays of mismatched sizes, non-finite D or b, NaN bounds, lo > hi,
            bad findex, negative or non-finite friction coefficients, bad warm_start, tol or
            max_iterations.
    """
    if validate:
        D, b, lo, hi, findex, mu = validated_arrays(D, b, lo, hi, findex, mu, tol)
        if not (isinstance(max_iterations, int | np.integer) and max_iterations >= 1):
            raise MLCPInputError(f"max_iterations must be an integer >= 1, got {max_iterations!r}")
        start = None if warm_start is None else warm_vector(warm_start, len(b))
    else:
        start = warm_start
    n = len(b)
    if n == 0:
        method = "proxqp+active-set" if start is None else "warm-start"
        return MLCPResult(np.zeros(0), np.zeros(0), 0.0, 0, True, method)
    threshold = float(tol) * max(1.0, float(np.abs(b).max()))
    if start is not None:
        # The hot path of a simulation: the last step's active set, solved in one compiled
        # call; most steps end here.
        p, w, residual, verified = active_set_step(D, b, lo, hi, findex, mu, start, threshold)
        if verified:
            return MLCPResult(p, w, float(residual), 0, True, "warm-start")
    # The cold path, compiled: pivoting from the warm start's active set, then from two
    # fixed ones (see the module doc).
    guess = np.zeros(n) if start is None else start
    budget = cold_pivot_budget(max_iterations)
    p, w, residual, verified, iterations, which = cold_pivot(
        D, b, lo, hi, findex, mu, guess, start is not None, threshold, budget
    )
    if verified:
        method = "warm-start" if which == 0 else "active-set"
        return MLCPResult(p, w, float(residual), iterations, True, method)
    return solve_after_pivoting(
        D, b, lo, hi, findex, mu, start, threshold, iterations, max_iterations
    )


def solve_after_pivoting(
    D: np.ndarray,
    b: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    findex: np.ndarray,
    mu: np.ndarray,
    start: np.ndarray | None,
    threshold: float,
    iterations: int,
    max_iterations: int = 50,
) -> MLCPResult:
    """The rest of :func:`solve_box_mlcp` once its compiled pivoting found nothing that
    verifies (arrays as there, valid; ``start`` its warm start or None, ``threshold`` its
    accepted residual, ``iterations`` the pivots so far): the exact finish from the warm
    start's active set, ProxQP's fixed point, the best point met."""
    n = len(b)
    prob = _box_problem(D, b, lo, hi, findex, mu, threshold)
    best = None
    if start is not None:
        out = finish(prob, labels_at(prob, start), min(_WARM_PIVOTS, max_iterations))
        iterations += out.pivots
        if out.converged:
            return _result(out.best, iterations, True, "warm-start")
        best = out.best
    cold = _cold_solve(prob, np.zeros(n) if start is None else start, max_iterations)
    iterations += cold.iterations
    if cold.converged and cold.best is not None:
        return _result(cold.best, iterations, True, "proxqp+active-set")
    best = _better(best, cold.best)
    if best is None:
        best = evaluate(prob, _safe_point(prob))
    return _result(best, iterations, best.residual <= prob.threshold, "fallback")


@dataclass(slots=True)
class _ColdOutcome:
    best: Candidate | None
    converged: bool
    iterations: int


def _cold_solve(prob: BoxProblem, start: np.ndarray, max_iterations: int) -> _ColdOutcome:
    """ProxQP fixed point on the friction bounds from ``start`` (n,), then the exact finish.

    Phase one is the plain fixed point; if its active set cannot be finished, the fixed
    point is run again from where it stopped with the bound updates under-relaxed
    (``_RELAXATION``), which damps the overshoot that makes the plain one cycle and so
    reaches other active sets to finish from. Within a phase, the fixed point hands over as
    soon as its iterate's active set repeats one seen before (settled, or cycling): the
    finish is tried on it with a few pivots and, if it verifies, returned. A phase ends when
    the bounds stop moving, after ``max_iterations`` iterations, or when the bounds repeat
    those of an earlier iterate (a cycle); its last active set is then finished with up to
    ``max_iterations`` pivots.
    """
    best: Candidate | None = None
    tried: set[bytes] = set()
    iterations = 0
    for relax in _RELAXATION:
        seen: set[bytes] = set()
        last: Candidate | None = None
        labels = None
        history: list[np.ndarray] = []
        for cand, width in _fixed_point(prob, start, max_iterations, relax):
            iterations += 1
            best, last = _better(best, cand), cand
            # The active set of the QP just solved: against its own bounds, not those at p.
            labels = labels_at(prob, cand.p, width)
            key = labels.tobytes()
            if (key in seen and key not in tried) or cand.residual <= prob.threshold:
                out = finish(prob, labels, _HANDOVER_PIVOTS)
                iterations += out.pivots
                if out.converged:
                    return _ColdOutcome(out.best, True, iterations)
                best = _better(best, out.best)
                tried.add(key)
            seen.add(key)
            if _repeats(width, history, prob.threshold):
                break  # a cycle: the fixed point would only repeat itself
        if labels is None or last is None:
            break
        out = finish(prob, labels, max_iterations)
        iterations += out.pivots
        best = _better(best, out.best)
        if out.converged:
            return _ColdOutcome(out.best, True, iterations)
        tried.add(labels.tobytes())
        start = last.p
    converged = best is not None and best.residual <= prob.threshold
    return _ColdOutcome(best, converged, iterations)


def _fixed_point(
    prob: BoxProblem, start: np.ndarray, max_iterations: int, relax: float
) -> Iterator[tuple[Candidate, np.ndarray]]:
    """Yield each fixed-point iteration's ProxQP solution and the friction half-widths (n,)
    it was solved with.

    The first QP gets the friction bounds ``±mu·|p_n|`` of ``start`` (n,); iteration k + 1
    moves the half-widths a fraction ``relax`` of the way to those of iterate k and re-solves,
    warm-started from iterate k. Stops when the bounds of an iterate match those it was
    solved with to the residual threshold, on a non-finite iterate, or after
    ``max_iterations`` solves.
    """
    n = prob.b.shape[0]
    qp = _reused_qp(n)
    qp.settings.initial_guess = proxqp.InitialGuess.EQUALITY_CONSTRAINED_INITIAL_GUESS
    # Friction half-widths mu·|p_n| (0 on other rows): the part of the bounds that moves.
    width = prob.mu * np.abs(start[prob.fi])
    qp.init(prob.D, prob.b, None, None, None, None, None, prob.lo - width, prob.hi + width)
    # Warm start from x passed explicitly: with WARM_START_WITH_PREVIOUS_RESULT, proxsuite
    # 0.8.0 returns the previous solution unchanged after a box-only update.
    qp.settings.initial_guess = proxqp.InitialGuess.WARM_START
    qp.solve(start, None, None)
    for _ in range(max_iterations):
        p = np.array(qp.results.x, dtype=float)
        if not np.all(np.isfinite(p)):
            return
        yield evaluate(prob, p), width
        step = prob.mu * np.abs(p[prob.fi]) - width
        if np.max(np.abs(step)) <= prob.threshold:
            return
        width = width + relax * step
        qp.update(l_box=prob.lo - width, u_box=prob.hi + width)
        qp.solve(p, None, None)


_QPS: dict[int, proxqp.dense.QP] = {}
"""One ProxQP problem per size, reused. It was the in-process fix for ProxSuite's vectorised
builds, whose answers move with where a fresh problem's workspace lands; with the portable
build (:mod:`pushctl.machine.proxqp_build`) placement no longer matters, and the reuse stays because
its answers are the ones the shipped results were made with and it saves an allocation."""


def _reused_qp(n: int) -> proxqp.dense.QP:
    qp = _QPS.get(n)
    if qp is None:
        qp = proxqp.dense.QP(n, 0, 0, True)
        qp.settings.eps_abs = _QP_EPS_ABS
        qp.settings.eps_rel = 0.0
        qp.settings.verbose = False
        _QPS[n] = qp
    return qp


def _repeats(width: np.ndarray, history: list[np.ndarray], tol: float) -> bool:
    """Whether the bounds ``width`` (n,) repeat those of an earlier iterate (a cycle of the
    fixed point, period ≤ ``_CYCLE_MEMORY``); appends them to ``history``."""
    cycle = any(float(np.max(np.abs(width - old))) <= tol for old in history[:-1])
    history.append(width)
    del history[:-_CYCLE_MEMORY]
    return cycle


def _better(a: Candidate | None, b: Candidate | None) -> Candidate | None:
    """The candidate with the lower residual (the first on a tie; None only if both are)."""
    if a is None or (b is not None and b.residual < a.residual):
        return b
    return a


def _safe_point(prob: BoxProblem) -> np.ndarray:
    """Last resort when every iterate was non-finite: 0 clipped to the fixed bounds (n,)."""
    return np.clip(np.zeros_like(prob.b), prob.lo, prob.hi)


def _result(cand: Candidate, iterations: int, converged: bool, method: str) -> MLCPResult:
    return MLCPResult(cand.p, cand.w, cand.residual, iterations, converged, method)


# ------------------------------------------------------------------------------ validation


def _box_problem(D, b, lo, hi, fidx, mu, threshold: float) -> BoxProblem:
    """The :class:`BoxProblem` of valid arrays: D (n, n), b, lo, hi, mu (n,) float64 and
    fidx (n,) integers; ``threshold`` the accepted natural-map residual."""
    n = len(b)
    fric = fidx >= 0
    lo_f = np.where(fric, 0.0, lo)
    hi_f = np.where(fric, 0.0, hi)
    # Any index will do on non-friction rows, where mu is 0: clamping saves a np.where.
    fi = np.maximum(fidx, 0)
    return BoxProblem(
        D=D,
        b=b,
        lo=lo_f,
        hi=hi_f,
        mu=np.where(fric, mu, 0.0),
        fi=fi,
        diag_flat=np.arange(0, n * n, n + 1),
        coupling_flat=fi + np.arange(0, n * n, max(n, 1)),
        rhs_flat=np.concatenate((lo_f, -b, hi_f)),
        rhs_base=np.arange(n, 2 * n),
        threshold=threshold,
    )

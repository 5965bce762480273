"""Tests of :func:`pushctl.contact.solve_box_mlcp` against an independent reference.

The reference below shares no code with the solver: it enumerates every active set (each
row at its lower bound, free, or at its upper bound; a friction row at a bound tied to its
normal, ``p_t = ±mu·p_n``), solves each candidate system with ``scipy.linalg.lstsq`` and
keeps the candidates that satisfy complementarity to 1e-9. For n ≤ 8 that is at most
3⁸ = 6561 small solves per instance.

What is true, and so what is asserted:

- The solution exists for these instances (b = G c lies in the range of D = G Gᵀ) and the
  reference finds it.
- D positive definite: the box-friction MLCP need not have a unique solution (friction
  makes it non-monotone), but it usually does; where the reference finds one, p must match
  it; where it finds several, p must be one of them.
- D singular without friction rows: a convex QP, whose gradient w = D p + b is the same at
  every minimiser, so w must match the reference's (unique) w.
- D singular with friction rows: neither p nor w need be unique. The reference's lstsq gives
  the minimum-norm p of each active set, as does the solver, so our (p, w) is asserted to be
  one of the reference's solutions (a seeded observation, not a theorem); always: residual.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import scipy.linalg

from pushctl.contact import MLCPResult, solve_box_mlcp
from pushctl.errors import MLCPInputError

TOL = 1e-9

# ------------------------------------------------------------------ independent reference


def natural_map(D, b, lo, hi, findex, mu, p):
    """|p − clip(p − w, lo(p), hi(p))| per row, friction bounds ±mu·p_n at p."""
    w = D @ p + b
    lower, upper = np.array(lo, dtype=float), np.array(hi, dtype=float)
    for i, j in enumerate(findex):
        if j >= 0:
            lower[i], upper[i] = -mu[i] * p[j], mu[i] * p[j]
    return np.abs(p - np.minimum(np.maximum(p - w, lower), upper))


def reference_solutions(D, b, lo, hi, findex, mu):
    """Every distinct solution p found by exhaustive active-set enumeration."""
    n = len(b)
    found: list[np.ndarray] = []
    for labels in itertools.product((-1, 0, 1), repeat=n):
        system = _candidate_system(D, b, lo, hi, findex, mu, labels)
        if system is None:
            continue
        p = scipy.linalg.lstsq(*system)[0]
        if np.max(np.abs(system[0] @ p - system[1])) > 1e-9:
            continue
        if np.max(natural_map(D, b, lo, hi, findex, mu, p)) > TOL:
            continue
        if not any(np.max(np.abs(p - q)) <= 1e-9 for q in found):
            found.append(p)
    return found


def _candidate_system(D, b, lo, hi, findex, mu, labels):
    n = len(b)
    A, rhs = np.zeros((n, n)), np.zeros(n)
    for i, s in enumerate(labels):
        if s == 0:
            A[i], rhs[i] = D[i], -b[i]
        elif findex[i] >= 0:
            A[i, i], A[i, findex[i]] = 1.0, -s * mu[i]
        else:
            bound = lo[i] if s < 0 else hi[i]
            if not np.isfinite(bound):
                return None
            A[i, i], rhs[i] = 1.0, bound
    return A, rhs


def plain_fixed_point(D, b, lo, hi, findex, mu, iterations=50):
    """The plain fixed point on the friction bounds, each box QP solved exactly by
    enumeration (no coupling: friction rows get the bounds of the previous iterate)."""
    p = np.zeros(len(b))
    for _ in range(iterations):
        lower, upper = np.array(lo, dtype=float), np.array(hi, dtype=float)
        for i, j in enumerate(findex):
            if j >= 0:
                lower[i], upper[i] = -mu[i] * p[j], mu[i] * p[j]
        frozen = -np.ones(len(b), dtype=int)
        p = reference_solutions(D, b, lower, upper, frozen, np.zeros(len(b)))[0]
    return p


# ------------------------------------------------------------------------------ instances


def random_instance(rng: np.random.Generator, n: int):
    """Normal + friction pairs mixed with fixed-bound rows; D = G Gᵀ, G (n, m), m maybe < n."""
    lo, hi = np.zeros(n), np.zeros(n)
    findex, mu = -np.ones(n, dtype=int), np.zeros(n)
    i = 0
    while i < n:
        if i + 1 < n and rng.random() < 0.6:
            hi[i] = np.inf
            findex[i + 1], mu[i + 1] = i, rng.uniform(0.0, 1.5)
            i += 2
            continue
        c, kind = rng.uniform(0.01, 1.0), rng.integers(0, 4)
        lo[i], hi[i] = [(-c, c), (0.0, np.inf), (c, c), (-np.inf, np.inf)][kind]
        i += 1
    m = int(rng.integers(1, n + 3))
    G = rng.standard_normal((n, m)) * rng.uniform(0.5, 5.0)
    b = G @ rng.standard_normal(m)
    b *= 10.0 ** rng.uniform(-3.0, 0.0) / np.max(np.abs(b))
    return G @ G.T, b, lo, hi, findex, mu


def two_prong_instance(rng: np.random.Generator, mu_c: float, push: float):
    """Two prongs on one face of a planar object (3 DOF): rows (n1, t1, n2, t2), the two
    tangential rows identical, so D (4, 4) has rank 3."""
    m, Iz = 0.3, 3.9e-4
    rows = [
        [1.0, 0.0, -0.035],
        [0.0, 1.0, -0.044],
        [1.0, 0.0, 0.035],
        [0.0, 1.0, -0.044],
    ]
    A = np.array(rows)
    D = A @ np.diag([1 / m, 1 / m, 1 / Iz]) @ A.T
    b = A @ np.array([-push, rng.uniform(-0.2, 0.2) * push, 0.0])
    lo, hi = np.zeros(4), np.array([np.inf, 0.0, np.inf, 0.0])
    return D, b, lo, hi, np.array([-1, 0, -1, 2]), np.array([0.0, mu_c, 0.0, mu_c])


def _sizes():
    return [2] * 40 + [3] * 40 + [4] * 40 + [5] * 40 + [6] * 28 + [7] * 12 + [8] * 6


# ------------------------------------------------------------------------- random cases


def test_random_instances_match_exhaustive_reference():
    rng = np.random.default_rng(20240611)
    counts = dict(pd_unique=0, pd_several=0, singular_plain=0, singular_friction=0)
    for n in _sizes():
        D, b, lo, hi, findex, mu = random_instance(rng, n)
        result = solve_box_mlcp(D, b, lo, hi, findex, mu)
        refs = reference_solutions(D, b, lo, hi, findex, mu)
        assert refs, "the reference found no solution: the instance generator is wrong"
        assert result.converged
        assert result.residual <= TOL
        assert np.max(natural_map(D, b, lo, hi, findex, mu, result.p)) <= TOL
        np.testing.assert_allclose(result.w, D @ result.p + b, rtol=0, atol=1e-12)
        p_dist = min(np.max(np.abs(result.p - q)) for q in refs)
        w_dist = min(np.max(np.abs(result.w - (D @ q + b))) for q in refs)
        if np.linalg.eigvalsh(D)[0] > 1e-8 * np.max(np.abs(D)):
            key = "pd_unique" if len(refs) == 1 else "pd_several"
            assert p_dist <= 1e-7
        elif (findex < 0).all():
            key = "singular_plain"
            assert np.ptp([D @ q + b for q in refs], axis=0).max() <= 1e-7
            assert w_dist <= 1e-7
        else:
            key = "singular_friction"
            assert w_dist <= 1e-7
        counts[key] += 1
    assert sum(counts.values()) >= 200
    assert counts["pd_unique"] >= 60 and counts["singular_friction"] >= 40
    assert counts["singular_plain"] >= 5


def test_warm_start_gives_the_cold_answer():
    rng = np.random.default_rng(7)
    warm_hits = 0
    for n in [4, 6, 8, 12] * 15:
        D, b, lo, hi, findex, mu = random_instance(rng, n)
        D += np.eye(n)  # positive definite, so (in these seeded cases) one solution
        cold = solve_box_mlcp(D, b, lo, hi, findex, mu)
        same = solve_box_mlcp(D, b, lo, hi, findex, mu, warm_start=cold.p)
        assert same.method == "warm-start" and same.iterations == 0
        np.testing.assert_allclose(same.p, cold.p, rtol=0, atol=1e-12)
        # Next "time step": b moves a little, warm start from the last p.
        b2 = b * (1.0 + 1e-3) + 1e-5 * rng.standard_normal(n)
        cold2 = solve_box_mlcp(D, b2, lo, hi, findex, mu)
        warm2 = solve_box_mlcp(D, b2, lo, hi, findex, mu, warm_start=cold.p)
        assert warm2.converged and warm2.residual <= TOL
        np.testing.assert_allclose(warm2.p, cold2.p, rtol=0, atol=1e-7)
        warm_hits += warm2.method == "warm-start"
    assert warm_hits >= 40


def test_wrong_warm_start_still_converges():
    rng = np.random.default_rng(8)
    for n in [3, 5, 6, 12] * 10:
        D, b, lo, hi, findex, mu = random_instance(rng, n)
        wrong = rng.normal(scale=10.0, size=n)
        result = solve_box_mlcp(D, b, lo, hi, findex, mu, warm_start=wrong)
        assert result.converged and result.residual <= TOL
        assert np.max(natural_map(D, b, lo, hi, findex, mu, result.p)) <= TOL
        if n <= 6:
            # Friction makes solutions non-unique, so the wrong start may pick another one.
            refs = reference_solutions(D, b, lo, hi, findex, mu)
            assert min(np.max(np.abs(result.p - q)) for q in refs) <= 1e-7


# ----------------------------------------------------------------------- degenerate cases


def test_identical_tangential_rows_share_equally():
    rng = np.random.default_rng(3)
    D, b, lo, hi, findex, mu = two_prong_instance(rng, mu_c=5.0, push=0.02)
    assert np.linalg.matrix_rank(D) == 3 and np.array_equal(D[1], D[3])
    result = solve_box_mlcp(D, b, lo, hi, findex, mu)
    assert result.residual <= TOL
    assert result.p[1] != 0.0
    assert abs(result.p[1] - result.p[3]) <= 1e-12 * abs(result.p[1])
    again = solve_box_mlcp(D, b, lo, hi, findex, mu)
    assert np.array_equal(again.p, result.p)


def test_free_singular_rows_get_the_minimum_norm_split():
    # 8 ground friction rows on 3 object DOF, all sticking: p = −D⁺ b, the minimum-norm one.
    rng = np.random.default_rng(4)
    A = rng.standard_normal((8, 3))
    D = A @ np.diag([1 / 0.3, 1 / 0.3, 1 / 3.9e-4]) @ A.T
    b = D @ rng.normal(scale=1e-4, size=8)
    big = np.full(8, 10.0)
    result = solve_box_mlcp(D, b, -big, big, -np.ones(8, dtype=int), np.zeros(8))
    assert result.residual <= TOL
    np.testing.assert_allclose(result.p, -np.linalg.pinv(D) @ b, rtol=1e-9, atol=1e-12)


def test_zero_friction_coefficient_gives_zero_friction():
    rng = np.random.default_rng(5)
    D, b, lo, hi, findex, _ = two_prong_instance(rng, mu_c=0.4, push=0.02)
    mu = np.zeros(4)
    result = solve_box_mlcp(D, b, lo, hi, findex, mu)
    assert result.residual <= TOL
    assert result.p[1] == 0.0 and result.p[3] == 0.0
    assert result.p[0] > 0.0 and result.p[2] > 0.0
    np.testing.assert_allclose(result.w[[0, 2]], 0.0, atol=1e-12)


def test_all_separating_gives_zero_impulse():
    rng = np.random.default_rng(6)
    D, b, lo, hi, findex, mu = two_prong_instance(rng, mu_c=0.4, push=-0.02)
    assert b[0] > 0 and b[2] > 0
    result = solve_box_mlcp(D, b, lo, hi, findex, mu)
    assert result.converged and np.array_equal(result.p, np.zeros(4))
    np.testing.assert_array_equal(result.w, b)


def test_all_sticking_keeps_friction_strictly_inside():
    rng = np.random.default_rng(9)
    D, b, lo, hi, findex, mu = two_prong_instance(rng, mu_c=10.0, push=0.02)
    result = solve_box_mlcp(D, b, lo, hi, findex, mu)
    p, w = result.p, result.w
    assert result.residual <= TOL
    assert p[0] > 0 and p[2] > 0
    assert abs(p[1]) < 10.0 * p[0] and abs(p[3]) < 10.0 * p[2]
    np.testing.assert_allclose(w, 0.0, atol=1e-12)


def test_single_contact_where_the_plain_fixed_point_cycles():
    rng = np.random.default_rng(11)
    for _ in range(400):
        g = rng.standard_normal((2, 2))
        D, b = g @ g.T, g @ rng.standard_normal(2)
        lo, hi = np.zeros(2), np.array([np.inf, 0.0])
        findex, mu = np.array([-1, 0]), np.array([0.0, rng.uniform(0.5, 2.0)])
        plain = plain_fixed_point(D, b, lo, hi, findex, mu)
        if np.max(natural_map(D, b, lo, hi, findex, mu, plain)) > 1e-6:
            break
    else:
        pytest.fail("no instance found on which the plain fixed point fails")
    result = solve_box_mlcp(D, b, lo, hi, findex, mu)
    refs = reference_solutions(D, b, lo, hi, findex, mu)
    assert result.converged and result.residual <= TOL
    assert min(np.max(np.abs(result.p - q)) for q in refs) <= 1e-12


def test_no_solution_falls_back_finite():
    # w = −1 whatever p ≥ 0 is: no solution. The result is the best iterate, never NaN.
    result = solve_box_mlcp(
        np.zeros((1, 1)), [-1.0], [0.0], [np.inf], [-1], [0.0], max_iterations=5
    )
    assert isinstance(result, MLCPResult)
    assert not result.converged and result.method == "fallback"
    assert np.isfinite(result.p).all() and np.isfinite(result.w).all()
    assert result.residual == pytest.approx(1.0)


def test_empty_problem():
    result = solve_box_mlcp(np.zeros((0, 0)), [], [], [], [], [])
    assert result.converged and result.p.shape == (0,) and result.residual == 0.0


# ---------------------------------------------------------------------------- bad inputs


def _good():
    D = np.array([[2.0, 0.5, 0.1], [0.5, 1.0, 0.2], [0.1, 0.2, 1.5]])
    return dict(
        D=D,
        b=np.array([-0.1, 0.05, 0.2]),
        lo=np.array([0.0, 0.0, -1.0]),
        hi=np.array([np.inf, 0.0, 1.0]),
        findex=np.array([-1, 0, -1]),
        mu=np.array([0.0, 0.5, 0.0]),
    )


def _with(**changes):
    args = _good()
    for key, value in changes.items():
        if callable(value):
            args[key] = value(args[key].copy())
        else:
            args[key] = value
    return args


def _set(index, value):
    def change(arr):
        arr[index] = value
        return arr

    return change


BAD_INPUTS = {
    "D not square": (_with(D=lambda D: D[:, :2]), "D"),
    "D one-dimensional": (_with(D=np.ones(3)), "D"),
    "b length": (_with(b=lambda b: b[:2]), "b"),
    "lo length": (_with(lo=np.zeros(4)), "lo"),
    "hi length": (_with(hi=np.zeros(2)), "hi"),
    "findex length": (_with(findex=np.array([-1, 0])), "findex"),
    "mu length": (_with(mu=np.zeros(5)), "mu"),
    "D NaN": (_with(D=_set((0, 1), np.nan)), "D"),
    "D inf": (_with(D=_set((2, 2), np.inf)), "D"),
    "b NaN": (_with(b=_set(1, np.nan)), "b"),
    "b inf": (_with(b=_set(0, -np.inf)), "b"),
    "lo > hi": (_with(lo=_set(2, 2.0)), "lo[2]"),
    "lo NaN": (_with(lo=_set(2, np.nan)), "lo[2]"),
    "lo +inf": (_with(lo=_set(2, np.inf), hi=_set(2, np.inf)), "lo[2]"),
    "hi NaN": (_with(hi=_set(2, np.nan)), "hi[2]"),
    "hi -inf": (_with(hi=_set(2, -np.inf), lo=_set(2, -np.inf)), "hi[2]"),
    "findex too large": (_with(findex=_set(1, 3)), "findex[1]"),
    "findex below -1": (_with(findex=_set(1, -2)), "findex[1]"),
    "findex not integer": (_with(findex=np.array([-1.0, 0.5, -1.0])), "findex"),
    "findex at itself": (_with(findex=_set(1, 1)), "findex[1]"),
    "findex at friction row": (_with(findex=np.array([-1, 0, 1])), "findex[2]"),
    "normal row lo < 0": (_with(lo=_set(0, -1.0)), "lo"),
    "mu negative": (_with(mu=_set(1, -0.1)), "mu[1]"),
    "mu NaN": (_with(mu=_set(1, np.nan)), "mu[1]"),
    "mu inf": (_with(mu=_set(1, np.inf)), "mu[1]"),
}


@pytest.mark.parametrize("case", sorted(BAD_INPUTS))
def test_bad_input_raises_with_a_one_line_message(case):
    args, needle = BAD_INPUTS[case]
    with pytest.raises(MLCPInputError) as info:
        solve_box_mlcp(**args)
    message = str(info.value)
    assert needle in message and "\n" not in message
    assert isinstance(info.value, ValueError)


@pytest.mark.parametrize(
    ("options", "needle"),
    [
        (dict(warm_start=np.zeros(2)), "warm_start"),
        (dict(warm_start=np.array([0.0, np.nan, 0.0])), "warm_start"),
        (dict(tol=0.0), "tol"),
        (dict(tol=float("nan")), "tol"),
        (dict(max_iterations=0), "max_iterations"),
    ],
)
def test_bad_option_raises(options, needle):
    with pytest.raises(MLCPInputError, match=needle):
        solve_box_mlcp(**_good(), **options)


def test_friction_rows_ignore_their_own_bounds_and_other_rows_ignore_mu():
    args = _with(lo=_set(1, np.nan), hi=_set(1, -np.inf), mu=_set(2, np.nan))
    result = solve_box_mlcp(**args)
    reference = solve_box_mlcp(**_good())
    assert result.converged
    np.testing.assert_array_equal(result.p, reference.p)

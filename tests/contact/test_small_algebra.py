"""The step's small dense algebra (pushctl/contact/small_algebra.py) against numpy's."""

from __future__ import annotations

import numpy as np

from pushctl.contact.compiled.algebra import lu_solve, matmul, matvec, plus_diagonal, spd_solve


def _spd(rng: np.random.Generator, n: int) -> np.ndarray:
    A = rng.standard_normal((n, n))
    return 0.1 * A @ A.T + 0.05 * np.eye(n)


def test_plus_diagonal_is_numpys_sum_to_the_bit_and_leaves_its_input() -> None:
    rng = np.random.default_rng(0)
    M, d = _spd(rng, 7), rng.uniform(0.0, 300.0, 7)
    before = M.copy()
    assert np.array_equal(plus_diagonal(M, 0.01, d), M + np.diag(0.01 * d))
    assert np.array_equal(M, before)


def test_the_products_and_the_solve_agree_with_numpy() -> None:
    rng = np.random.default_rng(1)
    A, B, x = _spd(rng, 7), rng.standard_normal((7, 3)), rng.standard_normal(7)
    np.testing.assert_allclose(matvec(A, x), A @ x, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(matmul(A, B), A @ B, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(A @ spd_solve(A, B), B, rtol=1e-10, atol=1e-12)


def test_the_lu_solve_solves_and_flags_a_singular_system() -> None:
    """An active-set system (unsymmetric, rows needing a pivot) is solved; one with a
    dependent row is flagged, for the minimum-norm solve, and its input left as it was."""
    rng = np.random.default_rng(2)
    A, rhs = rng.standard_normal((9, 9)), rng.standard_normal(9)
    A[0, 0] = 0.0  # the first pivot has to come from another row
    x, ok = lu_solve(A, rhs)
    assert ok
    np.testing.assert_allclose(A @ x, rhs, rtol=1e-10, atol=1e-12)
    singular = A.copy()
    singular[4] = 2.0 * singular[2]
    before = singular.copy()
    assert not lu_solve(singular, rhs)[1]
    assert np.array_equal(singular, before)

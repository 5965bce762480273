"""Input checks of :func:`pushctl.contact.mlcp.solve_box_mlcp`: one-line messages that say
what is wrong and what is accepted. The passing path is kept cheap (it runs per call)."""

from __future__ import annotations

import math

import numpy as np

from pushctl.errors import MLCPInputError


def validated_arrays(D, b, lo, hi, findex, mu, tol):
    """The inputs as arrays (D (n, n), b, lo, hi, mu float64 (n,), findex int (n,)), checked.

    The detailed messages are built only once something is wrong.
    """
    D = np.asarray(D, dtype=float)
    if D.ndim != 2 or D.shape[0] != D.shape[1]:
        raise MLCPInputError(f"D must be a square (n, n) array, got shape {D.shape}")
    n = D.shape[0]
    b = _vector(b, "b", n)
    lo = _vector(lo, "lo", n)
    hi = _vector(hi, "hi", n)
    mu = _vector(mu, "mu", n)
    fidx = _findex(findex, n)
    b_list = b.tolist()
    # A sum is finite iff every entry is (barring overflow, which the exact check settles).
    if not math.isfinite(D.sum() + sum(b_list)):
        for name, arr in (("D", D), ("b", b)):
            if not np.isfinite(arr).all():
                raise MLCPInputError(f"{name} must hold finite numbers only, got NaN or inf")
    if not (isinstance(tol, float | int) and 0.0 < tol < math.inf):
        raise MLCPInputError(f"tol must be a positive finite number, got {tol!r}")
    _check_rows(fidx.tolist(), lo.tolist(), hi.tolist(), mu.tolist())
    return np.ascontiguousarray(D), b, lo, hi, fidx.astype(np.int64, copy=False), mu


def _vector(v, name: str, n: int) -> np.ndarray:
    try:
        arr = np.asarray(v, dtype=float)
    except (TypeError, ValueError) as exc:
        raise MLCPInputError(f"{name} must be a numeric (n,) array with n = {n}: {exc}") from None
    if arr.shape != (n,):
        raise MLCPInputError(f"{name} must have shape ({n},) to match D, got {arr.shape}")
    return arr


def _findex(findex, n: int) -> np.ndarray:
    arr = np.asarray(findex)
    if arr.shape != (n,):
        raise MLCPInputError(f"findex must have shape ({n},) to match D, got {arr.shape}")
    if arr.dtype.kind not in "iu":
        if arr.dtype.kind != "f":
            raise MLCPInputError(f"findex must hold integers (-1 or a row index), got {arr.dtype}")
        for i, j in enumerate(arr.tolist()):
            if not (math.isfinite(j) and j == round(j)):
                raise MLCPInputError(f"findex[{i}] = {j} is not an integer: use -1 or a row index")
    arr = arr.astype(np.intp, copy=False)
    for i, j in enumerate(arr.tolist()):
        if not -1 <= j < n:
            raise MLCPInputError(
                f"findex[{i}] = {j} is out of range: use -1 (no friction) or 0..{n - 1}"
            )
    return arr


def _check_rows(fidx: list[int], lo: list[float], hi: list[float], mu: list[float]) -> None:
    """Per-row checks, in plain Python (cheaper than numpy at these sizes).

    Non-friction rows: no NaN, ``lo < +inf``, ``hi > -inf``, ``lo ≤ hi``. Friction rows: point
    at a distinct non-friction row with ``lo ≥ 0``, and have a finite ``mu ≥ 0``.
    """
    for i, j in enumerate(fidx):
        if j < 0:
            if not lo[i] < math.inf:
                raise MLCPInputError(
                    f"lo[{i}] = {lo[i]} is not a lower bound: use a number or -inf"
                )
            if not hi[i] > -math.inf:
                raise MLCPInputError(
                    f"hi[{i}] = {hi[i]} is not an upper bound: use a number or +inf"
                )
            if lo[i] > hi[i]:
                raise MLCPInputError(f"lo[{i}] = {lo[i]} > hi[{i}] = {hi[i]}: bounds need lo <= hi")
        elif i == j:
            raise MLCPInputError(
                f"findex[{i}] = {j} points at its own row: a friction row needs its normal row"
            )
        elif fidx[j] >= 0:
            raise MLCPInputError(
                f"findex[{i}] = {j} points at friction row {j}: it must point at a normal "
                "row (one with findex -1)"
            )
        elif not lo[j] >= 0.0:
            raise MLCPInputError(
                f"findex[{i}] = {j} points at row {j} with lo = {lo[j]}: a normal row needs "
                "lo >= 0 so that mu*p_n is a bound"
            )
        elif not 0.0 <= mu[i] < math.inf:
            raise MLCPInputError(
                f"mu[{i}] = {mu[i]} on friction row {i}: friction coefficients must be "
                "finite and >= 0"
            )


def warm_vector(warm_start, n: int) -> np.ndarray:
    arr = _vector(warm_start, "warm_start", n)
    if not math.isfinite(sum(arr.tolist())):
        raise MLCPInputError("warm_start must hold finite numbers only, got NaN or inf")
    return arr

"""Argument checks shared by the core: one-line errors that say what is accepted."""

from __future__ import annotations

import math

import numpy as np

from pushctl.errors import StateError


def finite_vector(name: str, value, n: int) -> np.ndarray:
    """``value`` as a float64 vector (n,), else a StateError naming ``name``.

    A float64 array of the right shape is returned as is, not copied (the hot path of a
    simulation step); copy it if you keep it.
    """
    if type(value) is np.ndarray and value.shape == (n,) and value.dtype == np.float64:
        array = value
    else:
        accepted = f"{name} must be a finite vector of length {n}"
        try:
            array = np.array(value, dtype=float)
        except (TypeError, ValueError):
            raise StateError(f"{accepted}, got {type(value).__name__} {value!r:.40}") from None
        if array.shape != (n,):
            raise StateError(f"{accepted}, got shape {array.shape}")
    # A finite sum of the entries means none is NaN or ±inf (for these short vectors a
    # Python sum is cheaper than isfinite(...).all()); otherwise the full check decides (the
    # sum may also have overflowed).
    if not math.isfinite(sum(array.tolist())) and not np.isfinite(array).all():
        bad = int(np.flatnonzero(~np.isfinite(array))[0])
        raise StateError(
            f"{name} must be a finite vector of length {n}, got {array[bad]} at index {bad}"
        )
    return array

"""Arrays for a world step's results, taken again once nothing outside the world holds them.

Every world step hands out new arrays: a :class:`~pushctl.types.StepResult` shares the
world's state arrays and an :class:`~pushctl.arm.ArmTerms` its arm terms, and a caller may
keep either for as long as it likes, so a step never writes into an array it handed out
before. Making them costs a step seventeen ``np.empty`` calls (docs/performance.md). Most
callers read a step's arrays and drop them
(the episode copies them into its trace), so by the step after next they are garbage.

:class:`ArrayRecycler` gives a step the arrays of the step before the previous one when no
reference to any of them is left outside the recycler (CPython's reference count, the test
numpy itself uses to reuse temporaries), else new ones. Whatever a caller still holds is
never written again; a step's kernels write every element of the arrays they are given,
so a taken array's old contents never reach a result (the same bits: tests/contact/).

It rests on CPython's reference counting, so it is off unless asked for:
:func:`set_recycling` turns it on for the process (a world step about 7 % faster:
docs/performance.md). Off, every step makes new arrays; the bits are the same either way.
"""

from __future__ import annotations

import sys

import numpy as np

_references = sys.getrefcount


def _all_free(arrays: tuple[np.ndarray, ...], free: int) -> bool:
    """Whether every array in ``arrays`` has ``free`` references (the tuple's and this
    call's own only)."""
    for array in arrays:
        if _references(array) != free:
            return False
    return True


def _calibrate() -> int:
    """An array's reference count as :func:`_all_free` sees it when only its tuple holds
    it, found on the same path at import (so it follows the interpreter's own counting)."""
    probe = (np.empty(0),)
    for count in range(1, 8):
        if _all_free(probe, count):
            return count
    raise RuntimeError("cannot calibrate the array recycler's reference count")


_FREE = _calibrate()
_recycling = False


def set_recycling(enabled: bool) -> bool:
    """Whether :meth:`ArrayRecycler.take` may hand a step's arrays out again (default: no,
    new arrays every step); returns the previous setting."""
    global _recycling
    previous, _recycling = _recycling, bool(enabled)
    return previous


class ArrayRecycler:
    """Sets of new-or-free arrays of fixed ``shapes`` (float64), one set per :meth:`take`.

    Two sets alternate: the one a step took stays the world's while the next step runs, and
    the step after next gets it back if nothing else holds any of its arrays."""

    def __init__(self, shapes: tuple[tuple[int, ...], ...]) -> None:
        self._shapes = shapes
        self._newer: tuple[np.ndarray, ...] | None = None
        self._older: tuple[np.ndarray, ...] | None = None

    def take(self) -> tuple[np.ndarray, ...]:
        """Arrays for this step, uninitialised (the caller writes every element): new ones
        unless :func:`set_recycling` turned recycling on."""
        if not _recycling:
            return tuple(map(np.empty, self._shapes))
        spare, self._older = self._older, self._newer
        if spare is None or not _all_free(spare, _FREE):
            spare = tuple(map(np.empty, self._shapes))
        self._newer = spare
        return spare

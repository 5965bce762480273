"""The world step's two compiled kernels called past numba's dispatcher.

numba's dispatcher types every argument of a call before it enters the compiled code, about
35 ns an argument. The world step's two kernels take 29 (``slip_step``) and 24 (the step
end, ``native_arm_moved``; 28 with a nominal frame) arguments: 1–2 µs of a 22–29 µs world
step (docs/reproducibility-and-speed.md, twenty-second pass). The types do not change from
step to step, so a world resolves each kernel's compiled entry point once, from its first
call's arguments (:func:`entry_point`), and calls that: the same machine code, so the same
bits.

The entry point does not check its arguments: it reads each array with the dtype, number of
dimensions and layout it was compiled for. A world passes only arrays it made itself (float64,
C-contiguous) and the caller's torque, which :meth:`World._check_command` makes C-contiguous.
With ``PUSHCTL_CHECK_CALLS=1`` in the environment (the test suite sets it, for its
subprocesses too) every call is checked against the types it was resolved for, and a
mismatch raises.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

from numba._dispatcher import compute_fingerprint
from numba.core import types
from numba.core.dispatcher import Dispatcher
from numba.core.typing.typeof import Purpose, typeof

CHECK_CALLS = os.environ.get("PUSHCTL_CHECK_CALLS") == "1"
"""Check every direct call's argument types (the test suite's setting; 2.3 µs for 29 arguments)."""


def argument_types(args: tuple) -> tuple:
    """numba's types of ``args``, as its dispatcher finds them for a call."""
    return tuple(typeof(arg, Purpose.argument) for arg in args)


def _as_read(kind: Any) -> Any:
    """``kind`` without its mutability: an entry point reads a read-only array of its dtype,
    dimensions and layout as it reads a writeable one."""
    return kind.copy(readonly=False) if isinstance(kind, types.Array) else kind


def entry_point(kernel: Dispatcher, args: tuple) -> Callable[..., Any]:
    """``kernel``'s compiled entry point for the types of ``args`` (compiled, or loaded from
    numba's disk cache, if it has not been yet); with :data:`CHECK_CALLS`, a function that
    checks each call's argument types against them first. A ``kernel`` that is not compiled
    (a test's wrapper around one) is returned as it is."""
    if not isinstance(kernel, Dispatcher):
        return kernel
    kinds = argument_types(args)
    entry = kernel.compile(kinds)
    if not CHECK_CALLS:
        return entry
    name, prints = kernel.py_func.__name__, tuple(map(compute_fingerprint, args))

    def checked(*call_args: Any) -> Any:
        # the dispatcher's own fingerprints first (0.1 µs an argument; typeof takes 6 µs
        # an array): only where they differ are the types compared
        if tuple(map(compute_fingerprint, call_args)) != prints:
            _check_types(name, argument_types(call_args), kinds)
        return entry(*call_args)

    return checked


def _check_types(name: str, found: tuple, kinds: tuple) -> None:
    """Raise TypeError unless the types ``found`` of a call of kernel ``name`` are the types
    ``kinds`` its entry point was resolved for, mutability aside."""
    if len(found) != len(kinds):
        raise TypeError(f"{name} called directly with {len(found)} arguments, not {len(kinds)}")
    wrong = [
        i for i, (a, b) in enumerate(zip(found, kinds, strict=True)) if _as_read(a) != _as_read(b)
    ]
    if wrong:
        raise TypeError(
            f"{name} called directly with arguments {wrong} of types "
            f"{[found[i] for i in wrong]}, resolved for {[kinds[i] for i in wrong]}"
        )

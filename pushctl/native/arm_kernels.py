"""The numba side of the compiled arm terms: :func:`native_terms` and
:func:`native_terms_nominal` call the library's ``pushctl_arm_terms`` (``arm_terms.cpp``)
by its symbol, in :func:`arm_pass`; ``pushctl.contact.compiled.step_end`` calls that and
``pushctl_arm_integrate`` too.

:func:`native_terms` is :func:`native_terms_nominal` without the nominal pusher's frame.
Declaring a symbol needs nothing; compiling or loading a kernel that calls it needs the
library loaded first (:func:`pushctl.native.available`), which is why these are called only
by code that holds a :class:`~pushctl.native.NativeArm`.
"""

from __future__ import annotations

import numpy as np
from numba import njit, types

_ptr = types.voidptr
_arm_terms = types.ExternalFunction(
    "pushctl_arm_terms",
    types.void(
        _ptr, _ptr, _ptr, types.int64, _ptr, types.int64, types.int64,  # handle … nominal
        _ptr, _ptr, _ptr,  # M, nle, g
        _ptr, _ptr,  # prong positions, Jacobians
        _ptr, _ptr, _ptr,  # pusher position, rotation, Jacobian
        _ptr, _ptr, _ptr,  # nominal pusher position, rotation, Jacobian
    ),
)  # fmt: skip
_arm_integrate = types.ExternalFunction(
    "pushctl_arm_integrate", types.void(_ptr, _ptr, _ptr, types.float64, _ptr)
)


@njit(cache=True)
def native_terms(
    handle, q, v, prongs, pusher, M, nle, g, prong_positions, prong_jacobians, pusher_position,
    pusher_rotation, pusher_jacobian,
):  # fmt: skip  # pragma: no cover - compiled
    """Arm terms at (q (nq,), v (nv,)) [rad, rad/s] of the model at ``handle``, its frames
    ``prongs`` (k,) int64 and ``pusher``, written into the caller's arrays: M (nv, nv),
    nle (nv,), g (nv,), prong positions (k, 3), prong Jacobians (k, 3, nv), pusher position
    (3,), rotation (3, 3), Jacobian (6, nv); units as in :class:`~pushctl.arm.ArmTerms`.

    Written into arrays made by ``np.empty`` in Python, not returned: numba's boxing of a
    returned array cost more than making one and passing it in (measured)."""
    native_terms_nominal(
        handle, q, v, prongs, pusher, -1, M, nle, g, prong_positions, prong_jacobians,
        pusher_position, pusher_rotation, pusher_jacobian, np.empty(0), np.empty((0, 3)),
        np.empty((0, M.shape[0])),
    )  # fmt: skip


@njit(cache=True)
def native_terms_nominal(
    handle, q, v, prongs, pusher, nominal, M, nle, g, prong_positions, prong_jacobians,
    pusher_position, pusher_rotation, pusher_jacobian, nominal_position, nominal_rotation,
    nominal_jacobian,
):  # fmt: skip  # pragma: no cover - compiled
    """:func:`native_terms` and the frame ``nominal``'s position (3,), rotation (3, 3) and
    Jacobian (6, nv), written into the three arrays after the eight (``nominal`` −1: none,
    and those three are empty)."""
    q = np.ascontiguousarray(q).astype(np.float64)  # the library reads raw float64 memory
    v = np.ascontiguousarray(v).astype(np.float64)
    arm_pass(
        handle, q, v, prongs, pusher, nominal, M, nle, g, prong_positions, prong_jacobians,
        pusher_position, pusher_rotation, pusher_jacobian, nominal_position, nominal_rotation,
        nominal_jacobian,
    )  # fmt: skip


@njit(cache=True)
def arm_pass(
    handle, q, v, prongs, pusher, nominal, M, nle, g, prong_positions, prong_jacobians,
    pusher_position, pusher_rotation, pusher_jacobian, nominal_position, nominal_rotation,
    nominal_jacobian,
):  # fmt: skip  # pragma: no cover - compiled
    """The library's pass at (q, v), contiguous float64 arrays as they are, into the arrays
    after them (``nominal`` −1: the nominal frame's are empty). :func:`native_terms_nominal`
    makes its q and v so first; the world's step end (``pushctl.contact.compiled.step_end``) has
    them so."""
    _arm_terms(
        handle, q.ctypes, v.ctypes, prongs.size, prongs.ctypes, pusher, nominal,
        M.ctypes, nle.ctypes, g.ctypes, prong_positions.ctypes, prong_jacobians.ctypes,
        pusher_position.ctypes, pusher_rotation.ctypes, pusher_jacobian.ctypes,
        nominal_position.ctypes, nominal_rotation.ctypes, nominal_jacobian.ctypes,
    )  # fmt: skip

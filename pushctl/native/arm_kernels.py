"""The numba side of the compiled arm terms: :func:`native_terms` and
:func:`native_terms_nominal` call the library's ``pushctl_arm_terms`` (``arm_terms.cpp``)
by its symbol; ``pushctl.contact.step_end`` calls it and ``pushctl_arm_integrate`` too.

The pass lives in ``_terms``; its two callers differ only in what they return (the nominal
pusher's frame or not). Declaring a symbol needs nothing; compiling or loading a kernel
that calls it needs the library loaded first (:func:`pushctl.native.available`), which
is why these are called only by code that holds a :class:`~pushctl.native.NativeArm`.
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
def native_terms(handle, q, v, prongs, pusher):  # pragma: no cover - compiled
    """Arm terms at (q (nq,), v (nv,)) [rad, rad/s] of the model at ``handle``, its frames
    ``prongs`` (k,) int64 and ``pusher``. Returns fresh arrays: M (nv, nv), nle (nv,),
    g (nv,), prong positions (k, 3), prong Jacobians (k, 3, nv), pusher position (3,),
    rotation (3, 3), Jacobian (6, nv); units as in :class:`~pushctl.arm.ArmTerms`.

    Eight arrays, not eleven with the nominal pusher's empty ones: each returned array
    costs about half a microsecond of boxing (measured)."""
    terms, nominal = _terms(handle, q, v, prongs, pusher, -1)
    return terms


@njit(cache=True)
def native_terms_nominal(handle, q, v, prongs, pusher, nominal):  # pragma: no cover
    """:func:`native_terms` and the frame ``nominal``'s position (3,), rotation (3, 3) and
    Jacobian (6, nv): a tuple of the eight, then a tuple of those three."""
    return _terms(handle, q, v, prongs, pusher, nominal)


@njit(cache=True)
def _terms(handle, q, v, prongs, pusher, nominal):  # pragma: no cover - compiled
    q = np.ascontiguousarray(q).astype(np.float64)  # the library reads raw float64 memory
    v = np.ascontiguousarray(v).astype(np.float64)
    nv = v.size
    k = prongs.size
    M = np.empty((nv, nv))
    nle = np.empty(nv)
    g = np.empty(nv)
    prong_positions = np.empty((k, 3))
    prong_jacobians = np.empty((k, 3, nv))
    pusher_position = np.empty(3)
    pusher_rotation = np.empty((3, 3))
    pusher_jacobian = np.empty((6, nv))
    rows = 1 if nominal >= 0 else 0
    nominal_position = np.empty(3 * rows)
    nominal_rotation = np.empty((3 * rows, 3))
    nominal_jacobian = np.empty((6 * rows, nv))
    _arm_terms(
        handle, q.ctypes, v.ctypes, k, prongs.ctypes, pusher, nominal,
        M.ctypes, nle.ctypes, g.ctypes, prong_positions.ctypes, prong_jacobians.ctypes,
        pusher_position.ctypes, pusher_rotation.ctypes, pusher_jacobian.ctypes,
        nominal_position.ctypes, nominal_rotation.ctypes, nominal_jacobian.ctypes,
    )  # fmt: skip
    terms = (
        M, nle, g, prong_positions, prong_jacobians, pusher_position, pusher_rotation,
        pusher_jacobian,
    )  # fmt: skip
    return terms, (nominal_position, nominal_rotation, nominal_jacobian)

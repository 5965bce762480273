"""Compiled kernels of the end of a world step, after the arm moved: the energy check of
its integration and the prongs' contact geometry at the new state, in one call
(:func:`arm_moved`); with pushctl's compiled library, the integration and the arm's terms
at the new state too (:func:`native_arm_moved`), whose library calls are declared in
:mod:`pushctl.native.arm_kernels` (symbols, not kernels: nothing there is compiled into
these).

Kept in a file of their own: numba's disk cache is invalidated per source file and does not
follow calls into other files, so a kernel and every kernel it calls live together
(:mod:`pushctl.contact.kernels`). :mod:`pushctl.contact.rows` and
:mod:`pushctl.contact.kernels` re-export :func:`prong_geometry` and
:func:`coriolis_energy_error`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from pushctl.native.arm_kernels import _arm_integrate, _arm_terms


@njit(cache=True)
def arm_moved(
    ledger, v_new, M_old, nle_old, g_old, M_new, h, edges, pose, prong_positions, margin
):  # fmt: skip
    """:func:`coriolis_energy_error` of the arm's step, then :func:`prong_geometry` at the
    new state: one compiled call instead of two (each costs about a microsecond of dispatch
    and boxing from Python). Returns ``(ledger, energy, geometry, gaps, mask)``."""
    ledger, energy = coriolis_energy_error(ledger, v_new, M_old, nle_old, g_old, M_new, h)
    geometry, gaps, mask = prong_geometry(edges, pose, prong_positions, margin)
    return ledger, energy, geometry, gaps, mask


@njit(cache=True)
def native_arm_moved(
    handle, q, v_new, h, prongs, pusher, ledger, M_old, nle_old, g_old, edges, pose, margin
):  # fmt: skip  # pragma: no cover - compiled
    """The arm's whole step end in one compiled call, through pushctl's compiled library
    (:mod:`pushctl.native`): ``q`` moved by ``v_new`` for ``h`` (``ArmModel.integrate``),
    the arm terms at the new state (``ArmModel.compute``, frames ``prongs`` and ``pusher``),
    then :func:`arm_moved`. The same library calls and arithmetic as those three calls from
    Python, so the same bits. Returns ``(q_new, terms, ledger, energy, geometry, gaps,
    mask)``, ``terms`` the eight arrays of an :class:`~pushctl.arm.ArmTerms`."""
    q_new, terms, nominal = _moved_terms(handle, q, v_new, h, prongs, pusher, -1)
    ledger, energy = coriolis_energy_error(ledger, v_new, M_old, nle_old, g_old, terms[0], h)
    geometry, gaps, mask = prong_geometry(edges, pose, terms[3], margin)
    return q_new, terms, ledger, energy, geometry, gaps, mask


@njit(cache=True)
def native_arm_moved_nominal(
    handle, q, v_new, h, prongs, pusher, nominal, ledger, M_old, nle_old, g_old, edges, pose,
    margin,
):  # fmt: skip  # pragma: no cover - compiled
    """:func:`native_arm_moved` for an arm whose frame ``nominal`` (the nominal pusher) is
    placed in the same pass: its position, rotation and Jacobian follow ``terms``."""
    q_new, terms, nominal_frame = _moved_terms(handle, q, v_new, h, prongs, pusher, nominal)
    ledger, energy = coriolis_energy_error(ledger, v_new, M_old, nle_old, g_old, terms[0], h)
    geometry, gaps, mask = prong_geometry(edges, pose, terms[3], margin)
    return q_new, terms, nominal_frame, ledger, energy, geometry, gaps, mask


@njit(cache=True)
def _moved_terms(handle, q, v_new, h, prongs, pusher, nominal):  # pragma: no cover
    """q⁺ and the library's pass at (q⁺, v⁺): ``pushctl.native.arm_kernels._terms``'s
    arrays (repeated here: numba's cache does not follow calls into another file)."""
    q = np.ascontiguousarray(q)
    v = np.ascontiguousarray(v_new)
    nv = v.size
    k = prongs.size
    q_new = np.empty(q.size)
    _arm_integrate(handle, q.ctypes, v.ctypes, h, q_new.ctypes)
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
        handle, q_new.ctypes, v.ctypes, k, prongs.ctypes, pusher, nominal,
        M.ctypes, nle.ctypes, g.ctypes, prong_positions.ctypes, prong_jacobians.ctypes,
        pusher_position.ctypes, pusher_rotation.ctypes, pusher_jacobian.ctypes,
        nominal_position.ctypes, nominal_rotation.ctypes, nominal_jacobian.ctypes,
    )  # fmt: skip
    terms = (
        M, nle, g, prong_positions, prong_jacobians, pusher_position, pusher_rotation,
        pusher_jacobian,
    )  # fmt: skip
    return q_new, terms, (nominal_position, nominal_rotation, nominal_jacobian)


@njit(cache=True)
def coriolis_energy_error(ledger, v_new, M_old, nle_old, g_old, M_new, h):
    """Add one step's Coriolis energy error to ``ledger`` [J]; return it and the new
    kinetic energy ``½ v⁺ᵀ M(q⁺) v⁺`` [J] (see ``World._advance_arm``).

    The error is ``½ v⁺ᵀ (M(q⁺) − M(q)) v⁺ − h v⁺ᵀ C(q, v) v``, with ``C(q, v) v = nle − g``.
    """
    energy = 0.5 * (v_new @ (M_new @ v_new))
    error = energy - 0.5 * (v_new @ (M_old @ v_new)) - h * (v_new @ (nle_old - g_old))
    return ledger + error, energy


@njit(cache=True)
def prong_geometry(edges, pose, prong_positions, margin):
    """The geometry (p, 5) of the prongs nearer than ``margin`` (see :func:`prong_contacts`),
    every prong's gap (k,) and the bit mask of the prongs in contact, in one compiled call:
    the same arithmetic as :meth:`ConvexPolygon.query`, per prong."""
    x0, y0, theta = pose[0], pose[1], pose[2]
    c, s = math.cos(theta), math.sin(theta)
    k = prong_positions.shape[0]
    geometry = np.empty((k, 5))
    gaps = np.empty(k)
    for i in range(k):
        px, py = prong_positions[i, 0] - x0, prong_positions[i, 1] - y0
        gap, n_lx, n_ly, cl_x, cl_y = _query(edges, c * px + s * py, -s * px + c * py)
        gaps[i] = gap
        geometry[i, 0] = gap
        geometry[i, 1] = -(c * n_lx - s * n_ly)
        geometry[i, 2] = -(s * n_lx + c * n_ly)
        geometry[i, 3] = c * cl_x - s * cl_y
        geometry[i, 4] = s * cl_x + c * cl_y
    mask, p = 0, 0
    for i in range(k):
        if gaps[i] < margin:
            mask |= 1 << i
            geometry[p] = geometry[i]
            p += 1
    return geometry[:p].copy(), gaps, mask


@njit(cache=True)
def _query(edges, px, py):
    """:meth:`ConvexPolygon.query` on the edge records (V, 8), operation for operation."""
    best = -math.inf
    best_edge = 0
    for e in range(edges.shape[0]):
        s = edges[e, 4] * px + edges[e, 5] * py - edges[e, 6]
        if s > best:
            best, best_edge = s, e
    if best <= 0.0:
        nx, ny = edges[best_edge, 4], edges[best_edge, 5]
        return best, nx, ny, px - best * nx, py - best * ny
    best_d2 = math.inf
    cx = cy = 0.0
    for e in range(edges.shape[0]):
        ax, ay, tx, ty = edges[e, 0], edges[e, 1], edges[e, 2], edges[e, 3]
        nx, ny, offset, length = edges[e, 4], edges[e, 5], edges[e, 6], edges[e, 7]
        s = nx * px + ny * py - offset
        if s <= 0.0:
            continue
        u = (px - ax) * tx + (py - ay) * ty
        if 0.0 < u < length:
            return s, nx, ny, px - s * nx, py - s * ny
        u = 0.0 if u <= 0.0 else length
        qx, qy = ax + u * tx, ay + u * ty
        d2 = (px - qx) * (px - qx) + (py - qy) * (py - qy)
        if d2 < best_d2:
            best_d2, cx, cy = d2, qx, qy
    distance = math.sqrt(best_d2)
    if distance == 0.0:
        return 0.0, edges[best_edge, 4], edges[best_edge, 5], px, py
    return distance, (px - cx) / distance, (py - cy) / distance, cx, cy

"""Compiled kernels of the end of a world step, after the arm moved: the energy check of
its integration and the prongs' contact geometry at the new state, in one call
(:func:`arm_moved`); with pushctl's compiled library, the integration and the arm's terms
at the new state too (:func:`native_arm_moved`), whose library calls are declared in
:mod:`pushctl.native.arm_kernels` (symbols, not kernels: nothing there is compiled into
these).

:mod:`pushctl.contact.rows` calls :func:`prong_geometry`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from pushctl.native.arm_kernels import _arm_integrate, arm_pass


@njit(cache=True)
def arm_moved(
    ledger, v_new, M_old, nle_old, g_old, M_new, h, edges, pose, prong_positions, margin
):  # fmt: skip
    """:func:`coriolis_energy_error` of the arm's step, then :func:`prong_geometry` at the
    new state: one compiled call instead of two (each pays numba's dispatch and boxing
    from Python). Returns ``(ledger, energy, geometry, gaps, mask)``."""
    ledger, energy = coriolis_energy_error(ledger, v_new, M_old, nle_old, g_old, M_new, h)
    geometry, gaps, mask = prong_geometry(edges, pose, prong_positions, margin)
    return ledger, energy, geometry, gaps, mask


@njit(cache=True)
def native_arm_moved(
    handle, q, v_new, h, prongs, pusher, ledger, M_old, nle_old, g_old, edges, pose, margin,
    q_new, M, nle, g, prong_positions, prong_jacobians, pusher_position, pusher_rotation,
    pusher_jacobian, geometry, gaps,
):  # fmt: skip  # pragma: no cover - compiled
    """The arm's whole step end in one compiled call, through pushctl's compiled library
    (:mod:`pushctl.native`): ``q`` moved by ``v_new`` for ``h`` (``ArmModel.integrate``),
    the arm terms at the new state (``ArmModel.compute``, frames ``prongs`` and ``pusher``),
    then :func:`arm_moved`. The same library calls and arithmetic as those three calls from
    Python, so the same bits.

    Writes into the arrays the caller passes (``q_new`` (nq,), the eight of an
    :class:`~pushctl.arm.ArmTerms` and ``geometry`` (k, 5), ``gaps`` (k,)) instead of
    returning new ones: numba boxes a returned array at several times the cost of one made
    by ``np.empty`` in Python and passed in (eleven a step; docs/performance.md).
    Returns ``(ledger, energy, contacts, mask)``:
    the first ``contacts`` rows of ``geometry`` are the prongs in contact."""
    return native_arm_moved_nominal(
        handle, q, v_new, h, prongs, pusher, -1, ledger, M_old, nle_old, g_old, edges, pose,
        margin, q_new, M, nle, g, prong_positions, prong_jacobians, pusher_position,
        pusher_rotation, pusher_jacobian, np.empty(0), np.empty((0, 3)),
        np.empty((0, M.shape[0])), geometry, gaps,
    )  # fmt: skip


@njit(cache=True)
def native_arm_moved_nominal(
    handle, q, v_new, h, prongs, pusher, nominal, ledger, M_old, nle_old, g_old, edges, pose,
    margin, q_new, M, nle, g, prong_positions, prong_jacobians, pusher_position,
    pusher_rotation, pusher_jacobian, nominal_position, nominal_rotation, nominal_jacobian,
    geometry, gaps,
):  # fmt: skip  # pragma: no cover - compiled
    """:func:`native_arm_moved` for an arm whose frame ``nominal`` (the nominal pusher) is
    placed in the same pass: its position (3,), rotation (3, 3) and Jacobian (6, nv) are
    written too (``nominal`` −1: none, and those three are empty). q⁺ goes into ``q_new``,
    and the library's pass (:func:`arm_pass`) runs at (q⁺, v⁺) without copies of q and v
    (``astype``), which a world step's float64 arrays do not need."""
    q = np.ascontiguousarray(q)
    v = np.ascontiguousarray(v_new)
    _arm_integrate(handle, q.ctypes, v.ctypes, h, q_new.ctypes)
    arm_pass(
        handle, q_new, v, prongs, pusher, nominal, M, nle, g, prong_positions, prong_jacobians,
        pusher_position, pusher_rotation, pusher_jacobian, nominal_position, nominal_rotation,
        nominal_jacobian,
    )  # fmt: skip
    ledger, energy = coriolis_energy_error(ledger, v_new, M_old, nle_old, g_old, M, h)
    contacts, mask = prong_geometry_into(edges, pose, prong_positions, margin, geometry, gaps)
    return ledger, energy, contacts, mask


@njit(cache=True)
def coriolis_energy_error(ledger, v_new, M_old, nle_old, g_old, M_new, h):
    """Add one step's Coriolis energy error to ``ledger`` [J]; return it and the new
    kinetic energy ``½ v⁺ᵀ M(q⁺) v⁺`` [J] (see ``World._advance_arm``).

    The error is ``½ v⁺ᵀ (M(q⁺) − M(q)) v⁺ − h v⁺ᵀ C(q, v) v``, with ``C(q, v) v = nle − g``;
    the products are loops (no BLAS calls: :mod:`pushctl.contact.compiled.assembly`).
    """
    n = v_new.shape[0]
    new_e = old_e = work = 0.0
    for i in range(n):
        a = b = 0.0
        for j in range(n):
            a += M_new[i, j] * v_new[j]
            b += M_old[i, j] * v_new[j]
        new_e += v_new[i] * a
        old_e += v_new[i] * b
        work += v_new[i] * (nle_old[i] - g_old[i])
    energy = 0.5 * new_e
    error = energy - 0.5 * old_e - h * work
    return ledger + error, energy


@njit(cache=True)
def prong_geometry(edges, pose, prong_positions, margin):
    """The geometry (p, 5) of the prongs nearer than ``margin`` (see :func:`prong_contacts`),
    every prong's gap (k,) and the bit mask of the prongs in contact, in one compiled call:
    the same arithmetic as :meth:`ConvexPolygon.query`, per prong."""
    k = prong_positions.shape[0]
    geometry, gaps = np.empty((k, 5)), np.empty(k)
    contacts, mask = prong_geometry_into(edges, pose, prong_positions, margin, geometry, gaps)
    return geometry[:contacts].copy(), gaps, mask


@njit(cache=True)
def prong_geometry_into(edges, pose, prong_positions, margin, geometry, gaps):
    """:func:`prong_geometry` into ``geometry`` (k, 5) and ``gaps`` (k,): returns (the
    number p of prongs in contact, whose rows come first in ``geometry``, the mask)."""
    x0, y0, theta = pose[0], pose[1], pose[2]
    c, s = math.cos(theta), math.sin(theta)
    k = prong_positions.shape[0]
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
    return p, mask


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

"""Compiled kernels of the end of a world step, after the arm moved: the energy check of
its integration and the prongs' contact geometry at the new state, in one call.

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

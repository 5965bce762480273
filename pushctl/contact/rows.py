"""Constraint rows of the world step: prong contacts and ground friction (docs/design.md §3).

Each row maps the generalised velocity ``v = [q̇_arm (nv); v_obj (3)]`` to one constraint
velocity; the impulse of the row acts along the same direction (``Aᵀ p``). Object columns are
``(vx, vy, ω)`` in the world frame, so a direction ``e`` at offset ``r`` from the centre of
mass has object part ``(e_x, e_y, r × e)``. Rows: per prong in contact a normal and a
tangential row, then per support point a row along its slip and one across it.

:func:`prong_contacts` finds the prongs' contact geometry; the rows themselves are assembled
in compiled code, :func:`pushctl.contact.kernels.assemble`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from pushctl.objects.geometry import ConvexPolygon


def edge_array(polygon: ConvexPolygon) -> np.ndarray:
    """The polygon's edge records (V, 8) as one array, for :func:`prong_geometry`."""
    return np.ascontiguousarray(np.array(polygon.edges, dtype=float).reshape(-1, 8))


def prong_contacts(
    polygon: ConvexPolygon,
    pose: np.ndarray,
    prong_positions: np.ndarray,
    margin: float,
    edges: np.ndarray | None = None,
) -> tuple[tuple[int, ...], np.ndarray, np.ndarray]:
    """The prongs nearer than ``margin`` [m] to the object's footprint, and their geometry.

    ``pose`` (3,) object (x, y, θ); ``prong_positions`` (k, 3) [m] world; ``edges``
    (V, 8): :func:`edge_array` of ``polygon``, precomputed by a caller that queries often.
    Returns the indices of the prongs in contact, their geometry (p, 5) — gap [m] (signed
    distance, negative inside), e_n (2,) into the object (minus the outward normal of the
    nearest feature) and r (2,) [m] from the centre of mass to the contact point, world
    axes — and every prong's gap (k,).
    """
    if edges is None:
        edges = edge_array(polygon)
    geometry, gaps, mask = prong_geometry(edges, pose, prong_positions, margin)
    return _MASKS.get(mask) or _indices(mask), geometry, gaps


def _indices(mask: int) -> tuple[int, ...]:
    """The set bits of ``mask``, lowest first."""
    return tuple(i for i in range(mask.bit_length()) if mask >> i & 1)


_MASKS = {mask: _indices(mask) for mask in range(1, 16)}
"""Prong index tuples of the contact masks of up to four prongs (no contact: the empty
tuple, which ``or`` sends to :func:`_indices`)."""


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

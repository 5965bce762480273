"""Constraint rows of the world step: prong contacts and ground friction (docs/design.md §3).

Each row maps the generalised velocity ``v = [q̇_arm (nv); v_obj (3)]`` to one constraint
velocity; the impulse of the row acts along the same direction (``Aᵀ p``). Object columns are
``(vx, vy, ω)`` in the world frame, so a direction ``e`` at offset ``r`` from the centre of
mass has object part ``(e_x, e_y, r × e)``. Rows: per prong in contact a normal and a
tangential row, then per support point a row along its slip and one across it.

:func:`prong_contacts` finds the prongs' contact geometry; the rows themselves are assembled
in compiled code, :func:`pushctl.contact.compiled.assembly.assemble`.
"""

from __future__ import annotations

import numpy as np

from pushctl.contact.compiled.step_end import prong_geometry
from pushctl.objects.geometry import ConvexPolygon

__all__ = ["PRONG_ROWS", "edge_array", "mask_indices", "prong_contacts", "prong_geometry"]


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
    return mask_indices(mask), geometry, gaps


def mask_indices(mask: int) -> tuple[int, ...]:
    """The prongs (indices, lowest first) of a contact bit mask of :func:`prong_geometry`."""
    indices = _MASKS.get(mask)
    return _indices(mask) if indices is None else indices


def _indices(mask: int) -> tuple[int, ...]:
    """The set bits of ``mask``, lowest first."""
    return tuple(i for i in range(mask.bit_length()) if mask >> i & 1)


_MASKS = {mask: _indices(mask) for mask in range(16)}
"""Prong index tuples of the contact masks of up to four prongs (no contact, mask 0, too:
every step of an approach)."""

PRONG_ROWS = {prongs: np.array(prongs, dtype=np.intp) for prongs in _MASKS.values()}
"""The rows (index arrays) of each set of up to four prongs in contact (or none), kept:
``take`` with one is faster than indexing with a fresh list (World._step_inputs)."""

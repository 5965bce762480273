"""Constraint rows of the world step: prong contacts and ground friction (DESIGN.md §3).

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

from pushctl.objects.geometry import ConvexPolygon


def prong_contacts(
    polygon: ConvexPolygon, pose: np.ndarray, prong_positions: np.ndarray, margin: float
) -> tuple[tuple[int, ...], np.ndarray, np.ndarray]:
    """The prongs nearer than ``margin`` [m] to the object's footprint, and their geometry.

    ``pose`` (3,) object (x, y, θ); ``prong_positions`` (k, 3) [m] world. Returns the indices
    of the prongs in contact, their geometry (p, 5) — gap [m] (signed distance, negative
    inside), e_n (2,) into the object (minus the outward normal of the nearest feature) and
    r (2,) [m] from the centre of mass to the contact point, world axes — and every prong's
    gap (k,).
    """
    x0, y0, theta = pose.tolist()
    c, s = math.cos(theta), math.sin(theta)
    prongs, geometry, gaps = [], [], []
    for i, (px, py, _) in enumerate(prong_positions.tolist()):
        px, py = px - x0, py - y0
        gap, n_lx, n_ly, cl_x, cl_y = polygon.query(c * px + s * py, -s * px + c * py)
        gaps.append(gap)
        if gap < margin:
            prongs.append(i)
            geometry.append(
                (
                    gap,
                    -(c * n_lx - s * n_ly),
                    -(s * n_lx + c * n_ly),
                    c * cl_x - s * cl_y,
                    s * cl_x + c * cl_y,
                )
            )
    return tuple(prongs), np.array(geometry, dtype=float).reshape(-1, 5), np.array(gaps)

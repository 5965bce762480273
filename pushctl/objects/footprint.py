"""Validation and normalisation of convex polygon footprints.

A footprint is a ``(V, 2)`` array of vertices [m] of a convex polygon in the table plane.
Users may give it clockwise or counter-clockwise; the core works with counter-clockwise
vertices, where edge ``i`` runs from vertex ``i`` to vertex ``(i + 1) % V`` and its outward
normal is the edge direction rotated by −90°.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from pushctl.errors import ConfigError

# Relative tolerance on cross products and areas, scaled by the polygon's size, below which
# a turn counts as straight and an area as zero.
_REL_TOL = 1e-9


def as_points(values: ArrayLike, what: str, *, min_count: int = 1) -> np.ndarray:
    """Check and convert ``values`` to a float array of shape ``(N, 2)`` [m].

    Raises :class:`ConfigError` naming ``what`` when the shape is wrong, there are fewer than
    ``min_count`` points, or a coordinate is not finite.
    """
    try:
        points = np.array(values, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"{what} must be a list of [x, y] pairs in metres ({exc})") from None
    if points.ndim != 2 or points.shape[1] != 2:
        raise ConfigError(
            f"{what} must be a list of [x, y] pairs in metres, got an array of shape {points.shape}"
        )
    if len(points) < min_count:
        raise ConfigError(f"{what} needs at least {min_count} points, got {len(points)}")
    if not np.all(np.isfinite(points)):
        raise ConfigError(f"{what} holds a NaN or infinite coordinate; give finite metres")
    return points


def signed_area(vertices: np.ndarray) -> float:
    """Signed area [m²] of the polygon ``vertices (V, 2)``: positive when counter-clockwise."""
    x, y = vertices[:, 0], vertices[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def normalise_footprint(footprint: ArrayLike) -> tuple[np.ndarray, bool]:
    """Validate a convex footprint and return it counter-clockwise.

    Args:
        footprint: ``(V, 2)`` vertices [m], V ≥ 3, clockwise or counter-clockwise.

    Returns:
        ``(vertices (V, 2), reversed)``: the counter-clockwise vertices and whether the input
        order was reversed to get them. When reversed, the input's vertex ``j`` is the
        output's vertex ``V − 1 − j``.

    Raises:
        ConfigError: fewer than 3 vertices, a repeated vertex, zero area, a non-convex or
            self-intersecting outline (naming the offending vertex).
    """
    vertices = as_points(footprint, "footprint", min_count=3)
    size = float(np.ptp(vertices, axis=0).max())
    edges = np.roll(vertices, -1, axis=0) - vertices
    lengths = np.hypot(edges[:, 0], edges[:, 1])
    for i in np.flatnonzero(lengths <= _REL_TOL * max(size, 1e-300)):
        j = (i + 1) % len(vertices)
        raise ConfigError(f"footprint vertex {j} repeats vertex {i}; give distinct vertices")
    area = signed_area(vertices)
    if abs(area) <= _REL_TOL * size**2:
        raise ConfigError(
            f"footprint is degenerate (area {abs(area):.3g} m²); give a polygon with positive area"
        )
    reversed_order = area < 0.0
    if reversed_order:
        vertices = vertices[::-1].copy()
    _check_convex(vertices, reversed_order)
    return vertices, reversed_order


def _check_convex(ccw: np.ndarray, reversed_order: bool) -> None:
    """Raise ConfigError unless every turn of ``ccw (V, 2)`` is left and it winds once."""
    n = len(ccw)
    edges = np.roll(ccw, -1, axis=0) - ccw
    incoming = np.roll(edges, 1, axis=0)  # edge arriving at vertex i
    cross = incoming[:, 0] * edges[:, 1] - incoming[:, 1] * edges[:, 0]
    dot = np.einsum("ij,ij->i", incoming, edges)
    lengths = np.hypot(edges[:, 0], edges[:, 1])
    scale = lengths * np.roll(lengths, 1)

    def user_index(i: int) -> int:
        return n - 1 - i if reversed_order else i

    for i in range(n):
        if cross[i] < -_REL_TOL * scale[i]:
            raise ConfigError(
                f"footprint is not convex at vertex {user_index(i)} (it turns the other way); "
                "give the vertices of a convex polygon in order"
            )
        if cross[i] <= _REL_TOL * scale[i]:
            raise ConfigError(
                f"footprint vertex {user_index(i)} is collinear with its neighbours "
                "(or folds back); remove it"
            )
    # All turns left but the outline may still wind around more than once (a star).
    turning = float(np.sum(np.arctan2(cross, dot)))
    if turning > 2.0 * math.pi + 1e-6:
        raise ConfigError(
            "footprint is self-intersecting (its outline winds around "
            f"{turning / (2.0 * math.pi):.0f} times); give a simple convex polygon"
        )


def outward_normals(ccw: np.ndarray) -> np.ndarray:
    """Unit outward normals ``(V, 2)`` of the edges of the counter-clockwise ``ccw (V, 2)``."""
    edges = np.roll(ccw, -1, axis=0) - ccw
    normals = np.column_stack((edges[:, 1], -edges[:, 0]))
    return normals / np.hypot(normals[:, 0], normals[:, 1])[:, None]


def default_pushed_face(ccw: np.ndarray) -> int:
    """Index of the edge of ``ccw (V, 2)`` whose outward normal points most along −x.

    Ties (within 1e-9) go to the lowest index, so the choice is reproducible.
    """
    facing = -outward_normals(ccw)[:, 0]
    return int(np.flatnonzero(facing >= facing.max() - 1e-9)[0])

"""Planar geometry of objects: point-versus-convex-polygon tests and frame transforms.

The signed distance runs every simulation step for every prong, so its kernel works on
plain Python floats over edge data precomputed once per polygon (:class:`ConvexPolygon`):
for V ≤ 8 edges this is several times faster than numpy, whose per-call overhead dominates
at these sizes.

Poses are planar ``(x, y, theta)`` [m, m, rad]: the object frame's origin in the world and
its rotation counter-clockwise about +z. A pose may be a sequence of three numbers or any
object with ``x``, ``y`` and ``theta`` attributes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike

from pushctl.objects.footprint import normalise_footprint


@dataclass(frozen=True, eq=False)
class ConvexPolygon:
    """Edge data of a counter-clockwise convex polygon, precomputed for fast queries.

    Build it with :meth:`from_vertices`. Edge ``i`` runs from vertex ``i`` to vertex
    ``i + 1``; each edge is stored as the float tuple
    ``(ax, ay, tx, ty, nx, ny, offset, length)``: start vertex [m], unit direction, unit
    outward normal, ``n · a`` [m] (the edge's line is ``n · p = offset``) and length [m].
    """

    vertices: np.ndarray
    edges: tuple[tuple[float, float, float, float, float, float, float, float], ...]

    @classmethod
    def from_vertices(cls, footprint: ArrayLike) -> ConvexPolygon:
        """Validate ``footprint (V, 2)`` [m] (either orientation) and precompute its edges."""
        ccw, _ = normalise_footprint(footprint)
        ccw.setflags(write=False)
        starts = ccw.tolist()
        records = []
        for (ax, ay), (bx, by) in zip(starts, starts[1:] + starts[:1], strict=True):
            length = math.hypot(bx - ax, by - ay)
            tx, ty = (bx - ax) / length, (by - ay) / length
            nx, ny = ty, -tx
            records.append((ax, ay, tx, ty, nx, ny, nx * ax + ny * ay, length))
        polygon = cls(vertices=ccw, edges=tuple(records))
        return polygon

    @property
    def normals(self) -> np.ndarray:
        """Unit outward edge normals, (V, 2)."""
        return np.array([e[4:6] for e in self.edges])

    @property
    def directions(self) -> np.ndarray:
        """Unit edge directions (counter-clockwise), (V, 2)."""
        return np.array([e[2:4] for e in self.edges])

    @property
    def lengths(self) -> np.ndarray:
        """Edge lengths, (V,) [m]."""
        return np.array([e[7] for e in self.edges])

    def query(self, px: float, py: float) -> tuple[float, float, float, float, float]:
        """Signed distance from the point ``(px, py)`` [m], as plain floats.

        Returns ``(distance, nx, ny, cx, cy)``: distance [m] (positive outside, negative
        inside), the outward unit normal of the nearest feature and the nearest boundary
        point [m]. See :func:`signed_distance`.
        """
        best = -math.inf
        best_edge = self.edges[0]
        for edge in self.edges:
            s = edge[4] * px + edge[5] * py - edge[6]
            if s > best:
                best, best_edge = s, edge
        if best <= 0.0:
            # Inside (or on the boundary): the face of least penetration. The foot of the
            # perpendicular lies on that face's segment because the polygon is convex.
            nx, ny = best_edge[4], best_edge[5]
            return best, nx, ny, px - best * nx, py - best * ny
        return self._outside(px, py, best_edge)

    def _outside(
        self, px: float, py: float, facing: tuple[float, ...]
    ) -> tuple[float, float, float, float, float]:
        """Nearest boundary feature of a point outside; ``facing`` is its most facing edge."""
        best_d2 = math.inf
        cx = cy = 0.0
        for ax, ay, tx, ty, nx, ny, offset, length in self.edges:
            s = nx * px + ny * py - offset
            if s <= 0.0:
                continue  # only edges that face the point can hold its nearest point
            u = (px - ax) * tx + (py - ay) * ty
            if 0.0 < u < length:
                # The outer Voronoi strips of a convex polygon's edges do not overlap with
                # each other or with the vertex wedges: this edge is the nearest feature.
                return s, nx, ny, px - s * nx, py - s * ny
            u = 0.0 if u <= 0.0 else length
            qx, qy = ax + u * tx, ay + u * ty
            d2 = (px - qx) ** 2 + (py - qy) ** 2
            if d2 < best_d2:
                best_d2, cx, cy = d2, qx, qy
        distance = math.sqrt(best_d2)
        if distance == 0.0:
            # On a vertex, outside only by rounding: no direction to the point exists.
            return 0.0, facing[4], facing[5], px, py
        return distance, (px - cx) / distance, (py - cy) / distance, cx, cy


class Shaped(Protocol):
    """Anything with a footprint and its precomputed edge data, such as an
    :class:`~pushctl.objects.spec.ObjectSpec` (named structurally, so this module, which
    the spec builds on, does not import it back)."""

    @property
    def footprint(self) -> np.ndarray: ...

    @property
    def polygon(self) -> ConvexPolygon: ...


def _as_polygon(shape: ConvexPolygon | Shaped | ArrayLike) -> ConvexPolygon:
    """The edge data of ``shape``: precomputed for a polygon or an ObjectSpec, else built."""
    if isinstance(shape, ConvexPolygon):
        return shape
    polygon = getattr(shape, "polygon", None)
    if isinstance(polygon, ConvexPolygon):
        return polygon
    return ConvexPolygon.from_vertices(shape)  # type: ignore[arg-type]


def signed_distance(
    shape: ConvexPolygon | Shaped | ArrayLike, point: ArrayLike
) -> tuple[float, np.ndarray, np.ndarray]:
    """Signed distance from a point to a convex polygon, with the nearest feature.

    Args:
        shape: the polygon: a :class:`ConvexPolygon` or an ``ObjectSpec`` (their edges are
            precomputed: the fast path), or vertices ``(V, 2)`` [m] (validated and
            preprocessed on every call, so slower).
        point: ``(2,)`` [m], in the polygon's frame.

    Returns:
        ``(distance, normal (2,), closest (2,))``: distance [m], positive outside and
        negative inside; the OUTWARD unit normal of the nearest feature (outside: from the
        nearest boundary point towards the point, which in a vertex region is the
        vertex→point direction; inside or on the boundary: the normal of the face of least
        penetration); the nearest boundary point [m].
    """
    px, py = np.asarray(point, dtype=float).tolist()
    d, nx, ny, cx, cy = _as_polygon(shape).query(px, py)
    return d, np.array((nx, ny)), np.array((cx, cy))


def signed_distance_batch(
    shape: ConvexPolygon | Shaped | ArrayLike, points: ArrayLike
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`signed_distance` for ``points (k, 2)`` [m].

    Returns ``(distance (k,), normal (k, 2), closest (k, 2))``.
    """
    polygon = _as_polygon(shape)
    rows = [polygon.query(px, py) for px, py in np.asarray(points, dtype=float).tolist()]
    out = np.array(rows, dtype=float).reshape(-1, 5)
    return out[:, 0], out[:, 1:3], out[:, 3:5]


def pose_components(pose: Any) -> tuple[float, float, float]:
    """``(x, y, theta)`` [m, m, rad] of a sequence of three numbers or a pose object."""
    if hasattr(pose, "theta"):
        return float(pose.x), float(pose.y), float(pose.theta)
    x, y, theta = (float(v) for v in pose)
    return x, y, theta


def rotation(theta: float) -> np.ndarray:
    """Planar rotation matrix ``(2, 2)`` by ``theta`` [rad] counter-clockwise."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array(((c, -s), (s, c)))


def to_world(pose: Any, points_local: ArrayLike) -> np.ndarray:
    """Map points ``(2,)`` or ``(N, 2)`` [m] from the object frame at ``pose`` to the world."""
    x, y, theta = pose_components(pose)
    return np.asarray(points_local, dtype=float) @ rotation(theta).T + (x, y)


def to_local(pose: Any, points_world: ArrayLike) -> np.ndarray:
    """Map points ``(2,)`` or ``(N, 2)`` [m] from the world to the object frame at ``pose``."""
    x, y, theta = pose_components(pose)
    return (np.asarray(points_world, dtype=float) - (x, y)) @ rotation(theta)


def vectors_to_world(pose: Any, vectors_local: ArrayLike) -> np.ndarray:
    """Rotate (not translate) vectors ``(2,)`` or ``(N, 2)`` from the object frame to the world."""
    return np.asarray(vectors_local, dtype=float) @ rotation(pose_components(pose)[2]).T


def vectors_to_local(pose: Any, vectors_world: ArrayLike) -> np.ndarray:
    """Rotate (not translate) vectors ``(2,)`` or ``(N, 2)`` from the world to the object frame."""
    return np.asarray(vectors_world, dtype=float) @ rotation(pose_components(pose)[2])


def polygon_world(spec: Shaped, pose: Any) -> np.ndarray:
    """The footprint of ``spec`` placed at ``pose``: vertices ``(V, 2)`` [m] in the world."""
    return to_world(pose, spec.footprint)

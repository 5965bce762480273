"""A rigid planar slider: a convex polygon in its own pose frame, its mass properties and
the support points that carry its weight (the pressure prior).

The pose frame is the frame the user's poses refer to; it need not sit at the centroid
(the MIT push dataset's triangles have theirs at a corner's neighbour). Internally the
world works about the centroid; :class:`Slider` converts between the two.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from pushctl.errors import ConfigError
from pushctl.objects import ConvexPolygon
from pushctl.objects.footprint import normalise_footprint

GRAVITY = 9.81
"""[m/s²]"""


@dataclass(frozen=True)
class PressurePrior:
    """Where the slider's weight rests on the table: support points on a uniform square grid
    clipped to the footprint, loaded in static equilibrium.

    - ``count``: about how many grid points fall inside the footprint (the grid's density);
      at least 3.
    - ``rim_weight``: load profile ``∝ exp(rim_weight · ρ)``, ρ = distance from the centroid
      over the farthest point's; 0 is uniform pressure, > 0 loads the rim (more torsional
      friction), < 0 the centre. The loads are then moved, by the least change, to put the
      centre of pressure exactly on the centroid (no moment at rest).
    """

    count: int = 16
    rim_weight: float = 0.0

    def __post_init__(self) -> None:
        if not (isinstance(self.count, int) and self.count >= 3):
            raise ConfigError(f"pressure prior count must be an integer >= 3, got {self.count!r}")
        if not math.isfinite(self.rim_weight) or abs(self.rim_weight) > 20:
            raise ConfigError(f"rim_weight must be finite, |w| <= 20, got {self.rim_weight!r}")


@dataclass(frozen=True, eq=False)
class Slider:
    """A uniform plate with a convex footprint.

    Args (construct with :meth:`from_vertices`):
        vertices: (V, 2) footprint [m] in the pose frame, counter-clockwise.
        mass: [kg].
        prior: the support points' pressure prior.

    Derived: ``centroid`` (2,) [m] in the pose frame, ``inertia`` about the centroid
    [kg·m²], ``polygon`` (edges about the centroid), ``supports`` (S, 2) [m] about the
    centroid and ``loads`` (S,) [N] summing to m g.
    """

    vertices: np.ndarray
    mass: float
    prior: PressurePrior
    centroid: np.ndarray = field(repr=False)
    inertia: float = field(repr=False)
    polygon: ConvexPolygon = field(repr=False)
    supports: np.ndarray = field(repr=False)
    loads: np.ndarray = field(repr=False)

    @classmethod
    def from_vertices(
        cls, vertices: ArrayLike, mass: float = 1.0, prior: PressurePrior | None = None
    ) -> Slider:
        """Validate a convex footprint (V, 2) [m] (either orientation) and derive the rest."""
        if not (math.isfinite(mass) and mass > 0):
            raise ConfigError(f"slider mass must be positive and finite, got {mass!r}")
        prior = prior or PressurePrior()
        ccw, _ = normalise_footprint(vertices)
        centroid, area, second = _area_moments(ccw)
        about = ccw - centroid
        supports = _grid_points(about, area, prior.count)
        loads = _equilibrium_loads(supports, prior.rim_weight) * mass * GRAVITY
        return cls(
            vertices=ccw,
            mass=float(mass),
            prior=prior,
            centroid=centroid,
            inertia=float(mass * second / area),
            polygon=ConvexPolygon.from_vertices(about),
            supports=supports,
            loads=loads,
        )

    @property
    def inertia_z(self) -> float:
        """Polar inertia about the centroid [kg·m²] (the name a world reads)."""
        return self.inertia

    @property
    def support_points(self) -> np.ndarray:
        """(S, 2) support points about the centroid [m] (the name a world reads)."""
        return self.supports

    @property
    def support_loads(self) -> np.ndarray:
        """(S,) loads [N] at :attr:`support_points`, summing to m g (the name a world reads)."""
        return self.loads

    def centroid_pose(self, pose: ArrayLike) -> np.ndarray:
        """(…, 3) pose-frame poses → the centroid's (x, y, θ) [m, m, rad]."""
        pose = np.asarray(pose, dtype=float)
        c, s = np.cos(pose[..., 2]), np.sin(pose[..., 2])
        cx, cy = self.centroid
        return np.stack(
            (pose[..., 0] + c * cx - s * cy, pose[..., 1] + s * cx + c * cy, pose[..., 2]), -1
        )

    def frame_pose(self, centroid_pose: ArrayLike) -> np.ndarray:
        """Inverse of :meth:`centroid_pose`."""
        pose = np.asarray(centroid_pose, dtype=float)
        c, s = np.cos(pose[..., 2]), np.sin(pose[..., 2])
        cx, cy = self.centroid
        return np.stack(
            (pose[..., 0] - c * cx + s * cy, pose[..., 1] - s * cx - c * cy, pose[..., 2]), -1
        )


def _area_moments(ccw: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Centroid (2,), area [m²] and polar second moment of area about the centroid [m⁴]."""
    centre = ccw.mean(axis=0)
    p = ccw - centre
    q = np.roll(p, -1, axis=0)
    cross = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]
    area = 0.5 * cross.sum()
    centroid = ((p + q) * cross[:, None]).sum(axis=0) / (6 * area)
    polar = (cross * ((p**2).sum(1) + (p * q).sum(1) + (q**2).sum(1))).sum() / 12
    second = polar - area * float(centroid @ centroid)
    return centre + centroid, float(area), float(second)


def _grid_points(about: np.ndarray, area: float, count: int) -> np.ndarray:
    """Cell centres (S, 2) of a uniform grid over the footprint's bounding box that fall
    strictly inside the footprint ``about`` (V, 2); the cell size is tuned so that about
    ``count`` do."""
    normals = np.stack(
        (np.roll(about, -1, 0)[:, 1] - about[:, 1], about[:, 0] - np.roll(about, -1, 0)[:, 0]), 1
    )
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    offsets = (normals * about).sum(1)
    low, high = about.min(axis=0), about.max(axis=0)
    spacing = math.sqrt(area / count)
    best = np.zeros((0, 2))
    for _ in range(12):
        cells = np.maximum(1, np.round((high - low) / spacing)).astype(int)
        size = (high - low) / cells
        xs = low[0] + (np.arange(cells[0]) + 0.5) * size[0]
        ys = low[1] + (np.arange(cells[1]) + 0.5) * size[1]
        grid = np.stack(np.meshgrid(xs, ys, indexing="ij"), -1).reshape(-1, 2)
        inside = grid[np.all(grid @ normals.T < offsets - 1e-9, axis=1)]
        if abs(len(inside) - count) < abs(len(best) - count):
            best = inside
        if abs(len(inside) - count) <= max(1, count // 10):
            break
        spacing *= math.sqrt(max(len(inside), 1) / count) ** 0.7
    if len(best) < 3:
        raise ConfigError("the footprint is too thin for a support grid; raise the count")
    return best


def _equilibrium_loads(points: np.ndarray, rim_weight: float) -> np.ndarray:
    """Load shares (S,) summing to 1 with their centre at the origin, ∝ exp(rim_weight ρ)
    before the least-norm correction that balances them; negatives are clipped and the
    balance redone on the rest."""
    radius = np.linalg.norm(points, axis=1)
    shares = np.exp(rim_weight * radius / radius.max())
    shares /= shares.sum()
    keep = np.ones(len(points), dtype=bool)
    for _ in range(len(points)):
        a = np.vstack((np.ones(keep.sum()), points[keep].T))
        target = np.array([1.0, 0.0, 0.0]) - a @ shares[keep]
        corrected = shares[keep] + a.T @ np.linalg.lstsq(a @ a.T, target, rcond=None)[0]
        if corrected.min() >= 0:
            out = np.zeros(len(points))
            out[keep] = corrected
            return out
        idx = np.flatnonzero(keep)
        keep[idx[corrected < 0]] = False
        if keep.sum() < 3:
            break
    raise ConfigError("no balanced support loads for this pressure prior")

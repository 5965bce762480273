"""The rigid planar object resting on the table: geometry, mass properties, support loads.

Object local frame (docs/design.md §2): origin at the centre of mass projected on the table,
x = e_n, the inward normal of the pushed face, y = e_t = e_z × e_n. In this frame the pushed
face is the footprint's edge 0 (vertex 0 → vertex 1), a segment of the line
``x = -face_offset``; prongs on it sit at ``r = (-face_offset, t)`` with ``t`` in
``face_extent``.

Build a spec from a footprint in any coordinates with :func:`object_from_footprint`; the
:class:`ObjectSpec` constructor itself expects the local frame and checks it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from pushctl.config import GRAVITY
from pushctl.errors import ConfigError
from pushctl.objects.footprint import as_points, default_pushed_face, normalise_footprint
from pushctl.objects.geometry import ConvexPolygon, rotation
from pushctl.objects.mass import mass_properties, support_loads
from pushctl.ranges import check_range

DEFAULT_PUSHER_MASS = 0.030
"""Pusher mass [kg] for objects from a config file that do not give one (Table II, cube)."""

# Heights this far below zero [m] are rounding, not a height field crossing the table.
_HEIGHT_TOL = 1e-12


@dataclass(frozen=True)
class ObjectSpec:
    """A rigid planar object on the table, in its local frame (see module docstring).

    Attributes:
        name: label used in tables and traces.
        footprint: convex polygon ``(V, 2)`` [m], counter-clockwise, CoM at the origin,
            edge 0 the pushed face (outward normal −x).
        mass: [kg].
        height_at_origin: top-surface height above the CoM [m].
        slope: gradient of the top surface ``(2,)`` [m/m]; the top is
            ``h(p) = height_at_origin + slope · p ≥ 0`` (zero for a prism).
        pusher_mass: mass of the pusher used with this object [kg] (Table II).
        support_points: ground contact points ``(S, 2)`` [m]; defaults to the footprint's
            corners.
        pressure_offset: the support loads' centre of pressure ``(2,)`` [m] relative to the
            CoM, or None for the CoM itself (static equilibrium). A plant unknown of
            docs/design.md §9: a real object's pressure distribution on the table is uneven.

    Derived on construction (never given): ``volume`` [m³], ``inertia_z`` [kg·m²] about the
    vertical axis through the CoM, ``com_height`` [m], ``support_loads (S,)`` [N],
    ``face_offset`` [m], ``face_extent (2,)`` [m] = (t_min, t_max), ``face_height`` [m]
    (solid height at the middle of the pushed face) and ``polygon`` (edge data for
    :func:`pushctl.objects.geometry.signed_distance`).
    """

    name: str
    footprint: np.ndarray
    mass: float
    height_at_origin: float
    slope: np.ndarray = field(default_factory=lambda: np.zeros(2))
    pusher_mass: float = DEFAULT_PUSHER_MASS
    support_points: np.ndarray | None = None
    pressure_offset: np.ndarray | None = None
    volume: float = field(init=False, repr=False)
    inertia_z: float = field(init=False)
    com_height: float = field(init=False)
    support_loads: np.ndarray = field(init=False, repr=False)
    face_offset: float = field(init=False, repr=False)
    face_extent: np.ndarray = field(init=False, repr=False)
    face_height: float = field(init=False, repr=False)
    polygon: ConvexPolygon = field(init=False, repr=False)

    def __post_init__(self) -> None:
        _check_positive(f"object '{self.name}' mass", self.mass, "kg")
        _check_positive(f"object '{self.name}' pusher_mass", self.pusher_mass, "kg")
        check_range("object mass", self.mass, f"object '{self.name}': ")
        check_range("pusher mass", self.pusher_mass, f"object '{self.name}': ")
        polygon = ConvexPolygon.from_vertices(self.footprint)
        footprint = polygon.vertices
        if not np.array_equal(footprint, np.asarray(self.footprint, dtype=float)):
            raise ConfigError(
                f"object '{self.name}': the footprint must be counter-clockwise in the object "
                "frame; use object_from_footprint() for other coordinates"
            )
        slope = _frozen(_check_slope(self.name, self.slope))
        height0 = _finite_height(self.name, self.height_at_origin)
        _check_heights(self.name, footprint, height0, slope)
        props = mass_properties(footprint, height0, slope, self.mass)
        self._check_frame(polygon, props.com_xy)
        supports = footprint if self.support_points is None else self.support_points
        supports = _frozen(as_points(supports, f"object '{self.name}' support_points"))
        _check_supports_inside(self.name, polygon, supports)
        pressure = None
        if self.pressure_offset is not None:
            where = f"object '{self.name}' pressure_offset"
            pressure = _frozen(as_points([self.pressure_offset], where)[0])
        face_offset = -0.5 * float(footprint[0, 0] + footprint[1, 0])
        face_extent = np.array([footprint[1, 1], footprint[0, 1]])
        self._set(
            footprint=footprint,
            mass=float(self.mass),
            pusher_mass=float(self.pusher_mass),
            height_at_origin=height0,
            slope=slope,
            support_points=supports,
            polygon=polygon,
            volume=props.volume,
            inertia_z=props.inertia_z,
            com_height=props.com_height,
            support_loads=_frozen(support_loads(supports, self.mass * GRAVITY, pressure)),
            pressure_offset=pressure,
            face_offset=face_offset,
            face_extent=_frozen(face_extent),
            face_height=float(height0 + slope @ (-face_offset, face_extent.mean())),
        )

    def _set(self, **values: object) -> None:
        for key, value in values.items():
            object.__setattr__(self, key, value)

    def _check_frame(self, polygon: ConvexPolygon, com_xy: np.ndarray) -> None:
        """Raise ConfigError unless the CoM is at the origin and edge 0 faces −x."""
        size = float(np.ptp(polygon.vertices, axis=0).max())
        normal_x = polygon.edges[0][4]
        if np.abs(com_xy).max() > 1e-9 * size or abs(normal_x + 1.0) > 1e-9:
            raise ConfigError(
                f"object '{self.name}' is not in its local frame (CoM at {com_xy.tolist()}, "
                "edge 0 must face -x); use object_from_footprint() to build it"
            )

    @property
    def weight(self) -> float:
        """``m g`` [N]."""
        return self.mass * GRAVITY

    @property
    def mass_matrix(self) -> np.ndarray:
        """Planar mass matrix ``diag(m, m, I_z)``, (3, 3) [kg, kg, kg·m²]."""
        return np.diag([self.mass, self.mass, self.inertia_z])

    def height_at(self, points: ArrayLike) -> np.ndarray:
        """Top-surface height [m] at local points ``(2,)`` or ``(N, 2)`` [m]."""
        return self.height_at_origin + np.asarray(points, dtype=float) @ self.slope

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, ObjectSpec):
            return NotImplemented
        return (
            self.name == other.name
            and self.mass == other.mass
            and self.pusher_mass == other.pusher_mass
            and self.height_at_origin == other.height_at_origin
            and np.array_equal(self.footprint, other.footprint)
            and np.array_equal(self.slope, other.slope)
            and np.array_equal(np.asarray(self.support_points), np.asarray(other.support_points))
            and np.array_equal(
                np.zeros(2) if self.pressure_offset is None else self.pressure_offset,
                np.zeros(2) if other.pressure_offset is None else other.pressure_offset,
            )
        )

    def __hash__(self) -> int:
        return hash((self.name, self.mass, self.pusher_mass, self.footprint.tobytes()))


def object_from_footprint(
    name: str,
    footprint: ArrayLike,
    mass: float,
    height: float,
    *,
    slope: ArrayLike = (0.0, 0.0),
    pushed_face: int | None = None,
    pusher_mass: float = DEFAULT_PUSHER_MASS,
    support_points: ArrayLike | None = None,
) -> ObjectSpec:
    """Build an :class:`ObjectSpec` from a footprint in arbitrary table coordinates.

    The footprint is translated so the centre of mass is at the origin and rotated so the
    pushed face's inward normal is +x; the height field and support points move with it.

    Args:
        name: label.
        footprint: convex polygon ``(V, 2)`` [m], clockwise or counter-clockwise.
        mass: [kg].
        height: top-surface height [m] at the origin of the given coordinates.
        slope: top-surface gradient ``(2,)`` [m/m] in the given coordinates.
        pushed_face: edge index ``i`` (vertex ``i`` → vertex ``i + 1`` in the given order);
            default: the edge whose outward normal points most along −x.
        pusher_mass: [kg].
        support_points: ``(S, 2)`` [m] in the given coordinates; default the corners.

    Raises:
        ConfigError: for any invalid input, with a one-line reason.
    """
    _check_positive(f"object '{name}' mass", mass, "kg")
    ccw, flipped = normalise_footprint(footprint)
    n = len(ccw)
    face = _pushed_face_index(name, ccw, flipped, pushed_face)
    grad = _check_slope(name, slope)
    height = _finite_height(name, height)
    _check_heights(name, ccw, height, grad)
    com = mass_properties(ccw, height, grad, mass).com_xy
    edge = ccw[(face + 1) % n] - ccw[face]
    inward = np.array([-edge[1], edge[0]])  # the edge direction turned left (ccw polygon)
    to_local = rotation(math.atan2(inward[1], inward[0])).T

    def local(points: np.ndarray) -> np.ndarray:
        return (points - com) @ to_local.T

    supports = None
    if support_points is not None:
        supports = local(as_points(support_points, f"object '{name}' support_points"))
    return ObjectSpec(
        name=name,
        footprint=local(np.roll(ccw, -face, axis=0)),
        mass=float(mass),
        height_at_origin=float(height + grad @ com),
        slope=to_local @ grad,
        pusher_mass=pusher_mass,
        support_points=supports,
    )


def _pushed_face_index(name: str, ccw: np.ndarray, flipped: bool, pushed_face: int | None) -> int:
    """Index in ``ccw`` of the pushed face given by the user's edge index (or the default)."""
    n = len(ccw)
    if pushed_face is None:
        return default_pushed_face(ccw)
    if isinstance(pushed_face, bool) or not isinstance(pushed_face, (int, np.integer)):
        raise ConfigError(f"object '{name}' pushed_face must be an edge index 0..{n - 1}")
    if not 0 <= pushed_face < n:
        raise ConfigError(
            f"object '{name}' pushed_face {pushed_face} is out of range: give an edge index "
            f"0..{n - 1} (edge i runs from vertex i to vertex i+1)"
        )
    # Reversing the order maps the user's edge (j → j+1) onto the ccw edge (V-2-j → V-1-j).
    return (n - 2 - int(pushed_face)) % n if flipped else int(pushed_face)


def _check_positive(what: str, value: object, unit: str) -> None:
    ok = isinstance(value, (int, float, np.floating, np.integer)) and not isinstance(value, bool)
    if not ok or not math.isfinite(float(value)) or float(value) <= 0.0:  # type: ignore[arg-type]
        raise ConfigError(f"{what} must be a positive number of {unit}, got {value!r}")


def _finite_height(name: str, value: object) -> float:
    try:
        height = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        height = math.nan
    if isinstance(value, bool) or not math.isfinite(height):
        raise ConfigError(
            f"object '{name}' height must be a finite number of metres, got {value!r}"
        )
    return height


def _check_slope(name: str, slope: ArrayLike) -> np.ndarray:
    try:
        grad = np.asarray(slope, dtype=float)
    except (TypeError, ValueError):
        grad = np.full(3, np.nan)  # reported below
    if grad.shape != (2,) or not np.all(np.isfinite(grad)):
        raise ConfigError(f"object '{name}' slope must be two finite numbers [gx, gy] (m/m)")
    return grad


def _check_heights(name: str, ccw: np.ndarray, height0: float, slope: np.ndarray) -> None:
    """Raise ConfigError unless ``h ≥ 0`` over the footprint and ``h > 0`` somewhere.

    ``h`` is linear, so its extremes over a convex polygon are at the vertices.
    """
    heights = height0 + ccw @ slope
    lowest = int(np.argmin(heights))
    if heights[lowest] < -_HEIGHT_TOL:
        raise ConfigError(
            f"object '{name}' height is negative ({heights[lowest]:.4g} m) at footprint corner "
            f"{ccw[lowest].tolist()}; the top surface must stay at or above the table"
        )
    if heights.max() <= _HEIGHT_TOL:
        raise ConfigError(f"object '{name}' height must be positive, got {heights.max():.4g} m")


def _check_supports_inside(name: str, polygon: ConvexPolygon, supports: np.ndarray) -> None:
    size = float(np.ptp(polygon.vertices, axis=0).max())
    for j, (px, py) in enumerate(supports.tolist()):
        if polygon.query(px, py)[0] > 1e-9 * size:
            raise ConfigError(
                f"object '{name}' support point {j} (object frame {[px, py]}) lies outside the "
                "footprint; support points must be on or inside it"
            )


def _frozen(array: np.ndarray) -> np.ndarray:
    out = np.array(array, dtype=float)
    out.setflags(write=False)
    return out

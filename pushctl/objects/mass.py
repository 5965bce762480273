"""Mass properties of a solid under a linear height field, and static support loads.

The solid occupies ``{(x, y, z): (x, y) in footprint, 0 <= z <= h(x, y)}`` with the plane
``h(x, y) = h0 + g · (x, y)`` and uniform density. Every integrand below (h, x·h, h²/2,
|p|²·h) is a polynomial of degree ≤ 3, so a fan triangulation with a triangle rule exact for
cubics integrates it exactly (up to rounding).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import pushctl.machine.proxqp_build  # noqa: F401  # before qpsolvers, which imports proxsuite
from pushctl.errors import ConfigError

# Barycentric points and weights (fractions of the triangle's area) of the 7-point
# triangle rule exact for polynomials of degree 3: vertices 1/20, edge midpoints 2/15,
# centroid 9/20.
_RULE_BARY = np.array(
    [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.5, 0.5, 0.0],
        [0.0, 0.5, 0.5],
        [0.5, 0.0, 0.5],
        [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
    ]
)
_RULE_WEIGHTS = np.array([1 / 20, 1 / 20, 1 / 20, 2 / 15, 2 / 15, 2 / 15, 9 / 20])


@dataclass(frozen=True, eq=False)
class MassProperties:
    """Mass properties of a uniform solid under a linear height field.

    Attributes:
        volume: [m³].
        com_xy: centre of mass projected on the table, (2,) [m], in the footprint's frame.
        com_height: height of the centre of mass above the table [m].
        inertia_z: moment of inertia about the vertical axis through the CoM [kg·m²].
    """

    volume: float
    com_xy: np.ndarray
    com_height: float
    inertia_z: float


def _quadrature(vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points ``(Q, 2)`` and weights ``(Q,)`` [m²] integrating cubics over the polygon.

    ``vertices (V, 2)`` is convex and counter-clockwise, so the fan from vertex 0 covers it
    with positively oriented triangles.
    """
    a = vertices[0]
    b, c = vertices[1:-1], vertices[2:]
    areas = 0.5 * ((b[:, 0] - a[0]) * (c[:, 1] - a[1]) - (b[:, 1] - a[1]) * (c[:, 0] - a[0]))
    corners = np.stack((np.broadcast_to(a, b.shape), b, c), axis=1)  # (T, 3, 2)
    points = np.einsum("qk,tkd->tqd", _RULE_BARY, corners).reshape(-1, 2)
    weights = (areas[:, None] * _RULE_WEIGHTS[None, :]).ravel()
    return points, weights


def mass_properties(
    vertices: np.ndarray, height_at_origin: float, slope: np.ndarray, mass: float
) -> MassProperties:
    """Exact mass properties of the solid under ``h(p) = height_at_origin + slope · p``.

    Args:
        vertices: convex counter-clockwise footprint, (V, 2) [m].
        height_at_origin: h at the footprint frame's origin [m].
        slope: height gradient, (2,) [m/m].
        mass: [kg].
    """
    # Integrate about the vertex mean to keep the moments well conditioned, then
    # integrate the second moment again about the CoM (no parallel-axis cancellation).
    centre = vertices.mean(axis=0)
    points, weights = _quadrature(vertices - centre)
    heights = height_at_origin + (points + centre) @ slope
    volume = float(weights @ heights)
    com_xy = centre + (weights * heights) @ points / volume
    com_height = float(weights @ (0.5 * heights**2)) / volume
    offsets = points + centre - com_xy
    second = float(weights @ (heights * np.einsum("ij,ij->i", offsets, offsets)))
    return MassProperties(
        volume=volume,
        com_xy=com_xy,
        com_height=com_height,
        inertia_z=mass / volume * second,
    )


def support_loads(
    points: np.ndarray, weight: float, centre: np.ndarray | None = None
) -> np.ndarray:
    """Normal loads [N] on support points holding a rigid body in static equilibrium.

    Solves ``Σ N_j = weight`` and ``Σ N_j r_j = 0`` (no moment about the CoM) with
    ``N ≥ 0``. With ``centre`` c (2,) [m] the loads balance about c instead,
    ``Σ N_j (r_j − c) = 0``: their centre of pressure is c (an uneven pressure distribution,
    a plant unknown of docs/design.md §9; the total stays ``weight``). With four or more points
    the loads are statically indeterminate; the minimum-norm solution is taken (equal loads
    on a symmetric support, the lever rule along a wedge's length).

    Args:
        points: support points ``(S, 2)`` [m] relative to the CoM.
        weight: ``m g`` [N].
        centre: the loads' centre of pressure ``(2,)`` [m], relative to the CoM (None: the CoM).

    Returns:
        ``(S,)`` [N], non-negative.

    Raises:
        ConfigError: the CoM (or ``centre``) lies outside the convex hull of the support
            points.
    """
    scale = max(float(np.abs(points).max()), 1e-12)
    # Unit weight and lever arms in units of the support's size keep the rows comparable.
    equilibrium = np.vstack((np.ones(len(points)), (points / scale).T))
    rhs = np.array([1.0, 0.0, 0.0])
    if centre is not None:
        rhs[1:] = np.asarray(centre, dtype=float) / scale
    n = len(points)
    import qpsolvers  # here: after pushctl.machine.proxqp_build loaded ProxSuite's portable build

    solution = qpsolvers.solve_problem(
        qpsolvers.Problem(P=np.eye(n), q=np.zeros(n), A=equilibrium, b=rhs, lb=np.zeros(n)),
        solver="proxqp",
        eps_abs=1e-12,
        eps_rel=0.0,
    )
    approx = solution.x if solution.found else None
    loads = None if approx is None else _polish(equilibrium, rhs, approx)
    if loads is None:
        raise ConfigError(
            f"support loads are infeasible: the centre of mass lies outside the support "
            f"polygon of the {n} support points; give support_points around the CoM"
        )
    return loads * weight


def _polish(equilibrium: np.ndarray, rhs: np.ndarray, approx: np.ndarray) -> np.ndarray | None:
    """Exact minimum-norm loads on the active set the QP suggests, or None if infeasible.

    On the active set the minimum-norm solution of the equality constraints is the
    least-squares one; it is accepted only if it is non-negative and balances exactly.
    """
    active = approx > 1e-9
    if not active.any():
        return None
    loads = np.zeros_like(approx)
    loads[active] = np.linalg.lstsq(equilibrium[:, active], rhs, rcond=None)[0]
    if loads.min() < -1e-12 or np.abs(equilibrium @ loads - rhs).max() > 1e-12:
        loads = np.clip(approx, 0.0, None)  # keep the QP answer if polishing broke it
        if np.abs(equilibrium @ loads - rhs).max() > 1e-9:
            return None
    return np.clip(loads, 0.0, None)

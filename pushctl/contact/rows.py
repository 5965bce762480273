"""Constraint rows of the world step: prong contacts and ground friction (DESIGN.md §3).

Each row maps the generalised velocity ``v = [q̇_arm (nv); v_obj (3)]`` to one constraint
velocity; the impulse of the row acts along the same direction (``Aᵀ p``). Object columns are
``(vx, vy, ω)`` in the world frame, so a direction ``e`` at offset ``r`` from the centre of
mass has object part ``(e_x, e_y, r × e)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pushctl.objects.geometry import ConvexPolygon

# A support point moving slower than this [m/s] counts as sticking: both friction rows get
# their full bound. Faster, friction acts only against the slip (the cross row's bound is
# 0), so the box is isotropic in the plane and does not lock the yaw of a sliding object.
SLIP_SPEED = 1e-6


@dataclass(frozen=True)
class ProngRows:
    """Normal and tangential rows of the prongs within the contact margin.

    ``prongs`` (p,) indices of those prongs; rows 2i and 2i+1 belong to ``prongs[i]``.
    ``A_arm`` (2p, nv); ``obj_rows`` 2p tuples (e_x, e_y, r × e), the object part;
    ``bias`` 2p floats [m/s], the position-stabilisation velocity added to the normal rows
    (a positive gap may close exactly within the step, a fraction ``stabilisation`` of a
    penetration is removed per step). Plain lists: the caller stacks them with the ground
    rows in one array.
    """

    prongs: tuple[int, ...]
    A_arm: np.ndarray
    obj_rows: list[tuple[float, float, float]]
    bias: list[float]


def prong_rows(
    polygon: ConvexPolygon,
    pose: np.ndarray,
    prong_positions: np.ndarray,
    prong_jacobians: np.ndarray,
    margin: float,
    stabilisation: float,
    h: float,
) -> ProngRows:
    """Rows of the prongs nearer than ``margin`` [m] to the object's footprint.

    ``pose`` (3,) object (x, y, θ); ``prong_positions`` (k, 3) [m] and ``prong_jacobians``
    (k, 3, nv) world frame. The normal e_n points into the object (minus the outward normal
    of the nearest feature), e_t = e_z × e_n; rows measure the velocity of the object's
    contact point relative to the prong along them, so w_n > 0 separates.
    """
    x0, y0, theta = pose.tolist()
    c, s = math.cos(theta), math.sin(theta)
    prongs, directions, obj, bias = [], [], [], []
    for i, (px, py, _) in enumerate(prong_positions.tolist()):
        px, py = px - x0, py - y0
        gap, n_lx, n_ly, cl_x, cl_y = polygon.query(c * px + s * py, -s * px + c * py)
        if gap >= margin:
            continue
        nx, ny = -(c * n_lx - s * n_ly), -(s * n_lx + c * n_ly)
        # r: centre of mass to the contact point on the surface, world axes.
        rx, ry = c * cl_x - s * cl_y, s * cl_x + c * cl_y
        prongs.append(i)
        directions.append(((nx, ny), (-ny, nx)))
        obj.append((nx, ny, rx * ny - ry * nx))
        obj.append((-ny, nx, rx * nx + ry * ny))
        bias.append(gap / h if gap >= 0.0 else stabilisation * gap / h)
        bias.append(0.0)
    nv = prong_jacobians.shape[2]
    if prongs:
        # Row (i, d) of the arm part: −e_d · J_i (planar components), one batched product.
        jacobians = prong_jacobians if len(prongs) == len(prong_jacobians) else prong_jacobians[prongs]
        A_arm = (np.array(directions) @ jacobians[:, :2, :]).reshape(-1, nv)
        np.negative(A_arm, out=A_arm)
    else:
        A_arm = np.zeros((0, nv))
    return ProngRows(prongs=tuple(prongs), A_arm=A_arm, obj_rows=obj, bias=bias)


class GroundFriction:
    """Box friction at the object's support points, aligned with each point's slip.

    Two rows per support point, always (a fixed structure keeps warm starts valid): along
    the slip direction with bounds ±h μ_g N_j, and across it with the same bounds at rest and
    0 while the point slides. At rest the box keeps the last slip direction seen (initially
    the object's e_n).
    """

    def __init__(self, support_points: np.ndarray, friction_limits: np.ndarray) -> None:
        """``support_points`` (S, 2) [m] object frame; ``friction_limits`` (S,) [N] = μ_g N_j."""
        self._point_list = [tuple(point) for point in np.asarray(support_points, float).tolist()]
        self._limit_list = np.asarray(friction_limits, dtype=float).tolist()
        self._direction_list: list[tuple[float, float]] = []
        self.reset(0.0)

    @property
    def n_rows(self) -> int:
        return 2 * len(self._point_list)

    def reset(self, theta: float) -> None:
        """Forget the slip history: at-rest boxes align with e_n at yaw ``theta`` [rad]."""
        self._direction_list = [(math.cos(theta), math.sin(theta))] * len(self._point_list)

    def rows(self, pose: np.ndarray, velocity: np.ndarray, h: float):
        """Rows at the object's ``pose`` and pre-step ``velocity``: ``(obj_rows, hi)``, 2S
        tuples (e_x, e_y, r × e) and 2S upper bounds [N·s]; the bounds are symmetric,
        ``lo = −hi``. Plain lists, stacked by the caller."""
        theta = float(pose[2])
        c, s = math.cos(theta), math.sin(theta)
        vx, vy, omega = velocity.tolist()
        rows, hi = [], []
        # Plain floats: for four points this is several times faster than numpy.
        for j, (sx, sy) in enumerate(self._point_list):
            rx, ry = c * sx - s * sy, s * sx + c * sy
            ux, uy = vx - omega * ry, vy + omega * rx
            speed = math.hypot(ux, uy)
            bound = h * self._limit_list[j]
            if speed > SLIP_SPEED:
                dx, dy = ux / speed, uy / speed
                self._direction_list[j] = (dx, dy)
                cross = 0.0
            else:
                dx, dy = self._direction_list[j]
                cross = bound
            rows.append((dx, dy, rx * dy - ry * dx))
            rows.append((-dy, dx, rx * dx + ry * dy))
            hi.append(bound)
            hi.append(cross)
        return rows, hi

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
    ``A_arm`` (2p, nv), ``A_obj`` (2p, 3); ``bias`` (2p,) [m/s] the position-stabilisation
    velocity added to the normal rows (a positive gap may close exactly within the step,
    a fraction ``stabilisation`` of a penetration is removed per step).
    """

    prongs: tuple[int, ...]
    A_arm: np.ndarray
    A_obj: np.ndarray
    bias: np.ndarray


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
    c, s = math.cos(pose[2]), math.sin(pose[2])
    prongs, arm, obj, bias = [], [], [], []
    for i, (px, py) in enumerate(prong_positions[:, :2] - pose[:2]):
        gap, n_lx, n_ly, cl_x, cl_y = polygon.query(c * px + s * py, -s * px + c * py)
        if gap >= margin:
            continue
        nx, ny = -(c * n_lx - s * n_ly), -(s * n_lx + c * n_ly)
        # r: centre of mass to the contact point on the surface, world axes.
        rx, ry = c * cl_x - s * cl_y, s * cl_x + c * cl_y
        J = prong_jacobians[i]
        prongs.append(i)
        arm.append(-(nx * J[0] + ny * J[1]))
        arm.append(ny * J[0] - nx * J[1])
        obj.append((nx, ny, rx * ny - ry * nx))
        obj.append((-ny, nx, rx * nx + ry * ny))
        bias.append(gap / h if gap >= 0.0 else stabilisation * gap / h)
        bias.append(0.0)
    nv = prong_jacobians.shape[2]
    return ProngRows(
        prongs=tuple(prongs),
        A_arm=np.array(arm).reshape(-1, nv),
        A_obj=np.array(obj, dtype=float).reshape(-1, 3),
        bias=np.array(bias),
    )


class GroundFriction:
    """Box friction at the object's support points, aligned with each point's slip.

    Two rows per support point, always (a fixed structure keeps warm starts valid): along
    the slip direction with bounds ±h μ_g N_j, and across it with the same bounds at rest and
    0 while the point slides. At rest the box keeps the last slip direction seen (initially
    the object's e_n).
    """

    def __init__(self, support_points: np.ndarray, friction_limits: np.ndarray) -> None:
        """``support_points`` (S, 2) [m] object frame; ``friction_limits`` (S,) [N] = μ_g N_j."""
        self._points = np.asarray(support_points, dtype=float)
        self._limits = np.asarray(friction_limits, dtype=float)
        self._directions = np.zeros_like(self._points)
        self.reset(0.0)

    @property
    def n_rows(self) -> int:
        return 2 * len(self._points)

    def reset(self, theta: float) -> None:
        """Forget the slip history: at-rest boxes align with e_n at yaw ``theta`` [rad]."""
        self._directions[:] = (math.cos(theta), math.sin(theta))

    def rows(self, pose: np.ndarray, velocity: np.ndarray, h: float):
        """``(A_obj (2S, 3), hi (2S,))`` at the object's ``pose`` and pre-step ``velocity``;
        the bounds are symmetric, ``lo = −hi`` [N·s]."""
        c, s = math.cos(pose[2]), math.sin(pose[2])
        r = self._points @ np.array([[c, s], [-s, c]])  # (S, 2) world offsets
        slip = velocity[:2] + velocity[2] * np.column_stack((-r[:, 1], r[:, 0]))
        speed = np.hypot(slip[:, 0], slip[:, 1])
        sliding = speed > SLIP_SPEED
        if sliding.any():
            self._directions[sliding] = slip[sliding] / speed[sliding, None]
        d = self._directions
        A = np.empty((self.n_rows, 3))
        A[0::2, 0], A[0::2, 1] = d[:, 0], d[:, 1]
        A[1::2, 0], A[1::2, 1] = -d[:, 1], d[:, 0]
        A[0::2, 2] = r[:, 0] * d[:, 1] - r[:, 1] * d[:, 0]
        A[1::2, 2] = r[:, 0] * d[:, 0] + r[:, 1] * d[:, 1]
        hi = np.empty(self.n_rows)
        hi[0::2] = h * self._limits
        hi[1::2] = np.where(sliding, 0.0, h * self._limits)
        return A, hi

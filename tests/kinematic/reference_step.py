"""An independent step for a slider pushed by prescribed prongs with ground friction fixed
to the table, written with numpy and :func:`pushctl.solve_box_mlcp`: the oracle the world's
compiled step (:meth:`pushctl.contact.world.World.push`) is checked against to round-off.

It assembles the rows its own way (per support point the facets/2 directions in angle
order, zero-bound rows left out, the Jacobian product by numpy) and solves the MLCP once per
step; only the physics is shared: the rows' definitions, the relative diagonal terms (10⁻⁶
on the prong rows, the ground compliance on the ground rows), semi-implicit Euler."""

from __future__ import annotations

import math

import numpy as np

from pushctl.contact import solve_box_mlcp
from pushctl.contact.world_config import GROUND_COMPLIANCE
from pushctl.kinematic import Friction, Pusher, Slider

_PRONG_REGULARISATION = 1e-6


class ReferencePushWorld:
    """A slider at rest at a pose-frame pose, stepped by :meth:`step` (pusher pose to pusher
    pose, as :class:`pushctl.kinematic.KinematicPushWorld`)."""

    def __init__(self, slider: Slider, pusher: Pusher, friction: Friction, dt: float) -> None:
        assert friction.model in ("polygon", "axis_box")
        self.slider, self.pusher, self.friction, self.dt = slider, pusher, friction, dt
        self._minv = np.array([1 / slider.mass, 1 / slider.mass, 1 / slider.inertia])
        half = 2 if friction.model == "axis_box" else friction.facets // 2
        angles = np.arange(half) * math.pi / half
        self._dirs = np.stack((np.cos(angles), np.sin(angles)), 1)
        share = 1.0 if friction.model == "axis_box" else math.pi / friction.facets
        self._bounds = np.repeat(friction.mu_ground * slider.loads * dt * share, half)
        self._warm: np.ndarray | None = None

    def reset(self, pose) -> None:
        self.com = self.slider.centroid_pose(np.asarray(pose, dtype=float))
        self.velocity = np.zeros(3)
        self._warm = None

    @property
    def pose(self) -> np.ndarray:
        return self.slider.frame_pose(self.com)

    def step(self, pusher_pose, next_pusher_pose) -> None:
        p0 = self.pusher.prong_positions(np.asarray(pusher_pose, dtype=float))
        p1 = self.pusher.prong_positions(np.asarray(next_pusher_pose, dtype=float))
        rows, bias = self._prong_rows(p0, (p1 - p0) / self.dt)
        if not rows and not self.velocity.any():
            return
        x, y, th = self.com
        c, s = math.cos(th), math.sin(th)
        sup = self.slider.supports
        r = np.stack((c * sup[:, 0] - s * sup[:, 1], s * sup[:, 0] + c * sup[:, 1]), 1)
        rr = np.repeat(r, len(self._dirs), axis=0)
        d = np.tile(self._dirs, (len(r), 1))
        ground = np.column_stack((d, rr[:, 0] * d[:, 1] - rr[:, 1] * d[:, 0]))
        jac = np.vstack((np.array(rows).reshape(-1, 3), ground))
        n_prong, n = len(rows), len(jac)
        b = jac @ self.velocity
        b[:n_prong] += np.array(bias)
        lo = np.concatenate((np.zeros(n_prong), -self._bounds))
        hi = np.concatenate((np.tile([np.inf, 0.0], n_prong // 2), self._bounds))
        findex = np.full(n, -1, dtype=np.int64)
        findex[1:n_prong:2] = np.arange(0, n_prong, 2)
        mu = np.zeros(n)
        mu[1:n_prong:2] = self.friction.mu_contact
        dmat = (jac * self._minv) @ jac.T
        diagonal = np.full(n, 1.0 + GROUND_COMPLIANCE)
        diagonal[:n_prong] = 1.0 + _PRONG_REGULARISATION
        dmat[np.diag_indices(n)] *= diagonal
        warm = self._warm if self._warm is not None and len(self._warm) == n else None
        result = solve_box_mlcp(dmat, b, lo, hi, findex, mu, warm_start=warm, validate=False)
        assert result.converged
        self._warm = result.p
        self.velocity = self.velocity + self._minv * (jac.T @ result.p)
        self.com = self.com + self.dt * self.velocity

    def _prong_rows(self, prongs, prong_vel):
        x, y, th = self.com
        c, s = math.cos(th), math.sin(th)
        rows, bias = [], []
        for (px, py), (vx, vy) in zip(prongs.tolist(), prong_vel.tolist(), strict=True):
            lx, ly = c * (px - x) + s * (py - y), -s * (px - x) + c * (py - y)
            dist, nx, ny, cx, cy = self.slider.polygon.query(lx, ly)
            gap = dist - self.pusher.radius
            if gap - math.hypot(vx, vy) * self.dt > 2e-3:
                continue
            nwx, nwy = -(c * nx - s * ny), -(s * nx + c * ny)
            rx, ry = c * cx - s * cy, s * cx + c * cy
            twx, twy = -nwy, nwx
            rows += [(nwx, nwy, rx * nwy - ry * nwx), (twx, twy, rx * twy - ry * twx)]
            closing = gap if gap >= 0 else 0.3 * gap
            bias += [-(nwx * vx + nwy * vy) + closing / self.dt, -(twx * vx + twy * vy)]
        return rows, bias

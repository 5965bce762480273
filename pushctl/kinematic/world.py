"""A world with a kinematic pusher: the prongs follow a prescribed path, only the slider is
dynamic, and each step is one box-friction MLCP (:func:`pushctl.contact.solve_box_mlcp`).

The step, in impulses p = h λ [N·s] over the slider's centroid velocity u = (vx, vy, ω):

- per prong within reach of the footprint (a round prong: signed distance to the polygon
  minus its radius), a unilateral normal row and a tangential row with friction
  |p_t| ≤ μ_c p_n; the prong's velocity enters the rows' free velocity as a prescribed
  motion (w_n = n·(v_object(c) − v_prong) + gap/h, so a gap may close within the step);
- per support point j (load N_j from the pressure prior), ground friction of bound h μ_g N_j:
  ``"box"`` (the default, the box-friction MLCP's own model): two rows along the world's
  x and y axes, each bounded by ±h μ_g N_j, so the friction set is a square (direction
  dependent: up to √2 h μ_g N_j along a diagonal). ``"polygon"``: an isotropic polyhedral
  friction set, a regular polygon of ``facets`` sides built as the sum of facets/2
  world-fixed segments (rows along directions kπ/(facets/2), bounds ±π h μ_g N_j / facets,
  so the polygon's mean support equals h μ_g N_j);
- ``w = D p + b`` with D = J M⁻¹ Jᵀ, M = diag(m, m, I); then u ← u + M⁻¹ Jᵀ p and the pose
  moves by h u (semi-implicit Euler).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from pushctl.contact import solve_box_mlcp
from pushctl.errors import ConfigError
from pushctl.kinematic.shape import Slider

FRICTION_MODELS = ("box", "polygon")

_REACH = 2e-3
"""A prong gets contact rows when its gap, less its motion in the step, is below this [m]."""

_PENETRATION_RECOVERY = 0.3
"""Share of a penetration removed per step (as in the arm world)."""


_PRONG_REGULARISATION = 1e-6
"""Relative diagonal term on the prong rows: a unique split between identical prongs."""

_GROUND_COMPLIANCE = 1e-2
"""Relative diagonal term on the ground rows: D alone has rank 3 for any number of support
points, and its many tied rows make the solver's pivoting fall back to its slow path; this
small compliance (a held point may creep at 1 % of the velocity its friction impulse would
give it alone) makes D positive definite and leaves sliding points unchanged."""


@dataclass(frozen=True)
class Pusher:
    """Round prongs rigidly attached to a pusher frame.

    - ``offsets``: (k, 2) prong centres in the pusher frame [m]; (0, 0) for one tip. The
      pusher frame's x axis is its push direction θ.
    - ``radius``: prong radius [m] (> 0).
    """

    offsets: tuple[tuple[float, float], ...] = ((0.0, 0.0),)
    radius: float = 4.75e-3

    def __post_init__(self) -> None:
        arr = np.asarray(self.offsets, dtype=float)
        if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) < 1 or not np.isfinite(arr).all():
            raise ConfigError(
                f"pusher offsets must be k >= 1 finite (x, y) pairs [m], got {self.offsets!r}"
            )
        if not (math.isfinite(self.radius) and self.radius > 0):
            raise ConfigError(f"prong radius must be positive [m], got {self.radius!r}")

    @classmethod
    def row(cls, count: int, spacing: float, radius: float) -> Pusher:
        """``count`` prongs ``spacing`` [m] apart across the push direction, centred."""
        ys = (np.arange(count) - (count - 1) / 2) * spacing
        return cls(tuple((0.0, float(y)) for y in ys), radius)

    def prong_positions(self, pose: np.ndarray) -> np.ndarray:
        """Pusher poses (..., 3) → prong centres (..., k, 2) [m] in the world."""
        pose = np.asarray(pose, dtype=float)
        off = np.asarray(self.offsets)
        c, s = np.cos(pose[..., 2])[..., None], np.sin(pose[..., 2])[..., None]
        x = pose[..., 0:1] + c * off[:, 0] - s * off[:, 1]
        y = pose[..., 1:2] + s * off[:, 0] + c * off[:, 1]
        return np.stack((x, y), -1)


@dataclass(frozen=True)
class Friction:
    """Friction coefficients and the ground model.

    - ``mu_contact``: prong–object μ_c [-]; ``mu_ground``: object–table μ_g [-].
    - ``model``: ``"box"`` or ``"polygon"`` (see the module doc); ``facets``: the polygon's
      sides (even, >= 8).
    """

    mu_contact: float = 0.25
    mu_ground: float = 0.3
    model: str = "box"
    facets: int = 8

    def __post_init__(self) -> None:
        for name in ("mu_contact", "mu_ground"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ConfigError(f"{name} must be finite and >= 0, got {value!r}")
        if self.model not in FRICTION_MODELS:
            raise ConfigError(
                f"friction model must be one of {FRICTION_MODELS}, got {self.model!r}"
            )
        if not (isinstance(self.facets, int) and self.facets >= 8 and self.facets % 2 == 0):
            raise ConfigError(f"facets must be an even integer >= 8, got {self.facets!r}")


@dataclass(frozen=True)
class StepReport:
    """One step's contact outcome: normal and tangential forces (k,) [N] per prong (0
    without contact; tangential along the contact normal turned +90°), whether the MLCP
    verified, and how many MLCPs were solved."""

    normal_force: np.ndarray
    tangential_force: np.ndarray
    converged: bool
    solves: int


class KinematicPushWorld:
    """A slider on a table pushed by prongs whose motion is prescribed.

    Args:
        slider: the object (:class:`~pushctl.kinematic.shape.Slider`).
        pusher: the prongs.
        friction: coefficients and ground model.
        dt: step [s] (> 0).
    """

    def __init__(self, slider: Slider, pusher: Pusher, friction: Friction, dt: float) -> None:
        if not (math.isfinite(dt) and dt > 0):
            raise ConfigError(f"dt must be positive [s], got {dt!r}")
        self.slider, self.pusher, self.friction, self.dt = slider, pusher, friction, float(dt)
        self._minv = np.array([1 / slider.mass, 1 / slider.mass, 1 / slider.inertia])
        self._bounds = friction.mu_ground * slider.loads * self.dt  # (S,) [N·s]
        # Ground rows per support point: the box's two world axes at the full bound, or the
        # polygon's facets/2 segment directions at π/facets of it (the polygon's mean support
        # is then the full bound, its support within 0.95-1.03 of it for 8 facets).
        half = 2 if friction.model == "box" else friction.facets // 2
        angles = np.arange(half) * math.pi / half
        self._ground_dirs = np.stack((np.cos(angles), np.sin(angles)), 1)  # (K, 2)
        self._bound_share = 1.0 if friction.model == "box" else math.pi / friction.facets
        self._warm: np.ndarray | None = None
        self.reset(np.zeros(3))

    def reset(self, object_pose: ArrayLike) -> None:
        """Place the slider at rest at ``object_pose`` (x, y, θ) of its pose frame."""
        self._com = self.slider.centroid_pose(np.asarray(object_pose, dtype=float))
        self.velocity = np.zeros(3)
        self._warm = None

    @property
    def pose(self) -> np.ndarray:
        """The slider's pose-frame pose (3,) [m, m, rad]."""
        return self.slider.frame_pose(self._com)

    def step(self, pusher_pose: ArrayLike, next_pusher_pose: ArrayLike) -> StepReport:
        """Advance one step while the pusher moves from ``pusher_pose`` to
        ``next_pusher_pose`` (each (3,) [m, m, rad])."""
        p0 = self.pusher.prong_positions(np.asarray(pusher_pose, dtype=float))
        p1 = self.pusher.prong_positions(np.asarray(next_pusher_pose, dtype=float))
        prong_rows, prong_b, touching = self._prong_rows(p0, (p1 - p0) / self.dt)
        k = len(self.pusher.offsets)
        if len(prong_rows) == 0 and not np.any(self.velocity):
            self._warm = None
            return StepReport(np.zeros(k), np.zeros(k), True, 0)
        result, solves, impulse = self._solve(prong_rows, prong_b)
        self.velocity = self.velocity + self._minv * impulse
        self._com = self._com + self.dt * self.velocity
        normal, tangential = np.zeros(k), np.zeros(k)
        normal[touching] = result.p[0 : 2 * len(touching) : 2] / self.dt
        tangential[touching] = result.p[1 : 2 * len(touching) : 2] / self.dt
        return StepReport(normal, tangential, bool(result.converged), solves)

    def _prong_rows(self, prongs: np.ndarray, prong_vel: np.ndarray):
        """Normal and tangential rows (2c, 3) of the c prongs within reach, their free
        velocity terms (2c,) and their indices."""
        x, y, th = self._com
        c, s = math.cos(th), math.sin(th)
        rows, bias, touching = [], [], []
        for j, ((px, py), (vx, vy)) in enumerate(
            zip(prongs.tolist(), prong_vel.tolist(), strict=True)
        ):
            lx, ly = c * (px - x) + s * (py - y), -s * (px - x) + c * (py - y)
            dist, nx, ny, cx, cy = self.slider.polygon.query(lx, ly)
            gap = dist - self.pusher.radius
            if gap - math.hypot(vx, vy) * self.dt > _REACH:
                continue
            # Impulse direction on the slider: into it, against the outward normal.
            nwx, nwy = -(c * nx - s * ny), -(s * nx + c * ny)
            rx, ry = c * cx - s * cy, s * cx + c * cy
            twx, twy = -nwy, nwx
            rows.append((nwx, nwy, rx * nwy - ry * nwx))
            rows.append((twx, twy, rx * twy - ry * twx))
            closing = gap if gap >= 0 else _PENETRATION_RECOVERY * gap
            bias.append(-(nwx * vx + nwy * vy) + closing / self.dt)
            bias.append(-(twx * vx + twy * vy))
            touching.append(j)
        return np.array(rows).reshape(-1, 3), np.array(bias), touching

    def _support_offsets(self) -> np.ndarray:
        th = self._com[2]
        c, s = math.cos(th), math.sin(th)
        sx, sy = self.slider.supports[:, 0], self.slider.supports[:, 1]
        return np.stack((c * sx - s * sy, s * sx + c * sy), 1)

    def _solve(self, prong_rows: np.ndarray, prong_b: np.ndarray):
        r = self._support_offsets()
        dirs = np.broadcast_to(self._ground_dirs, (len(r),) + self._ground_dirs.shape)
        bound = np.repeat(self._bounds * self._bound_share, len(self._ground_dirs))
        result, impulse = self._solve_rows(prong_rows, prong_b, r, dirs, bound)
        return result, 1, impulse

    def _solve_rows(self, prong_rows, prong_b, r, dirs, bound):
        """Assemble and solve the MLCP; ``dirs`` (S, m, 2) row directions per support point
        (rows with a zero bound left out) and ``bound`` (S·m,) their bounds [N·s]."""
        d = dirs.reshape(-1, 2)
        rr = np.repeat(r, dirs.shape[1], axis=0)
        keep = bound > 0
        ground = np.column_stack((d, rr[:, 0] * d[:, 1] - rr[:, 1] * d[:, 0]))[keep]
        jac = np.vstack((prong_rows, ground))
        n_prong, n = len(prong_rows), len(jac)
        b = jac @ self.velocity
        b[:n_prong] = prong_b + b[:n_prong]
        lo = np.concatenate((np.tile([0.0, 0.0], n_prong // 2), -bound[keep]))
        hi = np.concatenate((np.tile([np.inf, 0.0], n_prong // 2), bound[keep]))
        findex = np.full(n, -1, dtype=np.int64)
        findex[1:n_prong:2] = np.arange(0, n_prong, 2)
        mu = np.zeros(n)
        mu[1:n_prong:2] = self.friction.mu_contact
        scaled = jac * self._minv
        dmat = scaled @ jac.T
        diagonal = np.full(n, 1.0 + _GROUND_COMPLIANCE)
        diagonal[:n_prong] = 1.0 + _PRONG_REGULARISATION
        dmat[np.diag_indices(n)] *= diagonal
        warm = self._warm if self._warm is not None and len(self._warm) == n else None
        result = solve_box_mlcp(dmat, b, lo, hi, findex, mu, warm_start=warm, validate=False)
        self._warm = result.p
        return result, jac.T @ result.p

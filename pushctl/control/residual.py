"""How a residual planar twist reaches the PD baseline (Algorithm 1, docs/design.md §5).

A residual is a planar pusher twist v_θ = (vx [m/s], vy [m/s], ω_z [rad/s]), world axes. Two
paths carry it into the PD law ``v_e = v_ff + K_x (x_ref − x)``:

- ``reference`` (the default): the twist moves the reference. It is integrated into an
  offset of the pusher reference, x_ref = x_plan + ∫ v_θ dt (x, y and yaw), and the reference
  moves at v_ff + v_θ, so the PD servoes the shifted reference. A bounded twist builds an
  offset of any size, and the offset stays when the twist stops (a shut gate freezes it).
- ``velocity`` (the paper's form): the twist is added to v_e only. Against the position gain
  K_x a held twist v shifts the pusher by v / K_x only (0.47 mm at 20 mm/s, K_x = 42.4 /s),
  and the shift decays within ~1 / K_x once the twist stops.

Both give the PD the same commanded twist in the step the residual is applied; they differ
in what the reference remembers afterwards.

The ``reference`` path's offset can be bounded (``limit``): each of x, y [m] and yaw [rad]
is clipped to ±limit, and the reference then moves only as far as the clipped offset does.
The bound is anti-windup: without it a correction that cannot take effect (a prong that slid
off, an object that no longer follows) integrates into offsets of tens of mm and degrees.
"""

from __future__ import annotations

import math

import numpy as np

from pushctl.errors import ConfigError

RESIDUAL_PATHS = ("reference", "velocity")
"""The residual paths: the default first."""


def check_residual_path(path: object) -> str:
    """``path`` if it is one of :data:`RESIDUAL_PATHS`; ConfigError (one line) otherwise."""
    if path not in RESIDUAL_PATHS:
        raise ConfigError(f"residual_path must be one of {', '.join(RESIDUAL_PATHS)}, got {path!r}")
    return str(path)


class ReferenceOffset:
    """The pusher reference's offset from the plan built by the ``reference`` path:
    ``offset`` (3,) [m, m, rad], world x, y and yaw. ``dt`` [s]: the control step.
    ``limit`` (linear [m], angular [rad]): the offset's bound per component (None or inf:
    unbounded).

    Kept as three Python floats: :meth:`shifted` runs at every step, and numpy's per-call
    cost on a 3-vector was most of its time. The arithmetic is the numpy form's,
    component by component (``np.clip`` is ``min(max(x, lo), hi)``), so the same bits."""

    def __init__(self, dt: float, limit: tuple[float, float] | None = None) -> None:
        self.dt = float(dt)
        self._offset = (0.0, 0.0, 0.0)
        self.limit: tuple[float, float, float] | None = None
        if limit is not None:
            linear, angular = (float(value) for value in limit)
            if not (linear > 0.0 and angular > 0.0):  # also catches NaN
                raise ConfigError(
                    f"offset limit must be > 0 (m, rad; inf for none), got {tuple(limit)!r}"
                )
            if math.isfinite(linear) or math.isfinite(angular):
                self.limit = (linear, linear, angular)

    @property
    def offset(self) -> np.ndarray:
        """The offset so far (3,) [m, m, rad] (a new array)."""
        return np.array(self._offset)

    @offset.setter
    def offset(self, value: np.ndarray) -> None:
        x, y, yaw = np.asarray(value, dtype=float).tolist()
        self._offset = (x, y, yaw)

    def reset(self) -> None:
        self._offset = (0.0, 0.0, 0.0)

    def shifted(
        self, position: np.ndarray, yaw: float, twist_ff: np.ndarray, residual: np.ndarray | None
    ) -> tuple[np.ndarray, float, np.ndarray]:
        """The reference of this step: the planned ``position`` (3,) [m] and ``yaw`` [rad]
        plus the offset so far, the feed-forward ``twist_ff`` (6,) plus ``residual`` (3,) (the
        reference's own rate), and the offset advanced by ``residual`` · dt for the next step
        (clipped to ``limit``; the rate added to the twist is then the clipped offset's).
        Returns (position (3,), yaw, twist (6,))."""
        o_x, o_y, o_w = self._offset
        shifted_position = position.copy()
        shifted_position[0] += o_x
        shifted_position[1] += o_y
        shifted_yaw = float(yaw) + o_w
        if residual is None:
            return shifted_position, shifted_yaw, twist_ff
        dt = self.dt
        rates = residual.tolist()
        old = self._offset
        advanced = [old[i] + dt * rates[i] for i in range(3)]
        if self.limit is not None:
            for i, bound in enumerate(self.limit):
                clipped = min(max(advanced[i], -bound), bound)
                if clipped != advanced[i]:  # only a clipped component's rate changes
                    rates[i] = (clipped - old[i]) / dt
                    advanced[i] = clipped
        twist = twist_ff.copy()
        twist[0] += rates[0]
        twist[1] += rates[1]
        twist[5] += rates[2]
        self._offset = (advanced[0], advanced[1], advanced[2])
        return shifted_position, shifted_yaw, twist

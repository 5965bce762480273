"""Ground friction that varies smoothly over the table (docs/design.md §9, a plant unknown).

μ(p) = μ_g · (1 + a · tanh(f(p) / 2)) at a table point p (2,) [m], with f a stationary
Gaussian random field of unit variance and squared-exponential covariance
exp(−‖Δp‖² / (2 ℓ²)), ℓ the correlation length [m]. f is sampled by random Fourier features
(Rahimi & Recht 2007; the "randomisation method" of Kraichnan 1970 that GSTools implements):
f(p) = √(2/M) Σ_m cos(k_m · p + φ_m) with k_m ~ N(0, I/ℓ²) and φ_m ~ U(0, 2π), M modes.
With M = 128 the covariance is that of the kernel to a few percent and f is smooth
everywhere, cheap to evaluate at the few support points of every step, and defined on the
whole table without a grid. tanh keeps the multiplier strictly inside 1 ± a (two thirds of
the table lies within ±0.46 a). The field is a pure function of its seed.

Written here rather than taken from GSTools: the sum is four lines, while GSTools' call
overhead per evaluation (it is built for large grids) would dominate a 4-point query made
every simulation step.
"""

from __future__ import annotations

import math

import numpy as np

from pushctl.contact.compiled import friction_field as compiled
from pushctl.errors import ConfigError

N_MODES = 128
"""Fourier modes of the field."""


class FrictionField:
    """A smooth random multiplier of μ_g over the table (see the module docstring).

    ``variation`` a in [0, 1): the multiplier stays inside 1 ± a; ``length`` ℓ [m] the
    correlation length; ``seed`` an integer >= 0 that fixes the field.
    """

    def __init__(self, variation: float, length: float, seed: int, n_modes: int = N_MODES):
        if not (math.isfinite(variation) and 0.0 <= variation < 1.0):
            raise ConfigError(f"friction variation must be in [0, 1), got {variation!r}")
        if not (math.isfinite(length) and length > 0.0):
            raise ConfigError(f"friction correlation length must be > 0 m, got {length!r}")
        rng = np.random.default_rng(np.random.SeedSequence(int(seed)))
        self.variation, self.length, self.seed = float(variation), float(length), int(seed)
        self._wavevectors = rng.normal(size=(n_modes, 2)) / length  # (M, 2) [rad/m]
        self._phases = rng.uniform(0.0, 2.0 * math.pi, size=n_modes)  # (M,)
        self._amplitude = math.sqrt(2.0 / n_modes)

    def unit_field(self, points: np.ndarray) -> np.ndarray:
        """f at table points ``points`` (..., 2) [m]: unit variance, zero mean, shape (...)."""
        points = np.asarray(points, dtype=float)
        angles = points @ self._wavevectors.T + self._phases
        return self._amplitude * np.cos(angles).sum(axis=-1)

    def __call__(self, points: np.ndarray) -> np.ndarray:
        """μ(p)/μ_g at table points ``points`` (..., 2) [m], shape (...), in (1 − a, 1 + a)
        (compiled: the plant's force plan asks for every support point of every sample)."""
        points = np.asarray(points, dtype=float)
        flat = np.ascontiguousarray(points.reshape(-1, 2))
        values = compiled.multiplier(
            flat, self._wavevectors, self._phases, self._amplitude, self.variation
        )
        return values.reshape(points.shape[:-1])

    def at_support_points(self, pose: np.ndarray, support_points: np.ndarray) -> np.ndarray:
        """μ(p_j)/μ_g (S,) at the table positions of ``support_points`` (S, 2) [m] (object
        frame) of an object at ``pose`` (3,): the world's per-step query, compiled."""
        return compiled.support_multiplier(
            pose, support_points, self._wavevectors, self._phases, self._amplitude, self.variation
        )

    def update_support_bounds(
        self,
        pose: np.ndarray,
        support_points: np.ndarray,
        uniform_limits: np.ndarray,
        limits: np.ndarray,
        guess: np.ndarray | None,
    ) -> np.ndarray | None:
        """The world's per-step friction bounds in one compiled call: ``limits`` (S,) [N]
        rewritten in place with μ(p_j) N_j = ``uniform_limits`` (μ_g N_j) ×
        :meth:`at_support_points`; returns ``guess`` (n,) (the last impulses, ground rows
        last, 2 per support point) with its ground rows scaled by new/old bound (a new
        array; None stays None). Same arithmetic as the numpy form."""
        scaled = _EMPTY if guess is None else np.empty(guess.size)
        compiled.update_support_bounds(
            pose, support_points, self._wavevectors, self._phases, self._amplitude,
            self.variation, uniform_limits, limits, _EMPTY if guess is None else guess, scaled,
        )  # fmt: skip
        return None if guess is None else scaled


_EMPTY = np.zeros(0)


def support_positions(pose: np.ndarray, support_points: np.ndarray) -> np.ndarray:
    """Table positions (..., S, 2) [m] of support points (S, 2) [m] (object frame) of an
    object at ``pose`` (..., 3) (x [m], y [m], θ [rad])."""
    pose = np.asarray(pose, dtype=float)
    c, s = np.cos(pose[..., 2:3]), np.sin(pose[..., 2:3])
    px, py = support_points[:, 0], support_points[:, 1]
    return np.stack([pose[..., 0:1] + c * px - s * py, pose[..., 1:2] + s * px + c * py], axis=-1)

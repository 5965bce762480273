"""Angular profiles: how the plan moves along its arc in time.

A profile is a map s: [0, 1] → [0, 1] of normalised time τ = t/T to the fraction of the arc
covered, with s(0) = 0, s(1) = 1 and s'(τ) ≥ 0, so every profile shares the geometry of the
arc and only its timing differs (docs/design.md §4). :meth:`AngularProfile.evaluate` returns s and
its first two derivatives with respect to τ, analytically; divide by T and T² for time
derivatives.

``constant`` is the paper's uniform rotation: s' = 1, a step in rate at both ends.
``trapezoid`` accelerates uniformly, cruises and decelerates. ``chirp`` oscillates the rate
about its mean of 1 with a frequency rising linearly in time and stays non-negative.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pushctl.errors import ConfigError

PROFILE_NAMES = ("constant", "trapezoid", "chirp")
"""Names accepted by :func:`make_profile`."""

MIN_RAMP_FRACTION = 1e-6
"""Shortest non-zero trapezoid ramp [fraction of the push]: below it the ramp's acceleration
(cruise rate / fraction) overflows; use 0 for a step in rate."""


@dataclass(frozen=True)
class AngularProfile:
    """Base class: ``evaluate(tau)`` gives ``(s, ds, dds)``, each shaped like ``tau``."""

    @property
    def name(self) -> str:
        raise NotImplementedError

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        raise NotImplementedError


@dataclass(frozen=True)
class ConstantProfile(AngularProfile):
    """s = τ: uniform rotation (and uniform speed along the arc)."""

    @property
    def name(self) -> str:
        return "constant"

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        tau = np.asarray(tau, dtype=float)
        return tau.copy(), np.ones_like(tau), np.zeros_like(tau)


@dataclass(frozen=True)
class TrapezoidProfile(AngularProfile):
    """Uniform acceleration over the first ``accel_fraction`` of the push, cruise, uniform
    deceleration over the last ``decel_fraction``; the cruise rate is 2 / (2 − a − d).
    A zero fraction is a step in rate at that end; both zero is ``constant``."""

    accel_fraction: float = 0.25
    decel_fraction: float = 0.25

    def __post_init__(self) -> None:
        a, d = self.accel_fraction, self.decel_fraction
        for label, value in (("accel_fraction", a), ("decel_fraction", d)):
            if not (math.isfinite(value) and (value == 0.0 or MIN_RAMP_FRACTION <= value <= 1.0)):
                raise ConfigError(
                    f"trapezoid {label} must be 0 or in [{MIN_RAMP_FRACTION:g}, 1], got {value!r}"
                )
        if a + d > 1.0 + 1e-12:
            raise ConfigError(
                f"trapezoid accel_fraction + decel_fraction must be <= 1, got {a} + {d}"
            )

    @property
    def name(self) -> str:
        return "trapezoid"

    @property
    def cruise_rate(self) -> float:
        """ds/dτ while cruising [-]."""
        return 2.0 / (2.0 - self.accel_fraction - self.decel_fraction)

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        tau = np.asarray(tau, dtype=float)
        a, d, rate = self.accel_fraction, self.decel_fraction, self.cruise_rate
        s = rate * (tau - 0.5 * a)  # cruise phase
        ds = np.full_like(tau, rate)
        dds = np.zeros_like(tau)
        if a > 0.0:
            rising = tau < a
            s = np.where(rising, 0.5 * rate * tau**2 / a, s)
            ds = np.where(rising, rate * tau / a, ds)
            dds = np.where(rising, rate / a, dds)
        if d > 0.0:
            left = 1.0 - tau
            falling = left < d
            s = np.where(falling, 1.0 - 0.5 * rate * left**2 / d, s)
            ds = np.where(falling, rate * left / d, ds)
            dds = np.where(falling, -rate / d, dds)
        return s, ds, dds


@dataclass(frozen=True)
class ChirpProfile(AngularProfile):
    """Rate oscillating about its mean with a linearly rising frequency.

    With phase φ(τ) = 2π (f0 τ + (f1 − f0) τ²/2) (``start_cycles`` f0 and ``end_cycles`` f1 are
    instantaneous frequencies in cycles per push), s(τ) = τ − B sin φ(τ) + B τ sin φ(1).
    Then s(0) = 0 and s(1) = 1 exactly, the mean rate is 1, and
    s' = 1 + B sin φ(1) − B φ'(τ) cos φ(τ) oscillates with amplitude B φ'(τ), which grows
    with the frequency. B is chosen so that the deepest dip reaches 1 − ``depth`` of the mean
    at most: B (φ'_max + |sin φ(1)|) = ``depth`` ≤ 1 keeps s' ≥ 0.
    """

    start_cycles: float = 1.0
    end_cycles: float = 4.0
    depth: float = 0.8

    def __post_init__(self) -> None:
        for label, value in (("start_cycles", self.start_cycles), ("end_cycles", self.end_cycles)):
            if not (math.isfinite(value) and value > 0.0):
                raise ConfigError(f"chirp {label} must be a positive number, got {value!r}")
        if self.end_cycles < self.start_cycles:
            raise ConfigError(
                f"chirp end_cycles must be >= start_cycles (a rising frequency), got "
                f"{self.start_cycles} → {self.end_cycles}"
            )
        if not (math.isfinite(self.depth) and 0.0 <= self.depth <= 1.0):
            raise ConfigError(f"chirp depth must be in [0, 1], got {self.depth!r}")

    @property
    def name(self) -> str:
        return "chirp"

    def _phase(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        f0, f1 = self.start_cycles, self.end_cycles
        phase = 2.0 * math.pi * (f0 * tau + 0.5 * (f1 - f0) * tau**2)
        phase_rate = 2.0 * math.pi * (f0 + (f1 - f0) * tau)
        return phase, phase_rate, 2.0 * math.pi * (f1 - f0)

    @property
    def amplitude(self) -> float:
        """B [-] (see the class docstring)."""
        end_phase = math.pi * (self.start_cycles + self.end_cycles)
        peak_rate = 2.0 * math.pi * self.end_cycles  # φ' is largest at τ = 1
        return self.depth / (peak_rate + abs(math.sin(end_phase)))

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        tau = np.asarray(tau, dtype=float)
        phase, phase_rate, phase_accel = self._phase(tau)
        b = self.amplitude
        end_sine = math.sin(math.pi * (self.start_cycles + self.end_cycles))
        s = tau - b * np.sin(phase) + b * end_sine * tau
        ds = 1.0 + b * end_sine - b * phase_rate * np.cos(phase)
        dds = b * phase_rate**2 * np.sin(phase) - b * phase_accel * np.cos(phase)
        return s, ds, dds


def make_profile(name: str, **parameters: float) -> AngularProfile:
    """The profile called ``name`` (one of ``PROFILE_NAMES``) with optional parameters."""
    classes: dict[str, type[AngularProfile]] = {
        "constant": ConstantProfile,
        "trapezoid": TrapezoidProfile,
        "chirp": ChirpProfile,
    }
    if name not in classes:
        raise ConfigError(f"unknown profile {name!r}: choose one of {', '.join(PROFILE_NAMES)}")
    try:
        return classes[name](**parameters)
    except TypeError:
        raise ConfigError(f"profile {name!r} takes no parameters {sorted(parameters)}") from None

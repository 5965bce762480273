"""The sane range of every physical value a user gives, in one place.

A value outside its range is refused where it is read (an object or pusher file, a gains
file, a preset, a command-line option) with one line naming the quantity, its range and
unit, and the value, before any work: a 1e-9 kg object or a gain of 1e300 would otherwise
run and fail late (a lost contact, a solver fault, an allocation of petabytes).

The ranges are wide: every value the project ships, tunes over or tests sits well inside
them; they only catch what cannot be meant (a typo's orders of magnitude, a zero where the
physics needs a size).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pushctl.errors import ConfigError


@dataclass(frozen=True)
class Range:
    """Accepted values ``low``–``high`` in ``unit`` (both ends included)."""

    low: float
    high: float
    unit: str

    def text(self) -> str:
        unit = f" {self.unit}" if self.unit else ""
        return f"{self.low:g}..{self.high:g}{unit}"


RANGES: dict[str, Range] = {
    # objects and pushers (Table II's are 0.03-0.42 kg, 70 mm apart)
    "object mass": Range(0.01, 50.0, "kg"),
    "pusher mass": Range(0.001, 10.0, "kg"),
    "prong spacing": Range(0.005, 0.5, "m"),  # two prongs or more: they must be apart
    "pusher plate size": Range(0.001, 1.0, "m"),  # the paper's: 104 × 48 × 30 mm
    # PD gains (tuned: kp 30, kv 300, kx 42; a test saturates the torques with 1e6)
    "PD gain kp": Range(0.0, 1e6, "N·m/rad"),
    "PD gain kv": Range(1e-6, 1e6, "N·m·s/rad"),
    "PD gain kx_linear": Range(0.0, 1e4, "1/s"),
    "PD gain kx_angular": Range(0.0, 1e4, "1/s"),
    "PD gain ik_damping": Range(0.0, 10.0, ""),
    "PD gain posture_gain": Range(0.0, 1e3, "1/s"),
    # the feedback law (tuned: k 1 /s, k_i 0.1 /s², 0.05 N)
    "feedback k": Range(0.0, 100.0, "1/s"),
    "feedback k_i": Range(0.0, 1e3, "1/s²"),
    "feedback contact_force": Range(0.0, 100.0, "N"),
    # networks (the presets: two layers of 256 or fewer)
    "hidden layer width": Range(1, 4096, "units"),
    "hidden layers": Range(1, 8, ""),
    # training (the presets: 2500 episodes or fewer, buffers of 1e6 transitions)
    "replay buffer size": Range(1, 1e8, "transitions"),
    "training episodes": Range(1, 1e6, ""),
    # poses on the table (the arm reaches about 1 m)
    "position": Range(-10.0, 10.0, "m"),
    "angle": Range(-360.0, 360.0, "deg"),
    # recorded pushes (published fits: μ 0.1-0.5)
    "friction coefficient": Range(0.0, 10.0, ""),
}
"""Quantity → its accepted range."""


def check_range(quantity: str, value: float, where: str = "") -> float:
    """``value`` if it is a finite number within ``RANGES[quantity]``, else ConfigError (one
    line; ``where`` names the file or option it came from, ``"gains file X: "``)."""
    accepted = RANGES[quantity]
    number = value if isinstance(value, (int, float)) and not isinstance(value, bool) else None
    if number is None or not math.isfinite(number) or not (accepted.low <= number <= accepted.high):
        raise ConfigError(f"{where}{quantity} must be within {accepted.text()}, got {value!r}")
    return value

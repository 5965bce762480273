"""Frozen configuration dataclasses shared by the core.

Units: SI throughout (m, kg, s, N, N·m, rad). Defaults are the nominal values of
DESIGN.md §9 and the paper's Table II.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pushctl.errors import ConfigError

GRAVITY = 9.81
"""Magnitude of gravitational acceleration [m/s²], along world −z."""


@dataclass(frozen=True)
class PusherConfig:
    """The two-prong pusher plate of Table II, fixed to the arm's end effector.

    The plate is ``width`` [m] along the pushed face (the contact tangent e_t),
    ``height`` [m] vertically and ``thickness`` [m] along the push direction. Its prongs are
    points on the front face at mid-height, ``prong_spacing`` [m] apart, centred.
    """

    mass: float = 0.030
    width: float = 0.104
    height: float = 0.048
    thickness: float = 0.030
    n_prongs: int = 2
    prong_spacing: float = 0.070

    def __post_init__(self) -> None:
        for field in ("mass", "width", "height", "thickness"):
            value = getattr(self, field)
            if not np.isfinite(value) or value <= 0.0:
                raise ConfigError(f"pusher {field} must be a positive number, got {value!r}")
        if not (isinstance(self.n_prongs, int) and 1 <= self.n_prongs <= 4):
            raise ConfigError(f"pusher n_prongs must be an integer in 1..4, got {self.n_prongs!r}")
        if not np.isfinite(self.prong_spacing) or self.prong_spacing < 0.0:
            raise ConfigError(f"pusher prong_spacing must be >= 0 m, got {self.prong_spacing!r}")
        span = self.prong_spacing * (self.n_prongs - 1)
        if span > self.width + 1e-12:
            raise ConfigError(
                f"{self.n_prongs} prongs {self.prong_spacing} m apart span {span:.3f} m, "
                f"wider than the {self.width} m plate"
            )

    def prong_offsets(self) -> np.ndarray:
        """Tangential offsets of the prongs from the plate centre, (k,) [m], ascending."""
        k = self.n_prongs
        return self.prong_spacing * (np.arange(k) - (k - 1) / 2.0)

"""Frozen configuration dataclasses shared by the core.

Units: SI throughout (m, kg, s, N, N·m, rad). Defaults are the nominal values of
docs/design.md §9 and the paper's Table II.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from pushctl.errors import ConfigError
from pushctl.ranges import check_range

PLANT_KINDS = ("sim", "proxy", "mujoco")
"""The plant kinds (docs/glossary.md): the training simulator, the held-out reality proxy, and
MuJoCo (the same scene on another engine, evaluation only, parameters from the ``sim`` ranges;
docs/mujoco.md). Defined here once, for the simulator's side and the report's alike."""

GRAVITY = 9.81
"""Magnitude of gravitational acceleration [m/s²], along world −z."""


@dataclass(frozen=True)
class PusherConfig:
    """The two-prong pusher plate of Table II, fixed to the arm's end effector.

    The plate is ``width`` [m] along the pushed face (the contact tangent e_t),
    ``height`` [m] vertically and ``thickness`` [m] along the push direction. Its prongs are
    points on the front face at mid-height, ``prong_spacing`` [m] apart, centred.

    Mounting/calibration error (docs/design.md §9; zero on the nominal pusher the planner and the
    controllers use): ``mount_yaw`` [rad] turns the plate about the tool axis, counter-
    clockwise seen from above; ``prong_errors`` ((along the push, along the face) [m] per
    prong, or empty for none) displaces each prong on the plate.
    """

    mass: float = 0.030
    width: float = 0.104
    height: float = 0.048
    thickness: float = 0.030
    n_prongs: int = 2
    prong_spacing: float = 0.070
    mount_yaw: float = 0.0
    prong_errors: tuple[tuple[float, float], ...] = ()

    def __post_init__(self) -> None:
        if not (np.isfinite(self.mount_yaw) and abs(self.mount_yaw) <= 0.5):
            raise ConfigError(f"pusher mount_yaw must be within ±0.5 rad, got {self.mount_yaw!r}")
        errors = np.asarray(self.prong_errors, dtype=float)
        if errors.size and (
            errors.shape != (self.n_prongs, 2)
            or not np.all(np.isfinite(errors))
            or np.abs(errors).max() > 0.01
        ):
            raise ConfigError(
                f"pusher prong_errors must be {self.n_prongs} pairs (along, across) within "
                f"±0.01 m, got {self.prong_errors!r}"
            )
        for field in ("mass", "width", "height", "thickness"):
            value = getattr(self, field)
            if not np.isfinite(value) or value <= 0.0:
                raise ConfigError(f"pusher {field} must be a positive number, got {value!r}")
        check_range("pusher mass", self.mass, "pusher: ")
        for field in ("width", "height", "thickness"):
            check_range("pusher plate size", getattr(self, field), f"pusher {field}: ")
        if not (isinstance(self.n_prongs, int) and 1 <= self.n_prongs <= 4):
            raise ConfigError(f"pusher n_prongs must be an integer in 1..4, got {self.n_prongs!r}")
        if not np.isfinite(self.prong_spacing) or self.prong_spacing < 0.0:
            raise ConfigError(f"pusher prong_spacing must be >= 0 m, got {self.prong_spacing!r}")
        if self.n_prongs > 1:
            check_range("prong spacing", self.prong_spacing, f"pusher of {self.n_prongs} prongs: ")
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

    def prong_points(self) -> np.ndarray:
        """The prongs on the plate's front face, (k, 2) [m]: (along the push, along the face)
        in the pusher frame, the nominal (0, offset) plus any ``prong_errors``."""
        points = np.column_stack([np.zeros(self.n_prongs), self.prong_offsets()])
        if self.prong_errors:
            points = points + np.asarray(self.prong_errors, dtype=float)
        return points

    @property
    def nominal(self) -> PusherConfig:
        """This pusher without its mounting error (what the planner and controllers assume)."""
        return replace(self, mount_yaw=0.0, prong_errors=())

"""Plant unknowns (docs/design.md §6, §9): what the simulated world has and the planner and the
controllers never see.

- object placement error: the object's true start pose is the believed one composed with
  ``placement`` = (along, across, Δθ) in the believed start's frame [m, m, rad] (true =
  believed ⊕ error, SE(2)); the plan, the approach and the controller use the believed pose;
- pusher mounting error: the plate turned by ``mount_yaw`` [rad] about the tool axis and each
  prong displaced by ``prong_errors[i]`` = (along the push, along the face) [m] on the plate:
  the world's pusher has them, the controller's arm model does not;
- centre-of-pressure offset: the support loads balance about ``pressure_offset`` (fractions
  of the footprint's half-extents along e_n and e_t [-]) instead of the centre of mass;
- ground friction over the table: μ_g times a smooth random field of relative amplitude
  ``ground_variation`` [-] and correlation length ``ground_length`` [m], from ``ground_seed``.

The unknowns come from their own generator (:func:`unknowns_rng`: the scenario's seed and
stream with one more spawn key), so drawing them leaves every other draw of a seed unchanged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np

from pushctl.config import GRAVITY
from pushctl.contact.ground_field import FrictionField, support_positions
from pushctl.errors import ConfigError
from pushctl.objects import ObjectSpec, with_pressure_offset

UNKNOWNS_KEY = 7
"""The extra spawn key of the unknowns' generator (after the stream's)."""

MAX_PRONGS = 4
"""Prong errors drawn per scenario, whatever the pusher's k (the first k are used), so the
draw does not depend on the pusher."""


@dataclass(frozen=True)
class UnknownRanges:
    """Half-widths of the plant unknowns' uniform ranges (each drawn in [−w, w]), docs/design.md §9.

    ``placement_along``, ``placement_across`` [m] and ``placement_yaw_deg`` [deg]: the object's
    placement error; ``mount_yaw_deg`` [deg]: the plate's yaw on the end effector;
    ``prong_offset`` [m]: each prong's displacement on the plate, per axis;
    ``pressure_offset`` [-]: the centre of pressure's shift as a fraction of the half-extents;
    ``ground_variation`` [-]: the friction field's amplitude relative to μ_g;
    ``ground_length`` [m]: its correlation length (not a range: the field's scale).
    """

    placement_along: float = 0.0
    placement_across: float = 0.0
    placement_yaw_deg: float = 0.0
    mount_yaw_deg: float = 0.0
    prong_offset: float = 0.0
    pressure_offset: float = 0.0
    ground_variation: float = 0.0
    ground_length: float = 0.05

    def __post_init__(self) -> None:
        limits = {
            "placement_along": 0.05,
            "placement_across": 0.05,
            "placement_yaw_deg": 30.0,
            "mount_yaw_deg": 30.0,
            "prong_offset": 0.01,
            "pressure_offset": 0.9,
            "ground_variation": 0.9,
            "ground_length": 10.0,
        }
        for name, highest in limits.items():
            value = getattr(self, name)
            ok = isinstance(value, (int, float)) and not isinstance(value, bool)
            if not (ok and math.isfinite(value) and 0.0 <= value <= highest):
                raise ConfigError(
                    f"unknowns {name} must be a number in [0, {highest:g}], got {value!r}"
                )
        if self.ground_length <= 0.0:
            raise ConfigError(f"unknowns ground_length must be > 0 m, got {self.ground_length!r}")

    def draw(self, rng: np.random.Generator) -> PlantUnknowns:
        """Unknowns drawn uniformly in the ranges: always the same 3 + 1 + 2·MAX_PRONGS + 2
        unit uniforms and one field seed, in that order, whatever the ranges (so the sim and
        the proxy plant of one seed scale the same draws)."""
        unit = rng.uniform(-1.0, 1.0, size=6 + 2 * MAX_PRONGS)
        field_seed = int(rng.integers(2**63 - 1))
        prongs = unit[4 : 4 + 2 * MAX_PRONGS].reshape(MAX_PRONGS, 2) * self.prong_offset
        return PlantUnknowns(
            placement=(
                float(unit[0] * self.placement_along),
                float(unit[1] * self.placement_across),
                float(unit[2] * math.radians(self.placement_yaw_deg)),
            ),
            mount_yaw=float(unit[3] * math.radians(self.mount_yaw_deg)),
            prong_errors=tuple((float(a), float(b)) for a, b in prongs),
            pressure_offset=(
                float(unit[-2] * self.pressure_offset),
                float(unit[-1] * self.pressure_offset),
            ),
            ground_variation=float(self.ground_variation),
            ground_length=float(self.ground_length),
            ground_seed=field_seed,
        )


@dataclass(frozen=True)
class PlantUnknowns:
    """One episode's drawn unknowns (see the module docstring); the default is none at all."""

    placement: tuple[float, float, float] = (0.0, 0.0, 0.0)
    mount_yaw: float = 0.0
    prong_errors: tuple[tuple[float, float], ...] = ()
    pressure_offset: tuple[float, float] = (0.0, 0.0)
    ground_variation: float = 0.0
    ground_length: float = 0.05
    ground_seed: int = 0

    def __post_init__(self) -> None:
        values = [*self.placement, self.mount_yaw, *self.pressure_offset, self.ground_variation]
        values += [v for pair in self.prong_errors for v in pair]
        if len(self.placement) != 3 or len(self.pressure_offset) != 2:
            raise ConfigError("unknowns: placement is (along, across, dθ), pressure_offset (n, t)")
        if any(len(pair) != 2 for pair in self.prong_errors) or len(self.prong_errors) > MAX_PRONGS:
            raise ConfigError(
                f"unknowns: prong_errors are up to {MAX_PRONGS} pairs (along, across)"
            )
        if not all(math.isfinite(v) for v in values):
            raise ConfigError(f"unknowns must be finite numbers, got {self!r}")

    @property
    def is_none(self) -> bool:
        """Whether the world is exactly what the planner believes (every unknown zero)."""
        zero = all(v == 0.0 for v in (*self.placement, *self.pressure_offset))
        return zero and self.ground_variation == 0.0 and not self.has_mounting_error

    @property
    def has_mounting_error(self) -> bool:
        return self.mount_yaw != 0.0 or any(v != 0.0 for pair in self.prong_errors for v in pair)

    def acting_in(self, engine: str) -> PlantUnknowns:
        """The unknowns that ``engine``'s world carries: all of them in ours; in MuJoCo's
        the placement and mounting errors only. Its object rests on its own floor contact,
        whose loads balance about the centre of mass (no centre-of-pressure offset), with
        one μ_g per geom pair (no friction field): docs/mujoco.md."""
        if engine == "ours":
            return self
        return replace(self, pressure_offset=(0.0, 0.0), ground_variation=0.0)

    def prong_errors_for(self, n_prongs: int) -> tuple[tuple[float, float], ...]:
        """The first ``n_prongs`` prong errors (zeros where none were drawn)."""
        errors = list(self.prong_errors[:n_prongs])
        return tuple(errors + [(0.0, 0.0)] * (n_prongs - len(errors)))

    def true_start(self, believed: np.ndarray) -> np.ndarray:
        """The object's true start pose (3,) = ``believed`` (3,) ⊕ placement [m, m, rad]."""
        x, y, theta = (float(v) for v in believed)
        along, across, dtheta = self.placement
        c, s = math.cos(theta), math.sin(theta)
        return np.array([x + c * along - s * across, y + s * along + c * across, theta + dtheta])

    def as_dict(self, n_prongs: int = 2) -> dict[str, float]:
        """Flat record (SI units, radians) for ``info`` dicts and CSV rows: ``placement_*``,
        ``mount_yaw``, ``prong_{i}_along``/``_across`` (i from 1), ``pressure_n``/``_t``,
        ``ground_variation``, ``ground_length``, ``ground_seed``."""
        record: dict[str, float] = {
            "placement_along": self.placement[0],
            "placement_across": self.placement[1],
            "placement_theta": self.placement[2],
            "mount_yaw": self.mount_yaw,
        }
        for i, (along, across) in enumerate(self.prong_errors_for(n_prongs), start=1):
            record[f"prong_{i}_along"] = along
            record[f"prong_{i}_across"] = across
        record["pressure_n"], record["pressure_t"] = self.pressure_offset
        record["ground_variation"] = self.ground_variation
        record["ground_length"] = self.ground_length
        record["ground_seed"] = self.ground_seed
        return record


def with_unknown_loads(obj: ObjectSpec, unknowns: PlantUnknowns) -> ObjectSpec:
    """``obj`` with the centre-of-pressure offset of ``unknowns`` (fractions of the
    footprint's half-extents along e_n and e_t): the same object if there is none."""
    fractions = np.asarray(unknowns.pressure_offset, dtype=float)
    if not fractions.any():
        return obj
    half_extents = 0.5 * np.ptp(np.asarray(obj.footprint), axis=0)
    return with_pressure_offset(obj, fractions * half_extents)


def friction_field(unknowns: PlantUnknowns) -> FrictionField | None:
    """The ground-friction field of ``unknowns`` (None for a uniform μ_g)."""
    if unknowns.ground_variation == 0.0:
        return None
    return FrictionField(unknowns.ground_variation, unknowns.ground_length, unknowns.ground_seed)


def friction_limits(
    obj: ObjectSpec, mu_ground: float, field: FrictionField, poses: np.ndarray, gravity: float
) -> np.ndarray:
    """Sliding friction μ(p_j) N_j [N] of each support point of ``obj`` at each of ``poses``
    (N, 3), (N, S): what the world's friction field gives there."""
    uniform = mu_ground * np.asarray(obj.support_loads) * (gravity / GRAVITY)
    return uniform * field(support_positions(poses, np.asarray(obj.support_points)))


NO_UNKNOWNS = PlantUnknowns()
"""A plant that is exactly what the planner believes."""


def unknowns_rng(seed: int, stream_key: int) -> np.random.Generator:
    """The unknowns' generator of ``seed`` in the stream whose spawn key is ``stream_key``
    (:data:`pushctl.episode.scenario.STREAMS`): independent of that stream's own generator."""
    sequence = np.random.SeedSequence(int(seed), spawn_key=(int(stream_key), UNKNOWNS_KEY))
    return np.random.default_rng(sequence)


UNKNOWN_RANGE_KEYS = tuple(f.name for f in fields(UnknownRanges))

"""What one episode is: object, profile, start, goal, physical parameters, and where they
come from (nominal values, or draws from the seeded ranges of ``experiments/``).

Random streams. Every draw comes from ``numpy.random.default_rng(SeedSequence(seed,
spawn_key=(stream,)))`` with ``stream`` one of :data:`STREAMS`: the tuning, training and
evaluation streams of one integer seed are independent, so gains tuned on tuning seeds and
a policy trained on training seeds never see an evaluation target. ``pushctl simulate
--seed N`` draws from the evaluation stream, so it replays the evaluation trial of seed N.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from pushctl.config import GRAVITY, PusherConfig
from pushctl.episode.unknowns import PlantUnknowns
from pushctl.errors import ConfigError
from pushctl.planning.profiles import PROFILE_NAMES
from pushctl.types import PlanarPose

STREAMS = {"evaluation": 1, "tuning": 2, "training": 3}
"""Independent random streams of one seed, by purpose."""


def stream_rng(seed: int, stream: str) -> np.random.Generator:
    """The generator of ``stream`` (a key of :data:`STREAMS`) for the integer ``seed`` >= 0."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ConfigError(f"a seed must be an integer >= 0, got {seed!r}")
    if stream not in STREAMS:
        raise ConfigError(f"unknown random stream {stream!r}; accepted: {', '.join(STREAMS)}")
    return np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(STREAMS[stream],)))


@dataclass(frozen=True)
class PhysicalParameters:
    """The plant's physical parameters (docs/design.md §9). ``object_mass`` and ``pusher_mass``
    [kg]: None means the object's Table II value. μ_g and μ_c are Coulomb coefficients."""

    mu_ground: float = 0.30
    mu_contact: float = 0.40
    object_mass: float | None = None
    pusher_mass: float | None = None

    def __post_init__(self) -> None:
        for name in ("mu_ground", "mu_contact"):
            value = getattr(self, name)
            if not (_is_number(value) and math.isfinite(value) and value >= 0.0):
                raise ConfigError(f"{name} must be a finite number >= 0, got {value!r}")
        for name in ("object_mass", "pusher_mass"):
            value = getattr(self, name)
            if value is not None and not (
                _is_number(value) and math.isfinite(value) and value > 0.0
            ):
                raise ConfigError(f"{name} must be a positive number of kg, got {value!r}")


@dataclass(frozen=True)
class Scenario:
    """One episode's set-up. ``start`` None: the default start in front of the arm's ready
    pose (:func:`pushctl.planning.workspace.default_start`). ``goal``: absolute pose.
    ``nominal``: the parameters the planner and controller assume; ``true_parameters``: the
    ones the simulated world has (the same unless randomised; docs/glossary.md: plant
    parameters). ``unknowns``: the plant unknowns the
    world has and the planner and controller do not know (docs/design.md §9; none by default).
    ``start`` is where the planner believes the object starts; the world puts it at
    ``unknowns.true_start(start)``. ``pusher``: the plate and its prongs (a pusher file's,
    :mod:`pushctl.arm.pusher_file`); None: the paper's two-prong plate. Its ``mass`` is the
    pusher's mass wherever the parameters leave ``pusher_mass`` None (else theirs).
    ``seed``: where it was drawn from (recorded with results), None when it was given by
    hand."""

    object: str
    profile: str
    goal: PlanarPose
    start: PlanarPose | None = None
    true_parameters: PhysicalParameters = field(default_factory=PhysicalParameters)
    nominal: PhysicalParameters = field(default_factory=PhysicalParameters)
    seed: int | None = None
    duration: float = 20.0
    dt: float = 0.01
    arm: str = "kinova-gen2-7dof"
    gravity: float = GRAVITY
    unknowns: PlantUnknowns = field(default_factory=PlantUnknowns)
    pusher: PusherConfig | None = None

    def __post_init__(self) -> None:
        if self.pusher is not None and not isinstance(self.pusher, PusherConfig):
            raise ConfigError(f"pusher must be a PusherConfig, got {type(self.pusher).__name__}")
        if not isinstance(self.unknowns, PlantUnknowns):
            raise ConfigError(f"unknowns must be PlantUnknowns, got {type(self.unknowns).__name__}")
        if self.profile not in PROFILE_NAMES:
            raise ConfigError(
                f"unknown profile {self.profile!r}; accepted: {', '.join(PROFILE_NAMES)}"
            )
        for name in ("duration", "dt"):
            value = getattr(self, name)
            if not (_is_number(value) and math.isfinite(value) and value > 0.0):
                raise ConfigError(f"{name} must be a positive number of seconds, got {value!r}")

    def pusher_mass(self, parameters: PhysicalParameters) -> float | None:
        """The pusher mass [kg] of ``parameters`` (the true or the nominal ones): theirs if
        set, else the pusher file's, else None (the object's Table II value)."""
        if parameters.pusher_mass is not None or self.pusher is None:
            return parameters.pusher_mass
        return self.pusher.mass

    def pusher_config(self, mass: float) -> PusherConfig:
        """This scenario's pusher (the paper's plate when None) with ``mass`` [kg]."""
        return replace(self.pusher or PusherConfig(), mass=mass)

    def with_true_parameters(self, parameters: PhysicalParameters) -> Scenario:
        return replace(self, true_parameters=parameters)

    def with_unknowns(self, unknowns: PlantUnknowns) -> Scenario:
        return replace(self, unknowns=unknowns)


@dataclass(frozen=True)
class ParameterRanges:
    """Uniform ranges (lo, hi) of a plant's parameters: μ_g, μ_c, and the object's and the
    pusher's mass as multiples of their Table II values (docs/design.md §9)."""

    mu_ground: tuple[float, float]
    mu_contact: tuple[float, float]
    object_mass_scale: tuple[float, float]
    pusher_mass_scale: tuple[float, float]

    def __post_init__(self) -> None:
        for name in ("mu_ground", "mu_contact", "object_mass_scale", "pusher_mass_scale"):
            check_range(name, getattr(self, name), lowest=0.0)

    def draw(
        self, rng: np.random.Generator, object_mass: float, pusher_mass: float
    ) -> PhysicalParameters:
        """Parameters drawn uniformly (four draws, in the order of the fields)."""
        mu_g, mu_c, m_obj, m_push = (rng.uniform(*getattr(self, name)) for name in _DRAW_ORDER)
        return PhysicalParameters(
            mu_ground=float(mu_g),
            mu_contact=float(mu_c),
            object_mass=float(m_obj * object_mass),
            pusher_mass=float(m_push * pusher_mass),
        )


_DRAW_ORDER = ("mu_ground", "mu_contact", "object_mass_scale", "pusher_mass_scale")


@dataclass(frozen=True)
class TargetRanges:
    """Goal offsets from the start (docs/design.md §7): forward Δx [m], |Δθ| [deg] of either sign,
    and the lateral Δy·sign(Δθ) [m] (the object moves towards the side it turns to)."""

    forward: tuple[float, float] = (0.10, 0.25)
    rotation_deg: tuple[float, float] = (10.0, 45.0)
    lateral: tuple[float, float] = (0.0, 0.05)

    def __post_init__(self) -> None:
        check_range("forward", self.forward, lowest=0.0)
        check_range("rotation_deg", self.rotation_deg, lowest=0.0, highest=180.0)
        check_range("lateral", self.lateral)

    def draw(self, rng: np.random.Generator, start: PlanarPose) -> PlanarPose:
        """A goal (four draws: Δx, |Δθ|, sign, lateral), offsets in the start's frame."""
        forward = rng.uniform(*self.forward)
        rotation = math.radians(rng.uniform(*self.rotation_deg))
        sign = 1.0 if rng.uniform() < 0.5 else -1.0
        lateral = sign * rng.uniform(*self.lateral)
        c, s = math.cos(start.theta), math.sin(start.theta)
        return PlanarPose(
            start.x + c * forward - s * lateral,
            start.y + s * forward + c * lateral,
            start.theta + sign * rotation,
        )


def _is_number(value: object) -> bool:
    """A real number, not a bool (which Python counts as an int)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def check_range(name: str, values, lowest: float = -math.inf, highest: float = math.inf) -> None:
    """ConfigError unless ``values`` is a pair lo <= hi of finite numbers in [lowest, highest]."""
    accepted = f"{name} must be a range [lo, hi] of finite numbers, lo <= hi"
    if lowest > -math.inf:
        accepted += f", within [{lowest:g}, {highest:g}]"
    try:
        lo, hi = (float(v) for v in values)
    except (TypeError, ValueError):
        raise ConfigError(f"{accepted}; got {values!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lowest <= lo <= hi <= highest):
        raise ConfigError(f"{accepted}; got {values!r}")

"""The reality proxy (``--plant proxy``, docs/design.md §7, §9): what the simulator adds to stand in
for the paper's real robot. It is not the real robot, and no result on it is a real result.

Besides the wider parameter ranges of ``pushctl/defaults/randomisation.toml`` (drawn by
:mod:`pushctl.episode.draw`), the proxy has, with :class:`ProxyEffects`' defaults:

- one control step (10 ms) of actuation latency, and Coulomb + viscous joint friction
  (:class:`ProxyActuators`, between the controller and the world's joints);
- contact-force estimates with noise σ = 5 % of the reading + 0.02 N, on what the policy
  observes only (:meth:`ProxyEffects.noisy_forces`; the physics, the reward and the metrics
  keep the true forces);
- object poses read by a 30 Hz camera with noise σ = 1 mm (x, y) and 0.5° (θ), for the
  metrics only (:func:`camera_poses`; the policy's pose error stays exact, as in the paper).

Every random draw comes from :func:`proxy_rng`, seeded from the scenario's seed: one seed
gives identical numbers, and PD-only and RL-assisted runs of one scenario see the same camera.
"""

from __future__ import annotations

import math
import zlib
from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from pushctl.contact.world import World
from pushctl.episode.actuator_kernels import other_impulse, predict_friction, secant_damping
from pushctl.errors import ConfigError
from pushctl.types import StepResult

if TYPE_CHECKING:
    from pushctl.mujoco import MujocoWorld

PROXY_STREAM = 4
"""First spawn-key entry of the proxy's generators: beside the scenario streams 1–3 of
:data:`pushctl.episode.scenario.STREAMS`, so proxy noise never repeats a scenario draw."""

PROXY_PURPOSES = {"camera": 1, "force": 2, "landing": 3}
"""Second spawn-key entry, by purpose: the camera's noise does not depend on how many force
estimates the policy read, so a PD-only run and an RL-assisted run share it (``landing``: the
frames a re-landing reads, :mod:`pushctl.episode.relanding`)."""

LARGE_JOINT_COULOMB, SMALL_JOINT_COULOMB = 1.0, 0.5
"""Assumed Coulomb friction [N·m] of the Kinova Gen2's large (joints 1–4, 40/80 N·m) and
small (joints 5–7, 20 N·m) actuators: 2.5 % of the rated torque, within the 1–5 % usual for
harmonic-drive joints. The Kinova description publishes none (docs/kinova-facts.md §1,
Gazebo uses 0)."""

LARGE_JOINT_VISCOUS, SMALL_JOINT_VISCOUS = 0.5, 0.2
"""Assumed viscous friction [N·m·s/rad] of the same actuators (an assumption too): at the
push's joint speeds (≲ 0.05 rad/s) it adds ≲ 0.025 N·m, the Coulomb part dominates."""


@dataclass(frozen=True)
class ProxyEffects:
    """What the reality proxy adds to the simulator (docs/design.md §9 values as defaults).

    ``latency_steps``: control steps between computing a torque and its reaching the joints.
    ``coulomb_friction`` [N·m] and ``viscous_friction`` [N·m·s/rad]: per joint (one value for
    all, or one per joint of the arm; defaults for the 7-DOF Kinova, see
    :data:`LARGE_JOINT_COULOMB`); ``friction_velocity`` [rad/s]: the Coulomb term is
    F_c·clip(q̇ / v_s, −1, 1), linear below v_s. ``force_noise_relative`` [1] and
    ``force_noise_floor`` [N]: σ of each observed force component = relative·|reading| +
    floor. ``camera_rate`` [Hz], ``camera_sigma_position`` [m] (x and y each) and
    ``camera_sigma_angle`` [rad]: the metrics' camera.
    """

    latency_steps: int = 1
    coulomb_friction: tuple[float, ...] = (LARGE_JOINT_COULOMB,) * 4 + (SMALL_JOINT_COULOMB,) * 3
    viscous_friction: tuple[float, ...] = (LARGE_JOINT_VISCOUS,) * 4 + (SMALL_JOINT_VISCOUS,) * 3
    friction_velocity: float = 1e-3
    force_noise_relative: float = 0.05
    force_noise_floor: float = 0.02
    camera_rate: float = 30.0
    camera_sigma_position: float = 1e-3
    camera_sigma_angle: float = math.radians(0.5)

    def __post_init__(self) -> None:
        latency = self.latency_steps
        if isinstance(latency, bool) or not isinstance(latency, int) or latency < 0:
            raise ConfigError(f"proxy latency_steps must be an integer >= 0, got {latency!r}")
        for name in ("coulomb_friction", "viscous_friction"):
            values = getattr(self, name)
            if not (isinstance(values, tuple) and values and all(_is_ok(v) for v in values)):
                raise ConfigError(f"proxy {name} must be numbers >= 0 per joint, got {values!r}")
        for name in ("force_noise_relative", "force_noise_floor", "camera_sigma_position",
                     "camera_sigma_angle", "friction_velocity", "camera_rate"):  # fmt: skip
            value = getattr(self, name)
            positive = name in ("friction_velocity", "camera_rate")
            if not (_is_ok(value) and (value > 0.0 or not positive)):
                bound = "> 0" if positive else ">= 0"
                raise ConfigError(f"proxy {name} must be a finite number {bound}, got {value!r}")

    def noisy_forces(self, forces: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """``forces`` (…,) [N] as an estimator reads them: each component plus Gaussian noise
        of σ = relative·|reading| + floor (a new array; ``forces`` is not changed)."""
        forces = np.asarray(forces, dtype=float)
        sigma = self.force_noise_relative * np.abs(forces) + self.force_noise_floor
        return forces + sigma * rng.standard_normal(forces.shape)


def effects_for(plant: str | None) -> ProxyEffects | None:
    """The effects of plant ``plant``: the defaults for ``"proxy"``, None for ``"sim"``,
    ``"nominal"`` and None (the simulator as it is); ConfigError for another name."""
    if plant == "proxy":
        return ProxyEffects()
    if plant in (None, "sim", "nominal", "mujoco"):
        return None
    raise ConfigError(f"unknown plant {plant!r}; accepted: sim, proxy, mujoco")


def proxy_rng(seed: int | None, purpose: str, case: str = "") -> np.random.Generator:
    """The proxy's generator for ``purpose`` (a key of :data:`PROXY_PURPOSES`) of scenario
    seed ``seed`` (a scenario given by hand, seed None, uses 0) and ``case`` (the scenario's
    ``object/profile``, through its CRC-32: trial k of the cube and of the wedge, drawn from
    one seed, would otherwise see one camera noise, correlating the tables' cells)."""
    key = (PROXY_STREAM, PROXY_PURPOSES[purpose], zlib.crc32(case.encode()))
    return np.random.default_rng(np.random.SeedSequence(seed or 0, spawn_key=key))


def _is_ok(value: object) -> bool:
    """A finite real number >= 0 (bools refused)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    return math.isfinite(value) and value >= 0.0


# ------------------------------------------------------------------ actuation


class ProxyActuators:
    """Latency and joint friction between a controller and a :class:`World`'s joints.

    Latency. The controller's explicit torque τ (gravity, stiffness and its (K_p h + K_v) q̇_des
    term) computed from the state at t_n is applied over the step starting at t_{n+latency};
    until the first command arrives the joints get ``hold_tau`` (the gravity torque of the
    state at reset: the arm's firmware holding it). The −K_v q̇ part of the PD law stays
    implicit on the *new* velocity, undelayed: it is the actuator's own inner velocity loop,
    which on the real arm runs on the joint boards far faster than the 100 Hz command link,
    so the link's delay hits the reference q̇_des, not the damping. The alternative, the whole
    law delayed and its damping evaluated on the one-step-old velocity, is explicit damping:
    with K_v = 300 N·m·s/rad, h = 0.01 s and a wrist of M ≈ 0.05 kg·m² its gain h K_v / M ≈ 60
    is far above the explicit limit 2, and it diverges in a few steps.

    Friction. τ_f = −F_c clip(q̇ / v_s, −1, 1) − b q̇ per joint, applied as an extra implicit
    joint damping ``b + F_c / max(|q̂|, v_s)`` on the new velocity q̇_{n+1}: the secant of the
    Coulomb law at q̂, a prediction of q̇_{n+1}. Being a damping it only ever opposes the new
    velocity (no energy gain, no sign reversal, unconditionally stable at h = 0.01 s, like the
    PD's implicit damping), and it gives the law's torque exactly where q̇_{n+1} = q̂. The
    secant at q̇_n alone lags: joint 1 coasting from 0.4 rad/s against F_c = 0.5 N·m (stopped
    in 22 steps) decelerated 7.5 % slower than (F_c + b q̇) / M at 0.2 rad/s; with q̂, 1.3 %.
    So q̂ solves the step's joint equation (M + h D) q̂ = M q̇_n +
    h (τ − c − g) + r with that first secant, where r is the joint impulse the contacts (and the
    world's energy correction) added in the previous step: in a steady push the contact load
    persists, and without r the prediction would miss it.
    """

    def __init__(self, effects: ProxyEffects, nv: int, hold_tau: np.ndarray) -> None:
        self.coulomb = _per_joint(effects.coulomb_friction, nv, "coulomb_friction")
        self.viscous = _per_joint(effects.viscous_friction, nv, "viscous_friction")
        self.friction_velocity = effects.friction_velocity
        self._has_friction = bool(np.any(self.coulomb > 0.0) or np.any(self.viscous > 0.0))
        hold = np.array(hold_tau, dtype=float)
        self._pending: deque[np.ndarray] = deque(hold.copy() for _ in range(effects.latency_steps))
        self._other_impulse = np.zeros(nv)  # r of the last step [N·m·s]
        # (gain, the arm's damping, their sum): a scalar gain, usually the same every step
        self._base: tuple[float, np.ndarray, np.ndarray] | None = None

    def friction_damping(self, v: np.ndarray) -> np.ndarray:
        """The friction's damping (nv,) [N·m·s/rad] as a secant at joint velocity ``v``:
        ``−friction_damping(v) · v`` is :meth:`friction_torque` ``(v)``."""
        v = np.ascontiguousarray(v, dtype=float)
        return secant_damping(self.viscous, self.coulomb, v, self.friction_velocity)

    def friction_torque(self, v: np.ndarray) -> np.ndarray:
        """The friction law τ_f(q̇) (nv,) [N·m] at joint velocity ``v`` (nv,) [rad/s]."""
        coulomb = self.coulomb * np.clip(v / self.friction_velocity, -1.0, 1.0)
        return -coulomb - self.viscous * v

    def step(
        self, world: World | MujocoWorld, tau: np.ndarray, implicit_kv: float | np.ndarray
    ) -> tuple[StepResult, np.ndarray]:
        """One world step with the controller's latest command (``tau`` (nv,) [N·m] and its
        implicit gain ``implicit_kv`` [N·m·s/rad]). Returns the step's result and the torque
        the actuators applied over it (nv,) [N·m]: the delayed τ minus K_v q̇_{n+1} (friction
        not included). The prediction q̂ and the impulse r are compiled loops
        (:mod:`pushctl.episode.actuator_kernels`)."""
        applied = tau
        if self._pending:
            self._pending.append(np.array(tau, dtype=float))
            applied = self._pending.popleft()
        if not self._has_friction:
            result = world.step(applied, implicit_kv=implicit_kv)
            return result, applied - implicit_kv * result.arm_v
        terms, h = world.arm_terms, world.config.dt  # the prediction takes one step, unsplit
        assert terms is not None and world.arm is not None  # friction needs an arm
        base = self._base_damping(world.arm.damping, implicit_kv)
        momentum, friction = predict_friction(
            terms.M, world.v, np.asarray(applied, dtype=float), terms.nle, base,
            self.viscous, self.coulomb, self.friction_velocity, h, self._other_impulse,
        )  # fmt: skip
        result = world.step(applied, implicit_kv=implicit_kv + friction)
        self._other_impulse = other_impulse(terms.M, h, base + friction, result.arm_v, momentum)
        return result, applied - implicit_kv * result.arm_v

    def _base_damping(self, damping: np.ndarray, implicit_kv: float | np.ndarray) -> np.ndarray:
        """The world's own implicit damping (nv,) [N·m·s/rad]: the arm's ``damping`` plus the
        controller's gain ``implicit_kv``; their sum is kept while a scalar gain stays the
        same (it does for a whole push)."""
        kept = self._base
        if type(implicit_kv) is not float:
            return damping + implicit_kv
        if kept is None or kept[0] != implicit_kv or kept[1] is not damping:
            kept = self._base = (implicit_kv, damping, damping + implicit_kv)
        return kept[2]


def _per_joint(values: tuple[float, ...], nv: int, name: str) -> np.ndarray:
    """One value per joint (nv,) from one value for all or one per joint; ConfigError else."""
    if len(values) == 1:
        return np.full(nv, float(values[0]))
    if len(values) != nv:
        raise ConfigError(f"proxy {name} has {len(values)} values for an arm of {nv} joints")
    return np.array(values, dtype=float)


# ------------------------------------------------------------------ camera


def camera_frames(duration: float, rate: float) -> int:
    """Frames a camera at ``rate`` [Hz] takes over t = 0 … ``duration`` [s] (both included)."""
    return math.floor(duration * rate + 1e-9) + 1


def draw_camera_noise(effects: ProxyEffects, n_frames: int, rng: np.random.Generator) -> np.ndarray:
    """Noise of ``n_frames`` frames (n_frames, 3) [m, m, rad]: independent Gaussians of σ
    ``camera_sigma_position`` on x and y and ``camera_sigma_angle`` on θ."""
    sigma = np.array([effects.camera_sigma_position] * 2 + [effects.camera_sigma_angle])
    return sigma * rng.standard_normal((n_frames, 3))


def camera_poses(t: np.ndarray, pose: np.ndarray, rate: float, noise: np.ndarray) -> np.ndarray:
    """What a camera at ``rate`` [Hz] reports at the samples ``t`` (N+1,) [s] (t[0] = 0) of the
    true poses ``pose`` (N+1, 3): frame k is taken at k / rate (the true pose linearly
    interpolated between the samples around it, all at or before the next sample that
    shows it), plus ``noise[k]``, and held until frame k + 1. Returns (N+1, 3)."""
    frame = np.floor(np.asarray(t) * rate + 1e-9).astype(int)  # (N+1,) frame shown
    if frame[-1] >= len(noise):
        raise ConfigError(f"camera noise for {len(noise)} frames, the samples need {frame[-1] + 1}")
    taken = np.arange(frame[-1] + 1) / rate  # (F,) [s]
    seen = np.column_stack([np.interp(taken, t, pose[:, i]) for i in range(3)])
    return seen[frame] + noise[frame]

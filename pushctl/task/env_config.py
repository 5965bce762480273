"""The push environment's settings: what an episode draws, the residual's scale and gate
(Algorithm 1), and the weights of the force-level reward (eq. 17)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields
from typing import Any

from pushctl.control.residual import check_residual_path
from pushctl.episode.ranges import PLANTS
from pushctl.episode.scenario import STREAMS
from pushctl.errors import ConfigError
from pushctl.files.toml import check_keys
from pushctl.objects import OBJECT_NAMES
from pushctl.planning import PROFILE_NAMES

BASE_LAWS = ("none", "feedback")
"""What a residual is added to (``EnvConfig.base_law``): PD-only, or PD plus the feedback law."""

RANGES = ("randomisation", "randomisation_known_answer")
"""The shipped ranges files an environment can draw from (``EnvConfig.ranges``; package data,
:mod:`pushctl.defaults`): every randomisation and plant unknown, or the known-answer task's
nominal plant whose only unknown is the pusher's mounting yaw."""

HOLD_FORCE = 0.05
"""The measured normal force [N] below which a prong counts as unloaded for
``EnvConfig.policy_holds_off_contact``: the feedback law's ``contact_force``, above the proxy
force estimate's noise at no load (σ = 20 mN)."""

LANDINGS = ("believed", "measured")
"""Where a closed-loop push's prongs start (``EnvConfig.landing``): where the approach put
them, aimed at the believed pose, or put back on the plan's spot of the object as measured."""


@dataclass(frozen=True)
class EnvConfig:
    """Settings of :class:`pushctl.task.env.PushEnv`.

    Episodes
        ``objects``, ``profiles``: what a reset chooses from (uniformly). ``plant``: the
        randomisation ranges of the world's parameters (``sim`` for training). ``stream``:
        the random stream the scenarios are drawn from (``training``; evaluation draws from
        its own). ``ranges``: the shipped ranges file the draws use (:data:`RANGES`):
        ``randomisation`` (every parameter range and plant unknown) or
        ``randomisation_known_answer`` (the nominal plant, the mounting yaw its only
        unknown). ``duration`` [s] and ``dt`` [s] of the push.
    Residual (Algorithm 1; docs/residual-and-feedback.md)
        ``residual_path``: how the residual twist reaches the PD
        (:mod:`pushctl.control.residual`): ``reference`` integrates it into an offset of
        the pusher reference, which the PD servoes (a bounded twist builds an offset of any
        size); ``velocity`` (the paper's form) adds it to v_e = v_ff + K_x (x_des − x) only,
        whose position term pulls back: a held twist v moves the pusher v / K_x off its
        reference (0.47 mm at 20 mm/s and the tuned K_x of 42.4 /s).
        ``action_scale_linear`` [m/s] and ``action_scale_angular`` [rad/s]: the residual
        twist at an action of ±1 (on the ``reference`` path: the fastest the offset grows).
        ``gate_threshold`` [m]: the residual acts only while the object's pose deviation
        from the plan, √(e_x² + e_y² + (gate_length·e_θ)²), exceeds it; ``gate_length`` [m]
        turns the angle error into a distance. ``observe_camera``: on the ``proxy`` plant the
        observation's pose error and the gate read the 30 Hz camera (docs/design.md §7), as a
        real arm must; False reads the exact pose (how policies were trained before).
        ``observe_offset``: on the ``reference`` path, the observation carries the offset
        built so far (:mod:`pushctl.task.spaces`); the policy's own integrator state, without
        which the pose error alone cannot tell an offset still to build from one built.
        ``action_repeat``: environment steps one action is held for (the policy decides
        every ``action_repeat`` × ``dt``; a step() returns their summed reward). One 10 ms
        step of the reference path moves the offset by at most 0.05 mm, an effect the
        critic cannot tell from its own error; holding an action for 10 steps makes each
        decision's effect ten times larger and its horizon ten times shorter.
        ``offset_limit_linear`` [m] and ``offset_limit_angular`` [rad]: on the ``reference``
        path, the bound of the offset's x and y and of its yaw (anti-windup,
        :class:`~pushctl.control.residual.ReferenceOffset`; ``inf``: unbounded).
        ``base_law``: what the residual is added to. ``none``: PD-only, as in the paper;
        ``feedback``: PD plus the ``feedback`` controller's law
        (``pushctl/defaults/feedback_gains.toml``, read when the environment is made): at every
        step the gate is open the environment adds the law's action (from that step's
        observation) to the policy's held action before the clip, so the policy learns a
        residual on top of the law, and a zero action pushes as the ``feedback`` controller
        does (residual RL on a hand-designed controller, Johannink et al. 2019).
        ``residual_scale`` (0, 1]: the policy's action is multiplied by it before the law's
        is added, so a learned residual reaches at most that share of the action scale.
        ``policy_gated``: the gate switches the policy as well as the law (Algorithm 1, and
        ``Push-v0``); False (``Push-v1``): the gate switches the base law (or, without one,
        nothing), and the policy acts at every step, inside the gate's dead band too, where
        the deviation is an observation rather than a switch. With ``base_law`` and a zero
        action it still pushes as the law does. A base law with its own gate
        (``gate_threshold`` in its file, as the shipped catch-up law has) acts at every
        step, whatever ``gate_threshold``; the environment's gate then switches the policy
        only (with ``policy_gated``).
        ``policy_holds_off_contact``: the policy's action is dropped (and stored as zero)
        on every step where a prong's measured normal force is below
        :data:`HOLD_FORCE`, as the law holds its output then (``hold_off_contact``): with a
        prong off, the object does not move with the plate. On the known-answer task actors
        that acted there turned a wedge that started on one prong away from its plan; actors
        trained with the hold learned less (docs/known-answer.md). Off by default.
        ``observe_context``: the observation also carries the pose error's rate (through a
        0.1 s lag), the plan's speed now (which the law's caps scale with) and the base law's
        output (:mod:`pushctl.task.spaces`), what a residual needs to tell where the law is
        capped and how fast the error closes.
        ``landing``: where the environment's pushes start. ``believed``: where the approach
        landed the prongs, aimed at the object's believed pose (PD-only's start, always);
        ``measured``: the reset then re-lands them on the plan's spot of the object as its
        pose reads (:meth:`~pushctl.episode.runner.Episode.reland`; the ``reference`` path
        only), as a controller that reads the object's pose can. PD-only's comparison push of
        the same reset starts where the approach landed (:meth:`PushEnv.believed_start`).
    Reward (eq. 17)
        ``w_normal`` [1/N], ``w_tangential`` [1/N], ``w_torque`` [1/(N·m)]: per-step reward
        −Σ_i (w1 |ΔF_n,i| + w2 |ΔF_t,i| + w3 |Δτ_z,i|), dimensionless. The default w3 of
        25 /m weighs a torque error like a force error at a 40 mm lever (the prongs sit
        about that far from the centre of mass). ``w_pose`` [1/m]: an optional pose term,
        −w_pose × (the gate's pose deviation), not in eq. 17 (0 leaves the paper's reward):
        a force-level reward cannot see an object that was pushed off its path and is then
        pushed correctly beside it. ``w_metrics`` [1/%]: another optional pose term,
        −w_metrics × (100 ‖e_xy‖ / arc length + 100 |e_θ| / |Δθ|) per step, the exact pose
        error in the units of Table III's two errors, each weighed by its own scale (the
        pose deviation weighs the heading by ``gate_length``).
    """

    objects: tuple[str, ...] = OBJECT_NAMES
    profiles: tuple[str, ...] = PROFILE_NAMES
    plant: str = "sim"
    stream: str = "training"
    ranges: str = "randomisation"
    duration: float = 20.0
    dt: float = 0.01
    residual_path: str = "reference"
    # Sized from the offsets the plant unknowns cause (1-3 mm, up to 1.5 deg) and the rate the
    # tuned feedback law asks for (at most 3.1 mm/s, 0.023 rad/s on the tuning pushes):
    # docs/residual-and-feedback.md, section 2. (The velocity path's old default: 0.02 m/s.)
    action_scale_linear: float = 0.005
    action_scale_angular: float = 0.05
    # Above PD-only's steady tracking error (at most 0.04 mm on sim, tuning stream), below the
    # 1.5-2.7 mm the plant unknowns cause; on the proxy it reads the camera (sigma 1 mm) and is
    # open on nearly every step, which the reference path's integration averages out
    # (docs/residual-and-feedback.md, section 3).
    gate_threshold: float = 1.5e-4
    gate_length: float = 0.05
    observe_camera: bool = True
    observe_offset: bool = True
    action_repeat: int = 1
    # Anti-windup: 1.5x the sim plant's placement error (2 mm) would allow 3 mm; of the bounds
    # tried on the tuning stream with an earlier feedback law (no turn cap, a 0.01 rad/s seek;
    # 3/4/5/8 mm x 1.5/2/2.5/3/5 deg, 180 pushes), 3 mm and 1.5 deg lost the fewest
    # pushes (docs/residual-and-feedback.md, section 4). The yaw bound is 3 deg: the proxy's
    # placement yaw (up to 3 deg) plus its plate yaw can need more than 1.5 deg of contact
    # seek; with the seek and turn cap of today's law 3 deg costs at most 0.02 points of
    # angle error on sim and none on MuJoCo's tuning pushes.
    # Unbounded, a correction that cannot take effect winds up to tens of mm and degrees.
    offset_limit_linear: float = 0.003
    offset_limit_angular: float = math.radians(3.0)
    base_law: str = "none"
    residual_scale: float = 1.0
    policy_gated: bool = True
    policy_holds_off_contact: bool = False
    observe_context: bool = False
    # A placement error lands the prongs 1.2-1.3 mm off the plan's spot on average, and there
    # the plan's force split is wrong and the wedge can turn away (docs/plant-unknowns.md).
    landing: str = "measured"
    w_normal: float = 1.0
    w_tangential: float = 1.0
    w_torque: float = 25.0
    w_pose: float = 0.0
    w_metrics: float = 0.0

    def __post_init__(self) -> None:
        check_residual_path(self.residual_path)
        for name in (
            "observe_camera",
            "observe_offset",
            "policy_gated",
            "policy_holds_off_contact",
            "observe_context",
        ):
            if not isinstance(getattr(self, name), bool):
                raise ConfigError(f"env {name} must be true or false, got {getattr(self, name)!r}")
        if self.base_law not in BASE_LAWS:
            raise ConfigError(
                f"env base_law must be one of {', '.join(BASE_LAWS)}, got {self.base_law!r}"
            )
        if self.ranges not in RANGES:
            raise ConfigError(f"env ranges must be one of {', '.join(RANGES)}, got {self.ranges!r}")
        if self.landing not in LANDINGS:
            raise ConfigError(
                f"env landing must be one of {', '.join(LANDINGS)}, got {self.landing!r}"
            )
        if self.landing == "measured" and self.residual_path != "reference":
            raise ConfigError(
                'env landing = "measured" needs residual_path = "reference" (its offset '
                'holds the plate where it re-landed); use landing = "believed"'
            )
        scale = self.residual_scale
        ok = isinstance(scale, int | float) and not isinstance(scale, bool)
        if not ok or not 0.0 < scale <= 1.0:
            raise ConfigError(f"env residual_scale must be a number in (0, 1], got {scale!r}")
        repeat = self.action_repeat
        if isinstance(repeat, bool) or not isinstance(repeat, int) or not 1 <= repeat <= 100:
            raise ConfigError(f"env action_repeat must be an integer in 1..100, got {repeat!r}")
        _check_choice("objects", self.objects, OBJECT_NAMES)
        _check_choice("profiles", self.profiles, PROFILE_NAMES)
        if self.plant not in PLANTS:
            raise ConfigError(f"env plant must be one of {', '.join(PLANTS)}, got {self.plant!r}")
        if self.plant == "mujoco" and self.stream == "training":
            raise ConfigError(
                "the mujoco plant is for evaluation only: training runs on our engine "
                "(env plant sim or proxy)"
            )
        if self.stream not in STREAMS:
            raise ConfigError(
                f"env stream must be one of {', '.join(STREAMS)}, got {self.stream!r}"
            )
        for name in ("offset_limit_linear", "offset_limit_angular"):
            value = getattr(self, name)
            number = isinstance(value, int | float) and not isinstance(value, bool)
            if not (number and value > 0.0):  # inf allowed: unbounded; NaN fails
                raise ConfigError(
                    f"env {name} must be a number > 0 (inf: unbounded), got {value!r}"
                )
        for name in ("duration", "dt", "action_scale_linear", "action_scale_angular"):
            _check_number(name, getattr(self, name), positive=True)
        for name in (
            "gate_threshold",
            "gate_length",
            "w_normal",
            "w_tangential",
            "w_torque",
            "w_pose",
            "w_metrics",
        ):
            _check_number(name, getattr(self, name), positive=False)

    @classmethod
    def from_mapping(cls, values: Mapping[str, Any]) -> EnvConfig:
        """From a TOML table; ConfigError naming an unknown key and the accepted ones."""
        check_keys(values, [item.name for item in fields(cls)], "[env]", all_required=False)
        converted: dict[str, Any] = {
            key: tuple(value) if isinstance(value, list) else value for key, value in values.items()
        }
        return cls(**converted)

    @classmethod
    def v1(cls, **changes: Any) -> EnvConfig:
        """``Push-v1``'s settings (:data:`PUSH_V1`), with ``changes`` on top."""
        return cls(**{**PUSH_V1, **changes})

    @classmethod
    def from_saved(cls, values: Mapping[str, Any]) -> EnvConfig:
        """From the settings saved with a policy or a checkpoint: a key the file lacks takes
        its value from before that key existed (:data:`LEGACY_VALUES`), not today's default,
        so a policy keeps pushing as it was trained to."""
        return cls.from_mapping({**LEGACY_VALUES, **values})

    def to_dict(self) -> dict[str, Any]:
        return {
            key: list(value) if isinstance(value, tuple) else value
            for key, value in asdict(self).items()
        }

    @property
    def offset_observed(self) -> bool:
        """Whether the observation carries the reference offset (``observe_offset`` on the
        ``reference`` path; the ``velocity`` path builds none)."""
        return self.observe_offset and self.residual_path == "reference"

    @property
    def offset_limit(self) -> tuple[float, float]:
        """(linear [m], angular [rad]): the reference offset's bound."""
        return (float(self.offset_limit_linear), float(self.offset_limit_angular))


LEGACY_VALUES: dict[str, Any] = {
    "residual_path": "velocity",
    "observe_camera": False,
    "observe_offset": False,
    "action_repeat": 1,
    "offset_limit_linear": math.inf,
    "offset_limit_angular": math.inf,
    "base_law": "none",
    "landing": "believed",
    "policy_gated": True,
    "observe_context": False,
}
"""Settings of the keys added after ``Push-v0``'s first policies, as every policy trained
before them used them: the residual added to v_e, the exact object pose in the observation
and the gate, no offset in the observation, a decision every step, an unbounded reference
offset, and the prongs where the approach landed them; and of the keys ``Push-v1`` added:
the gate switching the policy, no context rows."""

PUSH_V1: dict[str, Any] = {
    "base_law": "feedback",
    "residual_scale": 1.0,
    "policy_gated": False,
    "observe_context": True,
    "action_repeat": 10,
    "w_pose": 20.0,
}
"""``pushctl/Push-v1``'s settings over :class:`EnvConfig`'s defaults (``Push-v0``'s): the
residual on the feedback law with the whole envelope (5 mm/s, 0.05 rad/s: at least the 0.15 ×
plan speed and k = 3 /s of the law's catch-up, whose rates reach 3.1 mm/s across and 4.2 mm/s
along on a 21 mm/s plan with 1.4 mm to close), acting inside the gate's dead band, the
context rows observed, a decision every 100 ms and the pose term. ``EnvConfig.v1()``."""


def _check_choice(name: str, chosen: object, accepted: tuple[str, ...]) -> None:
    ok = isinstance(chosen, tuple) and len(chosen) > 0
    if not ok or any(item not in accepted for item in chosen):  # type: ignore[attr-defined]
        raise ConfigError(
            f"env {name} must be a non-empty list of {', '.join(accepted)}, got {chosen!r}"
        )


def _check_number(name: str, value: object, *, positive: bool) -> None:
    ok = isinstance(value, int | float) and not isinstance(value, bool)
    if ok:
        number = float(value)  # type: ignore[arg-type]
        ok = math.isfinite(number) and (number > 0.0 if positive else number >= 0.0)
    if not ok:
        bound = "> 0" if positive else ">= 0"
        raise ConfigError(f"env {name} must be a finite number {bound}, got {value!r}")

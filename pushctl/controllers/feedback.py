"""``feedback``: PD plus the PI law on the object's pose error (docs/design.md §5,
:class:`~pushctl.control.feedback.FeedbackLaw`), sent through the same gate, action scale
and residual path as a policy; its gains: ``pushctl/defaults/feedback_gains.toml``."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING

from pushctl.controllers.base import ControllerRun, PushSetup, Start, register_controller

if TYPE_CHECKING:
    from pushctl.control.feedback_gains import FeedbackGains
    from pushctl.task.env_config import EnvConfig

__all__ = ["FeedbackController", "feedback_config"]


def feedback_config(config: EnvConfig, gains: FeedbackGains | None = None) -> EnvConfig:
    """The environment the ``feedback`` controller pushes in beside a policy trained with
    ``config``: the same push (duration, step, plant, stream) with today's default residual
    settings (path, action scale, gate, contact hold, the camera, the re-landing), whatever the
    policy was trained with. A law of ``gains`` with its own gate (``gains.owns_gate``) gets the
    environment's gate open (threshold 0), so that it sees every step."""
    from pushctl.task.env_config import EnvConfig

    default = EnvConfig()
    gate = 0.0 if gains is not None and gains.owns_gate else default.gate_threshold
    return replace(
        config,
        residual_path=default.residual_path,
        action_scale_linear=default.action_scale_linear,
        action_scale_angular=default.action_scale_angular,
        gate_threshold=gate,
        gate_length=default.gate_length,
        observe_camera=default.observe_camera,
        action_repeat=default.action_repeat,
        offset_limit_linear=default.offset_limit_linear,
        offset_limit_angular=default.offset_limit_angular,
        base_law=default.base_law,  # the law itself is the actor: not added twice
        residual_scale=default.residual_scale,  # and acts with the whole envelope
        policy_holds_off_contact=default.policy_holds_off_contact,  # it has its own hold
        landing=default.landing,
    )


def load_gains() -> FeedbackGains:
    """``pushctl/defaults/feedback_gains.toml``'s law (ConfigError, one line, for a bad file)."""
    from pushctl.control.feedback_gains import load_feedback_gains

    return load_feedback_gains()


def describe_gains(law: FeedbackGains) -> str:
    """The law's gains as the evaluation's provenance line names them."""
    from pushctl.control.feedback_gains import DEFAULT_FEEDBACK_FILE

    guard = (
        f", slide guard {1e3 * law.slide_limit:g} mm over {law.slide_filter:g} s"
        if math.isfinite(law.slide_limit)
        else ""
    )
    return (
        f"feedback k {law.k:g} /s, k_i {law.k_i:g} /s², lateral_ratio "
        f"{law.lateral_ratio:g}, seek {law.seek_rate:g} rad/s over {law.seek_ramp:g} s, "
        f"turn_ratio {law.turn_ratio:g}, smoothing {law.smoothing:g} s{guard} "
        f"({DEFAULT_FEEDBACK_FILE.name})"
    )


@register_controller(
    "feedback",
    label="feedback (PD + PI)",
    colour="#9467bd",
    width=1.8,
    summary="PD + PI on the pose",
    load_gains=load_gains,
    describe_gains=describe_gains,
    paper=True,
)
class FeedbackController:
    """The feedback law in its own environment (:func:`feedback_config`), built once; each
    push takes the start's reset over (:meth:`~pushctl.task.env.PushEnv.reset_from`) where
    that environment builds episodes as the start's does, else resets to the same
    scenario itself (the options fix the draw)."""

    def __init__(self, setup: PushSetup) -> None:
        from pushctl.task.env import PushEnv

        gains = setup.controller_gains.get("feedback")
        self.gains = gains if gains is not None else load_gains()
        self.env = PushEnv(feedback_config(setup.config, self.gains), setup.gains)

    def push(self, start: Start) -> tuple[ControllerRun, ...]:
        from pushctl.controllers.drive import push_with_actor
        from pushctl.task.feedback_actor import FeedbackActor

        env = self.env
        if env.episodes_differ(start.env) is None:
            env.reset_from(start.env, start.redrawn)
        else:
            env.reset(options=start.options)
        return (push_with_actor(env, FeedbackActor(env, self.gains)),)

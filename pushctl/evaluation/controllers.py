"""The three controllers an evaluation compares, as pushes of a reset :class:`PushEnv`.

- ``pd``: PD-only (the paper's π_H), no residual;
- ``feedback``: PD plus the PI law on the object's pose error
  (:class:`~pushctl.control.feedback.FeedbackLaw`), read from the environment's observation;
- ``rl``: PD plus the learned residual policy.

``feedback`` and ``rl`` share one code path: each maps the observation to an action in
[−1, 1]³, and :func:`~pushctl.rl.policy.finish_with_policy` sends it through the
environment's gate, action scale and residual path.
"""

from __future__ import annotations

from dataclasses import replace

from pushctl.control.feedback_gains import FeedbackGains
from pushctl.task.env_config import EnvConfig
from pushctl.task.feedback_actor import FeedbackActor

__all__ = ["CONTROLLERS", "FeedbackActor", "feedback_config"]

CONTROLLERS = ("pd", "feedback", "rl")
"""PD-only, PD + the PI feedback law, PD + the learned residual (the tables' order)."""


def feedback_config(config: EnvConfig, gains: FeedbackGains | None = None) -> EnvConfig:
    """The environment the ``feedback`` controller pushes in beside a policy trained with
    ``config``: the same push (duration, step, plant, stream) with today's default residual
    settings (path, action scale, gate, the camera, the re-landing), whatever the policy was
    trained with. A law of ``gains`` with its own gate (``gains.owns_gate``) gets the
    environment's gate open (threshold 0), so that it sees every step."""
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
        landing=default.landing,
    )

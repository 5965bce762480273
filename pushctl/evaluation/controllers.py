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

import math
from dataclasses import replace

import numpy as np

from pushctl.control.feedback import FeedbackGains, FeedbackLaw
from pushctl.rl.env import PushEnv
from pushctl.rl.env_config import EnvConfig
from pushctl.rl.spaces import index, observation_entries

CONTROLLERS = ("pd", "feedback", "rl")
"""PD-only, PD + the PI feedback law, PD + the learned residual (the tables' order)."""


class FeedbackActor:
    """The feedback law of the push ``env`` was just reset to, as an actor: observation
    (float32, :mod:`pushctl.rl.spaces`) → action (3,) in [−1, 1] (the law's twist over the
    environment's action scale, clipped). Called only while the gate is open, so the
    integral covers the steps the law acted on."""

    def __init__(self, env: PushEnv, gains: FeedbackGains) -> None:
        plan = env.plan
        start = plan.trajectory.pose[0]
        c, s = math.cos(start[2]), math.sin(start[2])
        dx, dy = plan.pusher_positions[0, :2] - start[:2]
        lever = np.array([c * dx + s * dy, -s * dx + c * dy])  # fixed in the object's frame
        self.law = FeedbackLaw(gains, lever, env.config.dt)
        # the observation's layout for this plan's k prongs (the environment's own table
        # is sized for the paper's two; its observation follows the pusher it pushes with)
        where = index(observation_entries(plan.pusher.n_prongs))
        self._error = [where["error_x"], where["error_y"], where["error_theta"]]
        self._normal = [where[f"force_n_{i + 1}"] for i in range(plan.pusher.n_prongs)]
        config = env.config
        self._scale = np.array([config.action_scale_linear] * 2 + [config.action_scale_angular])

    def twist(self, observation: np.ndarray) -> np.ndarray:
        """The law's pusher twist (3,) [m/s, m/s, rad/s], plan frame, before the clip."""
        obs = np.asarray(observation, dtype=float)
        return self.law.twist(obs[self._error], obs[self._normal])

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        return np.clip(self.twist(observation) / self._scale, -1.0, 1.0)


def feedback_config(config: EnvConfig) -> EnvConfig:
    """The environment the ``feedback`` controller pushes in beside a policy trained with
    ``config``: the same push (duration, step, plant, stream) with today's default residual
    settings (path, action scale, gate, the camera), whatever the policy was trained with."""
    default = EnvConfig()
    return replace(
        config,
        residual_path=default.residual_path,
        action_scale_linear=default.action_scale_linear,
        action_scale_angular=default.action_scale_angular,
        gate_threshold=default.gate_threshold,
        gate_length=default.gate_length,
        observe_camera=default.observe_camera,
    )

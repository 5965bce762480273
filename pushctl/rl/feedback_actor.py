"""The ``feedback`` controller's law as an actor of the push environment: observation →
action, like a policy, so the same loops run both (evaluation's ``feedback`` column, and the
demonstrated warm-up of training, :mod:`pushctl.rl.collect`)."""

from __future__ import annotations

import math
from typing import Any, Protocol

import numpy as np

from pushctl.control.feedback import FeedbackGains, FeedbackLaw
from pushctl.rl.spaces import index, observation_entries


class PushSource(Protocol):
    """What the actor reads of a :class:`~pushctl.rl.env.PushEnv` (not imported: the
    environment builds this actor as its ``base_law``): the plan, the settings and the
    episode (its step index)."""

    @property
    def plan(self) -> Any: ...
    @property
    def config(self) -> Any: ...
    @property
    def episode(self) -> Any: ...


class FeedbackActor:
    """The feedback law of the push ``env`` was just reset to, as an actor: observation
    (float32, :mod:`pushctl.rl.spaces`) → action (3,) in [−1, 1] (the law's twist over the
    environment's action scale, clipped). Called only while the gate is open, so the
    integral covers the steps the law acted on."""

    def __init__(
        self, env: PushSource, gains: FeedbackGains, interval: float | None = None
    ) -> None:
        plan = env.plan
        start = plan.trajectory.pose[0]
        c, s = math.cos(start[2]), math.sin(start[2])
        dx, dy = plan.pusher_positions[0, :2] - start[:2]
        lever = np.array([c * dx + s * dy, -s * dx + c * dy])  # fixed in the object's frame
        # one call per decision: every step while the gate is open, or every action_repeat
        # steps; ``interval`` [s] overrides (the base law under a policy runs every step)
        dt = env.config.dt * env.config.action_repeat if interval is None else interval
        self.law = FeedbackLaw(gains, lever, dt, prongs=plan.pusher.prong_offsets())
        # the observation's layout for this plan's k prongs (the environment's own table
        # is sized for the paper's two; its observation follows the pusher it pushes with)
        where = index(
            observation_entries(plan.pusher.n_prongs, reference_offset=env.config.offset_observed)
        )
        self._error = [where["error_x"], where["error_y"], where["error_theta"]]
        self._normal = [where[f"force_n_{i + 1}"] for i in range(plan.pusher.n_prongs)]
        # the reference offset, for the slide guard only (off by default: then the step
        # does not gather it), when the observation has it
        guarded = math.isfinite(gains.slide_limit) and "offset_x" in where
        self._offset = (
            [where["offset_x"], where["offset_y"], where["offset_theta"]] if guarded else None
        )
        config = env.config
        velocity = plan.trajectory.velocity
        self._speed = np.hypot(velocity[:, 0], velocity[:, 1])  # (N + 1,) [m/s]
        self._env = env
        self._scale = np.array([config.action_scale_linear] * 2 + [config.action_scale_angular])

    def twist(self, observation: np.ndarray) -> np.ndarray:
        """The law's pusher twist (3,) [m/s, m/s, rad/s], plan frame, before the clip."""
        obs = np.asarray(observation, dtype=float)
        episode = self._env.episode
        assert episode is not None
        speed = self._speed[min(episode.step_index, self._speed.size - 1)]
        offset = None if self._offset is None else obs[self._offset]
        return self.law.twist(obs[self._error], obs[self._normal], float(speed), offset)

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        return np.clip(self.twist(observation) / self._scale, -1.0, 1.0)

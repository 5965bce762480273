"""The ``feedback`` controller's law as an actor of the push environment: observation →
action, like a policy, so the same loops run both (evaluation's ``feedback`` column, and the
demonstrated warm-up of training, :mod:`pushctl.rl.collect`)."""

from __future__ import annotations

import math
from typing import Any, Protocol

import numpy as np

from pushctl.control.feedback import FeedbackGains, FeedbackLaw
from pushctl.task.spaces import clipped_action, index, observation_entries


class PushSource(Protocol):
    """What the actor reads of a :class:`~pushctl.task.env.PushEnv` (not imported: the
    environment builds this actor as its ``base_law``): the plan, the settings, the
    episode (its step index), and for :meth:`FeedbackActor.act` the observation's pose
    error and force estimate."""

    @property
    def plan(self) -> Any: ...
    @property
    def config(self) -> Any: ...
    @property
    def episode(self) -> Any: ...
    @property
    def pose_error(self) -> np.ndarray: ...
    @property
    def measured_forces(self) -> np.ndarray: ...
    def observation(self) -> np.ndarray: ...


class FeedbackActor:
    """The feedback law of the push ``env`` was just reset to, as an actor: observation
    (float32, :mod:`pushctl.task.spaces`) → action (3,) in [−1, 1] (the law's twist over the
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
        self.law = FeedbackLaw(
            gains, lever, dt, prongs=plan.pusher.prong_offsets(), gate_length=env.config.gate_length
        )
        # the observation's layout for this plan's k prongs (the environment's own table
        # is sized for the paper's two; its observation follows the pusher it pushes with)
        where = index(
            observation_entries(
                plan.pusher.n_prongs,
                reference_offset=env.config.offset_observed,
                context=env.config.observe_context,
            )
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
        self._speed = np.hypot(velocity[:, 0], velocity[:, 1]).tolist()  # (N + 1,) [m/s]
        self._dt = float(config.dt)  # the push step [s]: the catch-up phase's clock
        self.env = env
        linear, angular = config.action_scale_linear, config.action_scale_angular
        self._scales = (float(linear), float(linear), float(angular))  # the action's units

    def twist(self, observation: np.ndarray) -> np.ndarray:
        """The law's pusher twist (3,) [m/s, m/s, rad/s], plan frame, before the clip."""
        return np.array(self._twist(np.asarray(observation, dtype=float)))

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        # through twist(), which a subclass may extend (the residual study records it)
        x, y, w = self.twist(observation).tolist()
        return np.array(self._clipped((x, y, w)))

    def act(self) -> tuple[float, float, float]:
        """``self(observation)`` without the observation: the same floats, read from the
        environment's state (its pose error and force estimate, rounded to float32 as the
        observation rounds them). The base law under a policy runs at every 10 ms step, and
        building the whole observation for five of its entries cost as much as the law.
        The slide guard (which reads the offset rows) takes the observation's path."""
        if self._offset is not None:
            return self._clipped(self._twist(np.asarray(self.env.observation(), dtype=float)))
        env = self.env
        n_prongs = len(self._normal)
        read = np.empty(3 + n_prongs, dtype=np.float32)  # the observation's rounding
        read[:3] = env.pose_error
        read[3:] = env.measured_forces[:, 0]
        values = read.tolist()
        return self._clipped(
            self.law.twist_floats(values[:3], values[3:], self._speed_now(), None, self._time())
        )

    def _twist(self, obs: np.ndarray) -> tuple[float, float, float]:
        offset = None if self._offset is None else obs[self._offset].tolist()
        return self.law.twist_floats(
            obs[self._error].tolist(),
            obs[self._normal].tolist(),
            self._speed_now(),
            offset,
            self._time(),
        )

    def _speed_now(self) -> float:
        """The plan's object speed [m/s] at the episode's step."""
        episode = self.env.episode
        assert episode is not None
        return self._speed[min(episode.step_index, len(self._speed) - 1)]

    def _time(self) -> float:
        """The time since the push began [s] (the catch-up phase's clock)."""
        episode = self.env.episode
        assert episode is not None
        return episode.step_index * self._dt

    def _clipped(self, twist: tuple[float, float, float]) -> tuple[float, float, float]:
        """The twist over the action scale, clipped to [−1, 1] (np.clip's arithmetic)."""
        s_x, s_y, s_w = self._scales
        return clipped_action(twist[0] / s_x, twist[1] / s_y, twist[2] / s_w)

"""What the push environment reads off its episode: the observation, the pose error in the
plan frame and the gate's deviation, eq. 17's reward terms, an action's world twist, and
what a privileged critic may see (the plant unknowns). A mixin of
:class:`~pushctl.task.env.PushEnv`, which owns the episode and its reset; the rows are
:mod:`pushctl.task.spaces`'."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from pushctl.episode.scenario import Scenario
from pushctl.errors import ConfigError
from pushctl.planning import Plan

ERROR_RATE_LAG = 0.1
"""[s] The time constant of the first-order lag the observed pose error's rate goes through
(``EnvConfig.observe_context``): a 10 ms difference of the proxy's 30 Hz camera is mostly
noise."""


_UNKNOWN_KEYS = (
    "placement_along",
    "placement_across",
    "placement_theta",
    "mount_yaw",
    "prong_1_along",
    "prong_1_across",
    "prong_2_along",
    "prong_2_across",
    "pressure_n",
    "pressure_t",
    "ground_variation",
)
PRIVILEGED_SCALES = np.array(
    [1e-3, 1e-3, 1e-2, 1e-2, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 0.1, 0.5, 0.5, 0.5]
    + [1e-4, 1e-4, 2e-3]
)
"""The typical sizes [SI] the critic divides :meth:`EpisodeReadings.privileged_state`'s rows
by: the unknowns of docs/plant-unknowns.md (``placement_*``, ``mount_yaw``, the prongs'
``*_along``/``*_across``, ``pressure_*``, ``ground_variation``), μ_ground, μ_contact, the
object's mass [kg], and the exact pose error (e_x, e_y [m], e_θ [rad])."""


class EpisodeReadings:
    """The readings of :class:`~pushctl.task.env.PushEnv` (see the module docstring). State it
    reads, set by the environment: ``episode``, ``config``, ``_last`` (the last step's
    result), ``_plan_rows``, ``_plan_forces``, ``_true_forces``, ``_true_torques``,
    ``_measured``, ``_exact_pose``, ``_action_scales``, ``_law_owns_gate``; state it
    keeps: ``_error``, ``_error_deviation``, ``_error_rate``, ``_law_action``."""

    episode: Any
    config: Any
    _last: Any
    _plan_rows: list[list[float]]
    _plan_forces: np.ndarray
    _plan_speed: list[float]
    _true_forces: np.ndarray
    _true_torques: np.ndarray
    _measured: np.ndarray
    _exact_pose: bool
    _action_scales: tuple[float, float, float]
    _law_owns_gate: bool
    _law_action: tuple[float, float, float]
    _error: np.ndarray
    _error_deviation: float
    _error_rate: list[float]

    def observation(self) -> np.ndarray:
        """The observation (float32, :mod:`pushctl.task.spaces`) of the current state: what
        reset() or the last step() returned."""
        episode, last = self.episode, self._last
        assert episode is not None
        n, n_steps = episode.step_index, episode.n_steps
        terms = episode.world.arm_terms
        assert terms is not None
        yaw = self._plan_rows[n][2]
        c, s = math.cos(yaw), math.sin(yaw)
        t_x, t_y, _, _, _, t_w = (terms.pusher_jacobian @ last.arm_v).tolist()
        # Python floats into one array: the same float32s as concatenating the parts as
        # arrays, in fewer numpy calls
        planned_n, planned_t = self._plan_forces[min(n + 1, n_steps)].T.tolist()
        # noisy on the proxy: one draw per step, even unobserved
        measured_n, measured_t = self._measured.T.tolist()
        values = planned_n + planned_t + measured_n + measured_t
        values += (c * t_x + s * t_y, -s * t_x + c * t_y, t_w)
        values += self._error.tolist()
        if self.config.offset_observed:
            o_x, o_y, o_w = episode.reference_offset.tolist()  # world x, y, yaw
            values += (c * o_x + s * o_y, -s * o_x + c * o_y, o_w)
        if self.config.observe_context:
            values += self._error_rate
            values.append(self._plan_speed[min(n, n_steps)])
            values += self._law_action
        values.append(n / n_steps)
        return np.array(values, dtype=np.float32)

    # ------------------------------------------------------------------ what it exposes

    @property
    def scenario(self) -> Scenario:
        """The scenario of the current episode."""
        assert self.episode is not None, "reset() first"
        return self.episode.scenario

    @property
    def plan(self) -> Plan:
        assert self.episode is not None, "reset() first"
        return self.episode.plan

    @property
    def pose_error(self) -> np.ndarray:
        """The pose error (3,) [m, m, rad], plan frame, that the observation holds now
        (read by the controller: the camera's on the proxy with ``observe_camera``)."""
        return self._error

    @property
    def measured_forces(self) -> np.ndarray:
        """The prong forces (k, 2) [N] (normal, tangential) the observation holds now (the
        proxy's noisy estimate)."""
        return self._measured

    @property
    def gate_open(self) -> bool:
        """Whether the pose deviation exceeds the gate's threshold: the policy acts then
        (always without ``policy_gated``), and so does a base law that leaves the gate to
        the environment; a law that gates itself acts at every step."""
        return self._error_deviation > self.config.gate_threshold

    def _set_error(self, n: int) -> None:
        """The observation's pose error at step ``n`` (:meth:`_pose_error`) and its gate
        deviation (:meth:`_deviation`'s arithmetic on the same floats), computed once: the
        gate, the reward's pose term and the info all read the deviation. With
        ``observe_context`` also the error's rate through a lag of :data:`ERROR_RATE_LAG`
        (0 at the push's start)."""
        error = self._pose_error(n)
        if self.config.observe_context:
            if n == 0:
                self._error_rate = [0.0, 0.0, 0.0]
            else:
                dt = self.config.dt
                gain = dt / (ERROR_RATE_LAG + dt)
                old = self._error.tolist()
                self._error_rate = [
                    rate + gain * ((new - before) / dt - rate)
                    for rate, new, before in zip(self._error_rate, error, old, strict=True)
                ]
        self._error = np.array(error)
        self._error_deviation = self._deviation(error)

    def privileged_state(self) -> np.ndarray:
        """What an asymmetric critic may see and the actor never does (float32,
        :data:`PRIVILEGED_ENTRIES`' rows): the episode's plant unknowns and true parameters,
        fixed for the push, and the exact pose error now (the observation's reads the camera
        on the proxy)."""
        episode = self.episode
        assert episode is not None
        scenario = episode.scenario
        unknowns = scenario.unknowns.as_dict(episode.plan.pusher.n_prongs)
        plant = scenario.true_parameters
        values = [unknowns.get(name, 0.0) for name in _UNKNOWN_KEYS]
        values += (plant.mu_ground, plant.mu_contact, plant.object_mass)
        values += self._pose_error(episode.step_index, exact=True)
        return np.array(values, dtype=np.float32)

    def _pose_error(self, n: int, exact: bool = False) -> tuple[float, float, float]:
        """Planned minus actual object pose at step ``n``, plan frame (3,) [m, m, rad]; the
        actual pose as the controller reads it (the camera's, on the proxy with
        ``observe_camera``), or the true one if ``exact``: three floats."""
        episode = self.episode
        assert episode is not None
        x, y, yaw = self._plan_rows[n]
        if exact or self._exact_pose:
            actual = self._last.object_pose
        else:
            actual = episode.measured_pose()
        a_x, a_y, a_yaw = actual.tolist()  # floats: numpy's scalar arithmetic, faster
        c, s = math.cos(yaw), math.sin(yaw)
        dx, dy = x - a_x, y - a_y
        angle = math.remainder(yaw - a_yaw, math.tau)
        return (c * dx + s * dy, -s * dx + c * dy, angle)

    def _deviation(self, error: Sequence[float] | None = None) -> float:
        """The gate's pose deviation [m] of ``error`` (3,) (default: the current pose
        error)."""
        if error is None:
            return self._error_deviation
        return math.hypot(error[0], error[1], self.config.gate_length * error[2])

    def _world_twist(self, action: Sequence[float], n: int) -> np.ndarray:
        """The action's three floats in [−1, 1], plan frame, as a world twist [m/s, m/s,
        rad/s]."""
        a_x, a_y, a_w = action
        s_x, s_y, s_w = self._action_scales
        x, y = a_x * s_x, a_y * s_y  # the products of action * scale, component-wise
        yaw = self._plan_rows[n][2]
        c, s = math.cos(yaw), math.sin(yaw)
        return np.array([c * x - s * y, s * x + c * y, a_w * s_w])

    def _reward_terms(self, row: int) -> tuple[float, float, float]:
        """The three weighted terms of eq. 17 for the step that ended at ``row``.

        Plain floats over the k prongs: at k = 2 this is several times faster than numpy on
        (k, 2) arrays, and it runs 2000 times an episode. τ_z,i as in
        :func:`~pushctl.episode.trace.prong_torques`."""
        last, episode = self._last, self.episode
        assert episode is not None
        terms = episode.world.arm_terms
        assert terms is not None
        x, y, theta = last.object_pose.tolist()
        c, s = math.cos(theta), math.sin(theta)
        forces = last.contact_forces.tolist()
        true_forces = self._true_forces[row].tolist()
        true_torques = self._true_torques[row].tolist()
        normal = tangential = torque = 0.0
        for i, (prong_x, prong_y, _) in enumerate(terms.prong_positions.tolist()):
            f_n, f_t = forces[i]
            lever_n = c * (prong_x - x) + s * (prong_y - y)
            lever_t = -s * (prong_x - x) + c * (prong_y - y)
            normal += abs(true_forces[i][0] - f_n)
            tangential += abs(true_forces[i][1] - f_t)
            torque += abs(true_torques[i] - (lever_n * f_t - lever_t * f_n))
        config = self.config
        return (
            -config.w_normal * normal,
            -config.w_tangential * tangential,
            -config.w_torque * torque,
        )


def action_floats(action: Any) -> list[float]:
    """step()'s ``action`` as three Python floats (a float32 entry converted exactly, as
    ``np.asarray(action, dtype=float)`` does); ConfigError unless 3 finite numbers."""
    # The usual float32 or float64 array: its list's sum is finite unless an entry is not
    # (or the sum overflows: the full check then decides), without asarray and
    # isfinite(...).all().
    if type(action) is np.ndarray and action.shape == (3,) and action.dtype.char in "fd":
        values = action.tolist()
        if math.isfinite(sum(values)):
            return values
    array = np.asarray(action, dtype=float)
    if array.shape != (3,) or not np.all(np.isfinite(array)):
        raise ConfigError(f"action must be 3 finite numbers in [-1, 1], got {array!r}")
    return array.tolist()

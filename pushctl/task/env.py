"""``pushctl/Push-v1`` (and ``Push-v0``): one randomised push as a gymnasium environment.

The manual of the environment, in the layout of Gymnasium's own ``pusher_v5.py``. Numbers that
live in code are named, not copied: the observation and action tables are generated from
:mod:`pushctl.task.spaces` (``python -m pushctl.task.spaces`` prints them as Markdown; in Python
``markdown_table(observation_entries(k))`` and ``markdown_table(ACTION_ENTRIES)``), and every
default is a field of :class:`~pushctl.task.env_config.EnvConfig`, whose docstring gives its unit
and its reason. Rules behind it: docs/design.md §5–§7; a narrative with measurements:
docs/learning.md and docs/residual-and-feedback.md.

Description
    A Kinova Gen2 arm with a k-prong pusher (default 2) pushes a cube or a wedge along a
    planned arc (ICR arc, ``constant``/``trapezoid``/``chirp`` profile) under a joint PD
    baseline. The agent is the *residual*: a planar pusher twist added to the baseline through
    the config's ``residual_path`` (``reference``: integrated into an offset of the pusher
    reference, the default; ``velocity``: added to the commanded twist, the paper's
    Algorithm 1), and only while the gate is open. A zero action, or a shut gate, is the PD
    baseline from the push's start to the bit; with ``landing = "believed"`` that is PD-only's
    push (the default ``measured`` starts re-landed, below). The physics is pushctl's contact
    simulator (one box-friction MLCP per step), or MuJoCo on the ``mujoco`` plant kind
    (evaluation only).

Action space
    ``Box(-1, 1, (3,), float32)``: rows :data:`pushctl.task.spaces.ACTION_ENTRIES`
    (``residual_x``, ``residual_y`` in the plan frame, ``residual_wz``), multiplied by
    ``EnvConfig.action_scale_linear`` [m/s] and ``action_scale_angular`` [rad/s], rotated from
    the plan frame (x along the push) to the world. Actions outside [−1, 1] are clipped; a
    non-finite action or a wrong shape raises ``ConfigError``.

Observation space
    ``Box(-inf, inf, (d,), float32)`` with the rows of
    :func:`pushctl.task.spaces.observation_entries` for the pusher's prong count, in that order:
    index, name, meaning, unit and the ``scale`` the learner divides by. In short: the planned
    (nominal) prong forces of the next step, the measured prong forces of the last step, the
    pusher's planar velocity, the object's pose error to the plan (plan frame), with
    ``observe_offset`` on the ``reference`` path the offset built so far, with
    ``observe_context`` the error's rate, the plan's speed and the base law's action, and the
    phase of the push. Everything in it is deployable on a real arm: the planned forces come
    from the nominal plan, never from the plant's parameters. On the ``proxy`` plant kind the
    measured forces are noisy estimates and, with ``observe_camera``, the pose error reads
    the 30 Hz camera.

Rewards
    Per step, the paper's eq. 17 plus an optional pose term, each term ≤ 0 and returned by
    name in ``info``:

    - ``reward_normal`` = −``w_normal`` · Σ_i |F_n,des,i − λ_n,i|
    - ``reward_tangential`` = −``w_tangential`` · Σ_i |F_t,des,i − λ_t,i|
    - ``reward_torque`` = −``w_torque`` · Σ_i |τ_z,des,i − τ_z,i|
    - ``reward_pose`` = −``w_pose`` · (the exact pose deviation the gate measures); 0 at the
      default ``w_pose`` = 0 (the paper's reward); the shipped presets set it.
    - ``reward_metrics`` = −``w_metrics`` · (100 ‖e_xy‖ / arc length + 100 |e_θ| / |Δθ|), the
      exact pose error in the tables' units (the angle part 0 on a push without a turn): a
      push's return is then −N · w_metrics · (translation % + angle %); 0 by default.

    F_des and τ_des are the force plan recomputed with the episode's *true* (plant) parameters
    at the plan's prong offset, which the observation never sees; λ is the simulator's mean
    contact force over the step. The reward stays exact on every plant kind.

Starting state
    ``reset(seed=…)`` seeds ``np_random``, which draws (always these three, so fixing one does
    not shift the others) an object and a profile uniformly from ``EnvConfig.objects`` and
    ``profiles``, and a scenario seed. The scenario (goal, plant parameters, plant unknowns)
    is drawn from ``EnvConfig.stream`` (``training`` by default) with the ranges of
    ``EnvConfig.plant``, redrawn until the planner accepts the goal; it is planned with the
    nominal parameters and the arm runs the approach (a minimum-jerk move onto the pushed
    face, not part of the episode). With ``landing = "measured"`` (the default) the reset then
    re-lands the prongs on the plan's spot of the object as its pose reads
    (:meth:`~pushctl.episode.runner.Episode.reland`), and the push starts from there with the
    move as the reference offset; :attr:`PushEnv.believed_start` is the episode before it,
    PD-only's start. ``options`` (:data:`RESET_OPTIONS`) fixes the object,
    the profile, the scenario seed, or gives a whole ``Scenario``. ``info`` at reset:
    ``scenario``, ``goals_redrawn``, ``unknowns`` (the drawn plant unknowns, for logs only).

Episode end
    ``terminated`` after ``duration`` / ``dt`` push steps (2000 at the defaults; a step() is
    ``action_repeat`` push steps with the action held and their rewards summed, so
    ⌈2000 / action_repeat⌉ calls): the phase is observed, so the end is a true terminal.
    ``truncated`` is always False; a time limit a wrapper adds is the user's. There is no
    early termination: a lost object ends the push with large errors, as a real run would.

Arguments
    ``PushEnv(config=EnvConfig(...), gains=None)`` or ``gymnasium.make("pushctl/Push-v0",
    config=EnvConfig(...))``. ``EnvConfig`` fields: the episode's draws (``objects``,
    ``profiles``, ``plant``, ``stream``, ``duration``, ``dt``), the residual (``residual_path``,
    ``action_scale_linear``, ``action_scale_angular``, ``gate_threshold``, ``gate_length``,
    ``observe_camera``, ``observe_offset``, ``action_repeat``, ``offset_limit_linear``,
    ``offset_limit_angular``, ``base_law``, ``residual_scale``, ``policy_gated``,
    ``policy_holds_off_contact``, ``observe_context``), where the push starts (``landing``)
    and the reward (``w_normal``, ``w_tangential``, ``w_torque``, ``w_pose``, ``w_metrics``);
    ``EnvConfig.from_mapping`` reads a preset's ``[env]`` table. ``gains``: the PD baseline's
    (default ``pushctl/defaults/pd_gains.toml``). Step ``info`` besides the reward terms:
    ``residual_active`` (the gate), ``residual`` (3,) the world-frame twist applied
    [m/s, m/s, rad/s], ``action_applied`` (3,) the policy's action as applied (zeros when the
    gate or the contact hold dropped it), ``pose_deviation`` [m] the gate's deviation.

Version history
    One id, ``Push-v0``, so far; behaviour changes are recorded here and in the saved settings
    of every policy (:data:`~pushctl.task.env_config.LEGACY_VALUES` loads an older policy with
    the settings it was trained with).

    - ``Push-v0``: the environment, eq. 17 with ``w_pose``, the gate, the ``velocity`` path.
    - ``proxy`` plant kind: latency, joint friction, noisy force estimates; ``advance`` for
      loops that only act; the gate threshold sits above the proxy's lag.
    - ``residual_path`` (``reference`` the default) and ``observe_camera``: policies saved
      without them load as ``velocity`` with the exact pose; the plant unknowns are drawn at
      reset and reported in ``info["unknowns"]``; the action scale is sized for the
      reference path.
    - ``mujoco`` plant kind: evaluation only (training on it is refused).
    - ``observe_offset`` (the reference offset's three rows) and ``action_repeat`` (a
      decision interval): policies saved without them load without either.
    - ``offset_limit_linear`` / ``offset_limit_angular`` (the reference offset's anti-windup
      bound): policies saved without them load unbounded. ``base_law`` (``feedback``: the
      residual is added to the feedback law's action): saved policies load with ``none``.
    - ``landing`` (``measured``, the default: the reset re-lands the prongs on the plan's
      spot of the object as measured): saved policies load with ``believed``.
    - ``Push-v1`` (``EnvConfig.v1()``, :data:`~pushctl.task.env_config.PUSH_V1`): the policy
      acts inside the gate's dead band (``policy_gated`` False; the gate switches the law
      only), with the whole envelope on the feedback law, and observes the context rows
      (``observe_context``). ``EnvConfig()``'s defaults stay ``Push-v0``'s, to the bit;
      saved policies load with the gate on the policy and no context rows. A base law that
      gates itself (the catch-up law's ``gate_threshold``) acts at every step, whatever
      the environment's gate, so a zero residual pushes as the ``feedback`` controller.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np

from pushctl.config import PusherConfig
from pushctl.control.feedback import load_feedback_gains
from pushctl.control.gains import PDGains, load_gains
from pushctl.episode.metrics import pose_error_pct
from pushctl.episode.proxy import ProxyEffects, effects_for
from pushctl.episode.ranges import plant_engine
from pushctl.episode.runner import Episode
from pushctl.episode.scenario import Scenario
from pushctl.errors import ConfigError, StateError
from pushctl.planning import Plan
from pushctl.task.env_config import HOLD_FORCE, EnvConfig
from pushctl.task.env_draws import default_draws, draw_reset
from pushctl.task.feedback_actor import FeedbackActor
from pushctl.task.spaces import (
    ACTION_ENTRIES,
    PRIVILEGED_KEYS,
    action_floats,
    clipped_action,
    observation_entries,
)
from pushctl.types import StepResult

_EPISODE_FIELDS = (
    "plant", "stream", "duration", "dt", "residual_path", "offset_limit", "landing"
)  # fmt: skip
"""The configuration an environment's episodes are built from, after the draw
(:meth:`PushEnv.reset_from` hands a reset over only between environments that agree on it)."""

REWARD_TERMS = (
    "reward_normal", "reward_tangential", "reward_torque", "reward_pose", "reward_metrics"
)  # fmt: skip
"""The reward's named terms, in the order they are summed (:meth:`PushEnv._reward`)."""

ERROR_RATE_LAG = 0.1
"""[s] The time constant of the first-order lag the observed pose error's rate goes through
(``EnvConfig.observe_context``): a 10 ms difference of the proxy's 30 Hz camera is mostly
noise."""


class PushEnv(gym.Env[np.ndarray, np.ndarray]):
    """The residual-learning environment. ``config``: :class:`EnvConfig`; ``gains``: the PD
    baseline's (default ``pushctl/defaults/pd_gains.toml``).

    ``info`` of a step: ``reward_normal``, ``reward_tangential``, ``reward_torque`` (the
    three weighted terms of eq. 17), ``reward_pose`` and ``reward_metrics`` (the optional
    pose terms, 0 unless ``w_pose`` or ``w_metrics`` > 0), each ≤ 0, summing to the reward;
    ``residual_active``
    (the gate), ``residual`` (3,) the world-frame twist applied [m/s, m/s, rad/s],
    ``action_applied`` (3,) the policy's action as the decision's first step applied it
    (clipped to [−1, 1]; zeros when the gate dropped it: the action to learn from),
    ``pose_deviation`` [m] that the gate compared with its threshold.
    """

    metadata: dict[str, Any] = {"render_modes": []}

    def __init__(self, config: EnvConfig | None = None, gains: PDGains | None = None) -> None:
        self.config = config or EnvConfig()
        self.gains = gains if gains is not None else load_gains()
        self.observation_entries = observation_entries(
            PusherConfig().n_prongs,
            reference_offset=self.config.offset_observed,
            context=self.config.observe_context,
        )
        self.action_entries = ACTION_ENTRIES
        self.observation_space = gym.spaces.Box(
            -np.inf, np.inf, shape=(len(self.observation_entries),), dtype=np.float32
        )
        self.action_space = gym.spaces.Box(-1.0, 1.0, shape=(3,), dtype=np.float32)
        linear, angular = self.config.action_scale_linear, self.config.action_scale_angular
        self._action_scales = (float(linear), float(linear), float(angular))
        self.effects: ProxyEffects | None = effects_for(self.config.plant)
        """The reality proxy's effects of the episodes (None on the sim plant): a paired
        PD-only run is ``Episode(env.scenario, env.gains, plan=env.plan, effects=env.effects,
        engine=env.engine)``."""
        self.engine = plant_engine(self.config.plant)
        """The episodes' physics engine: ``mujoco`` on the MuJoCo plant, else ``ours``."""
        self.episode: Episode | None = None
        self._believed: Episode | None = None
        self._exact_pose = self.effects is None or not self.config.observe_camera
        self._base_gains = None
        if self.config.base_law == "feedback":
            self._base_gains = load_feedback_gains()
        self._base: FeedbackActor | None = None
        self._law_owns_gate = self._base_gains is not None and self._base_gains.owns_gate
        # the readings of the current step, set by reset() and each push step (_set_error)
        self._error = np.zeros(3)  # the observation's pose error (3,) [m, m, rad], plan frame
        self._error_deviation = 0.0  # its gate deviation [m]
        self._error_rate = [0.0, 0.0, 0.0]  # its rate through the lag [m/s, m/s, rad/s]
        self._law_action = (0.0, 0.0, 0.0)  # the base law's last action, before the policy's

    # ------------------------------------------------------------------ gymnasium API

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        scenario, redrawn, plan = draw_reset(self.config, self.np_random, options or {})
        episode = Episode(
            scenario,
            self.gains,
            plan=plan,
            effects=self.effects,
            residual_path=self.config.residual_path,
            engine=self.engine,
            offset_limit=self.config.offset_limit,
        )
        last = episode.reset()
        believed = None
        if self.config.landing == "measured":
            believed = copy.deepcopy(episode)  # PD-only's start: where the approach landed
            last = episode.reland()
        measured = episode.measured_forces(last.contact_forces)
        return self._start(episode, last, measured, redrawn, believed)

    def reset_from(self, reset: PushEnv, redrawn: int = 0) -> tuple[np.ndarray, dict[str, Any]]:
        """reset() to the episode ``reset`` (another environment) was just reset to, from a
        copy of it: no drawing, planning and approaching again (a reset's 0.15 s). The same
        observation, info and state as ``reset(options=…)`` with the options that gave
        ``reset`` its episode, this environment's generator advanced as that reset would
        (tested to the byte), when both build their episodes alike: the same plant, stream,
        push length, step, PD gains, residual path and offset bound (ConfigError naming the
        first that differs). The ``feedback`` controller's environment in the evaluation
        takes each trial's reset from the policy's. ``redrawn``: the goals ``reset`` redrew
        (its info's ``goals_redrawn``)."""
        episode = reset.episode
        if episode is None or episode.step_index != 0:
            raise StateError("reset_from() takes an environment just reset, before a step")
        differs = self.episodes_differ(reset)
        if differs is not None:
            raise ConfigError(f"reset_from(): the environments differ in {differs}")
        super().reset(seed=None)
        default_draws(self.config, self.np_random)
        copied = copy.deepcopy((episode, reset._last, reset._measured, reset._believed))
        return self._start(*copied[:3], redrawn, copied[3])

    @property
    def believed_start(self) -> Episode:
        """The episode as the reset's approach left it, the prongs where it landed them:
        PD-only's start (:func:`~pushctl.rl.policy.pd_only_episode`). It is :attr:`episode`
        itself unless the reset re-landed the prongs (``landing = "measured"``); do not
        step it."""
        if self.episode is None:
            raise StateError("call reset() first: no episode yet")
        return self.episode if self._believed is None else self._believed

    def episodes_differ(self, other: PushEnv) -> str | None:
        """What makes ``other``'s episodes other than this environment's for the same draw
        (e.g. ``"residual_path ('reference' against 'velocity')"``), or None: then
        :meth:`reset_from` can take ``other``'s resets."""
        for name in _EPISODE_FIELDS:
            mine, theirs = getattr(self.config, name), getattr(other.config, name)
            if mine != theirs:
                return f"{name} ({mine!r} against {theirs!r})"
        if self.gains != other.gains:
            return "the PD gains"
        return None

    def _start(
        self,
        episode: Episode,
        last: StepResult,
        measured: np.ndarray,
        redrawn: int,
        believed: Episode | None = None,
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Take ``episode``, just reset (its approach's last step ``last`` and the force
        estimate ``measured`` of it), as the current one: reset()'s observation and info.
        ``believed``: the same episode as the approach left it, before a re-landing (None:
        not re-landed)."""
        self.episode = episode
        self._believed = believed
        plan = episode.plan
        self._plan_rows = plan.trajectory.pose.tolist()  # (N + 1) × [x, y, yaw], floats
        # the metrics' scales [m], [rad]: 0 leaves that part of ``reward_metrics`` out
        self._metric_scales = (plan.trajectory.arc_length, abs(plan.trajectory.delta_theta))
        self._plan_forces = plan.forces.forces
        self._true_forces = episode.plant_forces.forces
        self._true_torques = episode.plant_forces.torques
        self._last = last
        velocity = plan.trajectory.velocity
        self._plan_speed = np.hypot(velocity[:, 0], velocity[:, 1]).tolist()  # (N + 1,) [m/s]
        self._law_action = (0.0, 0.0, 0.0)
        self._set_error(0)
        self._measured = measured
        self._base = self._base_law()
        # the plant unknowns (docs/design.md §9) drawn for this episode, for logs: never observed
        scenario = episode.scenario
        unknowns = scenario.unknowns.as_dict(plan.pusher.n_prongs)
        info = {"scenario": scenario, "goals_redrawn": redrawn, "unknowns": unknowns}
        return self.observation(), info

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        episode = self.episode
        if episode is None:
            raise StateError("call reset() before step()")
        values = action_floats(action)
        deviation = self._error_deviation
        applied = np.clip(values, -1.0, 1.0) if self.policy_acts else np.zeros(3)
        summed = dict.fromkeys(REWARD_TERMS, 0.0)
        first = None
        for held in range(self.config.action_repeat):
            n = episode.step_index
            residual = self._advance(values)
            if held == 0:
                first = residual
            _, named = self._reward(n + 1)
            for name in REWARD_TERMS:
                summed[name] += named[name]
            if episode.done:
                break
        info = {
            **summed,
            "residual_active": first is not None,
            "residual": np.zeros(3) if first is None else first,
            "action_applied": applied,
            "pose_deviation": deviation,
        }
        reward = float(sum(summed.values()))  # the held steps' terms, summed term by term
        return self.observation(), reward, episode.done, False, info

    # ------------------------------------------------------------------ acting without gym

    def advance(self, action: np.ndarray | None) -> np.ndarray | None:
        """step()'s push step without its observation, reward and info, for loops that only
        act (evaluation and validation: they ask for :meth:`observation` only while
        :attr:`gate_open`, and a policy's forward pass only then). ``action`` (3,) in
        [−1, 1], unchecked, or None, which the open gate takes as zeros. Returns the
        world-frame residual twist applied (3,) [m/s, m/s, rad/s], None while the gate was
        shut. The same steps, and the same draws of the proxy's force noise, as step().
        With a ``base_law`` the law's action, from the observation of this step (the law
        runs at every step, as the ``feedback`` controller does), is added to ``action``
        (None: zeros) before the clip; ``action`` is first multiplied by
        ``residual_scale``."""
        if self.episode is None:
            raise StateError("call reset() before advance()")
        return self._advance(None if action is None else np.asarray(action, np.float64).tolist())

    def _advance(self, action: list[float] | None) -> np.ndarray | None:
        """:meth:`advance` with the action as three Python floats (or None). The clip and
        the scale are numpy's ``np.clip(scale * action, -1, 1)`` arithmetic, component by
        component: the same floats, without the arrays."""
        episode = self.episode
        assert episode is not None
        n = episode.step_index
        residual = None
        gate = self.gate_open
        base = self._base
        policy_acts = self.policy_acts
        pushed = None  # the policy's scaled action, when it acts and has one
        if policy_acts and action is not None:
            scale = self.config.residual_scale
            pushed = action if scale == 1.0 else [scale * a for a in action]
        if base is not None and (gate or self._law_owns_gate):
            law = self._law_action = base.act()  # on the state now; the policy's held action
            if pushed is not None:
                law = clipped_action(law[0] + pushed[0], law[1] + pushed[1], law[2] + pushed[2])
            residual = self._world_twist(law, n)
        elif policy_acts:
            self._law_action = (0.0, 0.0, 0.0)
            if not gate:  # the policy alone, inside the dead band (Push-v1); zero: none
                if pushed is not None and any(pushed):
                    residual = self._world_twist(clipped_action(*pushed), n)
            else:  # no base law: the open gate applies the policy's action (None: zeros)
                clipped = (0.0, 0.0, 0.0) if pushed is None else clipped_action(*pushed)
                residual = self._world_twist(clipped, n)
        elif base is not None:
            self._law_action = (0.0, 0.0, 0.0)
        self._last = episode.step(residual)
        self._set_error(n + 1)  # the observation's, the next gate's
        self._measured = episode.measured_forces(self._last.contact_forces)
        return residual

    # ------------------------------------------------------------------ readings

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
        """What an asymmetric critic may see and the actor never does (float32: the rows
        :data:`~pushctl.task.spaces.PRIVILEGED_KEYS`, then μ_g, μ_c, the object's mass and
        the exact pose error): the episode's plant unknowns and true parameters,
        fixed for the push, and the exact pose error now (the observation's reads the camera
        on the proxy)."""
        episode = self.episode
        assert episode is not None
        scenario = episode.scenario
        unknowns = scenario.unknowns.as_dict(episode.plan.pusher.n_prongs)
        plant = scenario.true_parameters
        values: list[float | None] = [unknowns.get(name, 0.0) for name in PRIVILEGED_KEYS]
        values += (plant.mu_ground, plant.mu_contact, plant.object_mass)  # None: nan
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

    def _reward(self, row: int) -> tuple[float, dict[str, float]]:
        """The reward of the push step that ended at ``row`` and its named terms, each ≤ 0
        (``reward_normal``, ``reward_tangential``, ``reward_torque``: eq. 17's weighted
        terms; ``reward_pose``: −``w_pose`` × the exact pose deviation; ``reward_metrics``:
        −``w_metrics`` × the exact pose error in the tables' % units); the total is their
        sum, in that order.

        Plain floats over the k prongs: at k = 2 this is several times faster than numpy on
        (k, 2) arrays, and it runs 2000 times an episode. τ_z,i as in
        :func:`~pushctl.episode.trace.prong_torques`."""
        last, episode, config = self._last, self.episode, self.config
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
        # with an exact observation, the observation's error is the true one
        error = None if self._exact_pose else self._pose_error(row, exact=True)
        deviation = self._error_deviation if error is None else self._deviation(error)
        metrics = 0.0
        if config.w_metrics:
            exact = self._error.tolist() if error is None else error
            metrics = pose_error_pct(exact, *self._metric_scales)
        named = {
            "reward_normal": -config.w_normal * normal,
            "reward_tangential": -config.w_tangential * tangential,
            "reward_torque": -config.w_torque * torque,
            "reward_pose": -config.w_pose * deviation,
            "reward_metrics": -config.w_metrics * metrics,
        }
        return float(sum(named.values())), named

    # ------------------------------------------------------------------ internals

    @property
    def policy_acts(self) -> bool:
        """Whether the next step applies the policy's action: while the gate is open, or
        always when the gate does not switch the policy (``policy_gated`` False); never while
        a prong's measured normal force is below :data:`~pushctl.task.env_config.HOLD_FORCE`
        with ``policy_holds_off_contact``."""
        held = self.config.policy_holds_off_contact and self._measured[:, 0].min() < HOLD_FORCE
        return (not self.config.policy_gated or self.gate_open) and not held

    def _base_law(self) -> FeedbackActor | None:
        """The law under the residual for the episode just reset (None: PD-only)."""
        if self._base_gains is None:
            return None
        return FeedbackActor(self, self._base_gains, interval=self.config.dt)

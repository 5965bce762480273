"""The episode runner: scenario → plan → approach → push → trace.

:class:`Episode` runs step by step (a learner drives :meth:`Episode.step` with its residual)
or all at once (:meth:`Episode.run`). The planner and the controller use the scenario's
*nominal* parameters, the world its *plant* parameters; the desired prong forces in the
trace (and any reward) are the force distribution recomputed with the plant's parameters at
the plan's prong offset: what the pushed object really needed where the prongs really were.

Plant unknowns (``Scenario.unknowns``, docs/design.md §9) live in the world only: the object
starts at its true pose (the believed start ⊕ the placement error) while the plan and the
approach aim at the believed one, and the world's pusher has the mounting error while the
controller's arm model (:meth:`Episode.controller_terms`) keeps the nominal pusher; the
world's object carries the shifted support loads and its table the friction field, and the
plant forces (:attr:`Episode.plant_forces`) are computed with both. The trace also keeps the
nominal plan's forces (``plan_forces``), the reference of ``force_error_plan``.

With :class:`~pushctl.episode.proxy.ProxyEffects` the episode runs on the reality proxy: its
actuators delay the controller's torque and add joint friction (approach and push alike),
:meth:`Episode.measured_forces` is the noisy force estimate a policy observes, and the trace
gains the camera's object poses, which the metrics then use.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from pushctl.arm import ArmModel, ArmTerms, BelievedTerms
from pushctl.checks import finite_vector
from pushctl.contact.ground_field import FrictionField
from pushctl.contact.world import World
from pushctl.control.gains import PDGains, load_gains
from pushctl.control.pd import PDCommand, PDController
from pushctl.control.reference import PusherReference, concatenate, minimum_jerk, push_reference
from pushctl.control.residual import ReferenceOffset, check_residual_path
from pushctl.engines import make_world
from pushctl.episode import plant as plant_setup
from pushctl.episode.approach import ApproachSettings, approach_path, onto_face, standoff_point
from pushctl.episode.proxy import ProxyActuators, ProxyEffects
from pushctl.episode.proxy_run import ProxyRun
from pushctl.episode.recording import Recording
from pushctl.episode.relanding import camera_noise_at_rest, landing_shift
from pushctl.episode.scenario import Scenario
from pushctl.episode.trace import Trace
from pushctl.episode.unknowns import friction_field
from pushctl.errors import ConfigError, StateError
from pushctl.objects import ObjectSpec
from pushctl.planning import ForcePlan, Plan
from pushctl.types import StepResult

if TYPE_CHECKING:
    from pushctl.mujoco import MujocoWorld

__all__ = ["ApproachSettings", "Episode"]


class Episode:
    """One scenario on a fresh world with the PD baseline.

    Construction plans (raising PlanError if the plan cannot be executed) and builds the
    world (``plan``: one already made for this scenario with its nominal parameters, e.g. by
    :func:`~pushctl.episode.draw.draw_planned_scenario`, to save planning it twice);
    :meth:`reset` runs the approach; :meth:`step` advances one push step with an
    optional residual planar twist (3,) (vx [m/s], vy [m/s], ω_z [rad/s]); :meth:`trace`
    returns what has been recorded. ``effects``: the reality proxy's (None: the simulator as
    it is); its random draws restart from the scenario's seed at every :meth:`reset`.
    ``residual_path``: how the residual reaches the PD (:mod:`pushctl.control.residual`):
    ``reference`` (integrated into an offset of the pusher reference) or ``velocity`` (the
    paper's form, added to v_e only). ``offset_limit`` (linear [m], angular [rad]): the
    ``reference`` path's offset bound (None: unbounded; :class:`ReferenceOffset`).
    ``engine``: the world's physics, ``ours`` or ``mujoco`` (:func:`make_world`); the
    controller is the same on either.
    """

    def __init__(
        self,
        scenario: Scenario,
        gains: PDGains | None = None,
        approach: ApproachSettings | None = None,
        plan: Plan | None = None,
        effects: ProxyEffects | None = None,
        residual_path: str = "reference",
        engine: str = "ours",
        offset_limit: tuple[float, float] | None = None,
    ) -> None:
        self.scenario = scenario
        self.residual_path = check_residual_path(residual_path)
        self.effects = effects
        self.gains = gains if gains is not None else load_gains()
        self.approach = approach or ApproachSettings()
        plant = scenario.true_parameters
        # The plant's needs (plant_forces) are those of the world that runs: MuJoCo's carries
        # neither the centre-of-pressure offset nor the friction field.
        unknowns = scenario.unknowns.acting_in(engine)
        self.object: ObjectSpec = plant_setup.plant_object(scenario, unknowns)
        self.friction_field: FrictionField | None = friction_field(unknowns)
        self.plan: Plan = plan if plan is not None else plant_setup.nominal_plan(scenario)
        self.plan.raise_if_infeasible()
        pusher = plant_setup.true_pusher(scenario, self.object.pusher_mass, unknowns)
        self._friction_limits = plant_setup.plant_friction_limits(
            self.object, scenario, self.friction_field, self.plan
        )
        self._true_pusher = pusher
        self.plant_forces: ForcePlan = self.plant_forces_at(0.0)
        self.world: World | MujocoWorld = make_world(
            self.object,
            arm=scenario.arm,
            mu_ground=plant.mu_ground,
            mu_contact=plant.mu_contact,
            dt=scenario.dt,
            pusher=pusher,
            gravity=scenario.gravity,
            friction_field=self.friction_field,  # None on MuJoCo (acting_in above)
            engine=engine,  # "mujoco": the same scene on MuJoCo (an independent plant)
        )
        world_arm = self.world.arm
        assert world_arm is not None
        self.controller_arm: ArmModel = plant_setup.believed_arm(world_arm, self.scenario, pusher)
        self._believed = (
            None
            if self.controller_arm is world_arm
            else BelievedTerms(world_arm, self.controller_arm)
        )
        self.true_start: np.ndarray = unknowns.true_start(self.plan.trajectory.pose[0])
        self.controller = self._controller(self.gains)
        self.reference: PusherReference = push_reference(self.plan)
        self._offset = ReferenceOffset(scenario.dt, offset_limit)
        self._allocate()
        self._proxy: ProxyRun | None = None  # the proxy's state, fresh at every reset()
        if effects is not None:  # check its per-joint friction against this arm now
            ProxyActuators(effects, self.world.v.size, np.zeros(self.world.v.size))

    def set_gains(self, gains: PDGains) -> None:
        """Use other PD gains from the next :meth:`reset` on (the plan and world are kept:
        a gain search reruns one episode many times)."""
        self.gains = gains
        self.controller = self._controller(gains)

    def plant_forces_at(self, shift: float) -> ForcePlan:
        """The prong forces the plant needs to follow the plan (docs/design.md §7's F_des): its
        true parameters, support loads and friction field, with the plate ``shift`` [m]
        across the face from the plan's plate offset and the prongs where they really are on
        the plate (along the face). ``shift`` = 0 gives :attr:`plant_forces`; the spot where
        the prongs really landed gives the reference of ``force_error_landed``
        (:mod:`pushctl.episode.landed`)."""
        limits = self._friction_limits
        return plant_setup.needed_forces(
            self.scenario, self.plan, self.object, self._true_pusher, limits, shift
        )

    def _controller(self, gains: PDGains) -> PDController:
        return PDController(self.controller_arm, gains, self.scenario.dt)

    def controller_terms(self) -> ArmTerms:
        """The arm's terms at the world's current state as the controller's model computes
        them: the world's own (:attr:`World.arm_terms`) unless the pusher has a mounting
        error, then the nominal pusher's frame, Jacobian and g(q), bit for bit what
        :attr:`controller_arm` computes, taken from the world's pass
        (:class:`~pushctl.arm.believed.BelievedTerms`; M, nle and the prongs' true
        positions are the world's)."""
        world = self.world
        terms = world.arm_terms
        assert terms is not None
        if self._believed is None:
            return terms
        return self._believed(terms, world.q, world.v)

    @property
    def n_steps(self) -> int:
        return self.plan.trajectory.n_steps

    @property
    def step_index(self) -> int:
        """Push steps taken since :meth:`reset` (0 … n_steps)."""
        return self._n

    @property
    def done(self) -> bool:
        return self._n >= self.n_steps

    def reset(self) -> StepResult:
        """Put the arm at its ready configuration (the controller's) and the object at its
        true start (the plan's, unless placed with an error), run the approach, and return
        the state at the start of the push (t = 0)."""
        world = self.world
        world.reset(object_pose=self.true_start, arm_q=self.controller_arm.q_ready)
        self._start_proxy()
        self._offset.reset()
        result = self._approach()
        self._n = 0
        self._started = True
        self._record(0, result, self._rows.tau[0])
        return result

    def step(self, residual: np.ndarray | None = None) -> StepResult:
        """One push step from t_n to t_{n+1}; ``residual`` (3,) a planar pusher twist (vx
        [m/s], vy [m/s], ω_z [rad/s], world axes) taken by the episode's residual path
        (Algorithm 1). StateError after the last step."""
        if not self._started:
            raise StateError("call reset() before step(): the approach has not run")
        if self._n >= self.n_steps:
            raise StateError(f"the push is over: all {self.n_steps} steps have been taken")
        n, world, ref = self._n, self.world, self.reference
        terms = self.controller_terms()
        position, yaw, twist = ref.position[n], ref.yaw[n], self._twists[n]
        if self.residual_path == "reference":
            checked = None if residual is None else finite_vector("residual", residual, 3)
            position, yaw, twist = self._offset.shifted(position, yaw, twist, checked)
            residual = None
        command = self.controller.command(terms, world.q, position, yaw, twist, residual)
        result, tau, kv = self._actuate(command)
        self._n = n + 1
        self._record(self._n, result, tau, kv)
        return result

    def set_offset_limit(self, limit: tuple[float, float] | None) -> None:
        """Bound the ``reference`` path's offset from now on by ``limit`` (linear [m],
        angular [rad]; None: unbounded), keeping the offset built so far."""
        built = self._offset.offset
        self._offset = ReferenceOffset(self.scenario.dt, limit)
        self._offset.offset = built.copy()

    @property
    def reference_offset(self) -> np.ndarray:
        """The ``reference`` path's offset of the pusher reference from the plan so far (3,)
        [m, m, rad], world x, y and yaw (zeros on the ``velocity`` path)."""
        return self._offset.offset.copy()

    def measured_pose(self) -> np.ndarray:
        """The object pose (3,) [m, m, rad] at the current step as a controller can know it:
        exact on the simulator; on the proxy the camera's latest frame (the pose at the
        frame's time plus its noise, as :func:`~pushctl.episode.proxy.camera_poses` gives
        the trace's ``measured_pose``)."""
        if self.effects is None:
            return self._rows.pose[self._n].copy()
        return self._started_proxy().measured_pose(self._rows.pose, self.plan.trajectory.t, self._n)

    def measured_forces(self, forces: np.ndarray) -> np.ndarray:
        """Contact forces ``forces`` [N] as the force estimate reads them: on the proxy with
        its noise (a draw from the episode's force generator), otherwise as they are."""
        if self.effects is None:
            return forces
        return self._started_proxy().measured_forces(forces)

    def _started_proxy(self) -> ProxyRun:
        if self._proxy is None:
            raise StateError("call reset() before reading the proxy's measurements")
        return self._proxy

    def run(self) -> Trace:
        """reset(), every push step without a residual, and the trace."""
        self.reset()
        return self.finish()

    def finish(self) -> Trace:
        """Every remaining push step without a residual, and the trace. After reset() it is
        run()'s push; on a ``copy.deepcopy`` of an episode just reset, it is that push without
        running the approach again (how the evaluation pairs PD-only with RL-assisted)."""
        if not self._started:
            raise StateError("call reset() before finish(): the approach has not run")
        while self._n < self.n_steps:
            self.step()
        return self.trace()

    def trace(self) -> Trace:
        """The rows recorded so far (t = 0 … t_n)."""
        rows = slice(0, self._n + 1)
        measured = None
        if self._proxy is not None:
            measured = self._proxy.camera_poses(self.plan.trajectory.t[rows], self._rows.pose[rows])
        mu_contact = self.scenario.true_parameters.mu_contact
        return self._rows.trace(rows, self.plan, self.plant_forces, mu_contact, measured)

    # ---------------------------------------------------------------- internals

    def _approach(self) -> StepResult:
        """Ready pose → standoff → touching at the plan's offset → settle."""
        terms = self.controller_terms()
        path = approach_path(
            self.approach,
            self.scenario.dt,
            terms.pusher_position,
            terms.pusher_rotation,
            self.reference.position[0],
            float(self.reference.yaw[0]),
        )
        return self._follow(path)

    def _follow(self, reference: PusherReference) -> StepResult:
        """Servo the PD along ``reference`` (an approach's path), one world step per sample
        after its first; the last step's result."""
        world = self.world
        twists = reference.twist
        result = None
        for n in range(len(reference) - 1):
            terms = self.controller_terms()
            command = self.controller.command(
                terms, world.q, reference.position[n], reference.yaw[n], twists[n]
            )
            result, _, _ = self._actuate(command)
        assert result is not None
        return result

    def reland(self) -> StepResult:
        """Put the prongs back on the plan's spot of the face, as a controller that reads the
        object's pose does before its push (:mod:`pushctl.episode.relanding`): back the
        plate off to the approach's standoff (``creep_time``), read the object's pose (exact
        on the simulator; on the proxy the mean of the camera's frames over the back-off),
        move the plate across its face by :func:`~pushctl.episode.relanding.landing_shift`
        (``creep_time``), creep back onto the face (``creep_time``) and settle. The move is
        kept as the reference path's offset, so the push holds it; the state at t = 0 is
        the new one. Only on an episode just reset, on the ``reference`` path (StateError,
        ConfigError); about 3.2 s of world steps."""
        if not self._started or self._n != 0:
            raise StateError("reland() takes an episode just reset, before a push step")
        if self.residual_path != "reference":
            raise ConfigError(
                "re-landing needs the reference residual path: its offset holds the plate "
                f"where it landed (got {self.residual_path!r})"
            )
        creep, dt = self.approach.creep_time, self.scenario.dt
        contact = self.reference.position[0]
        yaw = float(self.reference.yaw[0])
        standoff = standoff_point(self.approach, contact, yaw)
        self._follow(minimum_jerk(contact, yaw, standoff, yaw, creep, dt))
        bound = math.inf if self._offset.limit is None else self._offset.limit[0]
        shift = landing_shift(
            self.plan.trajectory.pose[0], self._landing_pose(), contact, yaw, bound
        )
        parts = [
            minimum_jerk(standoff, yaw, standoff + shift, yaw, creep, dt),
            *onto_face(self.approach, dt, standoff + shift, contact + shift, yaw),
        ]
        result = self._follow(concatenate(*parts))
        self._offset.offset = shift
        self._record(0, result, self._rows.tau[0])
        return result

    def _landing_pose(self) -> np.ndarray:
        """The object's pose (3,) [m, m, rad] as :meth:`reland` reads it, the plate backed
        off: exact on the simulator and MuJoCo; on the proxy plus the mean noise of the
        camera's frames over the back-off (the object at rest), from their own generator."""
        pose = np.asarray(self.world.object_pose, dtype=float).copy()
        if self.effects is None:
            return pose
        case = f"{self.scenario.object}/{self.scenario.profile}"
        noise = camera_noise_at_rest(
            self.effects, self.approach.creep_time, self.scenario.seed, case
        )
        return pose + noise

    def _actuate(self, command: PDCommand) -> tuple[StepResult, np.ndarray, float]:
        """One world step with ``command``: (the result, τ (nv,) [N·m], K_v [N·m·s/rad]).
        The joint torque applied over the step is τ − K_v q̇ of the new velocity, the
        explicit torque minus the implicit damping. On the proxy's actuators τ is that
        torque and K_v is 0. Otherwise τ and K_v are the command's, and the subtraction waits
        for :meth:`trace` (:meth:`_applied_torques`): most steps' torques are never read,
        and the two numpy operations would run every step
        (:meth:`Recording.applied_torques`)."""
        if self._proxy is not None:
            result, applied = self._proxy.actuators.step(
                self.world, command.tau, command.implicit_kv
            )
            return result, applied, 0.0
        result = self.world.step(command.tau, implicit_kv=command.implicit_kv)
        return result, command.tau, command.implicit_kv

    def _start_proxy(self) -> None:
        """Fresh proxy state for a run from the world's reset state (nothing without effects):
        the actuators (holding the arm until the first command arrives), the camera's noise
        for every frame of the push, and the force estimate's generator."""
        if self.effects is None:
            return
        case = f"{self.scenario.object}/{self.scenario.profile}"
        t = self.plan.trajectory.t
        self._proxy = ProxyRun(self.effects, self.world, t, self.scenario.seed, case)

    def _allocate(self) -> None:
        arm = self.world.arm
        assert arm is not None
        self._twists = self.reference.twist
        self._rows = Recording(self.n_steps + 1, self.plan.pusher.n_prongs, arm.nq, arm.nv)
        self._n = 0
        self._started = False

    def _record(self, row: int, result: StepResult, tau: np.ndarray, kv: float = 0.0) -> None:
        terms = self.world.arm_terms
        assert terms is not None
        self._rows.record(row, result, terms, tau, kv)

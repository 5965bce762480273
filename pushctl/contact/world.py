"""The world step: arm + pusher + planar object + table, one box-friction MLCP per step.

Generalised velocity ``v = [q̇_arm (nv); v_obj (3)]``, ``v_obj = (vx, vy, ω)`` in the world
frame. Per step of length h (docs/design.md §3, the paper's eq. 6–8):

1. arm terms at (q, q̇): M (with armature), c + g, prong positions and Jacobians;
2. free velocity with implicit joint damping: ``(M + h K_d) q̇_free = M q̇ + h (τ − c − g)``,
   K_d the physical damping plus any ``implicit_kv`` the controller hands over (its K_v);
   the object has no applied force besides contact and friction: ``v_obj,free = v_obj``;
3. contact rows A (m, nv + 3) from :mod:`pushctl.contact.rows`: a normal row (unilateral,
   position-stabilised) and a tangential row (|p_t| ≤ μ_c p_n) per prong within
   ``contact_margin`` of the footprint, then the ground friction rows of each support point
   (``WorldConfig.friction_model``);
4. ``D = A M̃⁻¹ Aᵀ``, ``b = A v_free + stabilisation``; :func:`solve_box_mlcp` for the
   impulses p = h λ; ``v⁺ = v_free + M̃⁻¹ Aᵀ p``; positions integrated with v⁺.

Without an arm, prongs on a prescribed path take its place (:meth:`World.push`). Contact is
planar (prong heights are the controller's job, and so are joint limits).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from pushctl.arm import ArmModel, ArmTerms
from pushctl.checks import finite_vector
from pushctl.config import GRAVITY
from pushctl.contact.compiled.step_end import arm_moved, native_arm_moved, native_arm_moved_nominal
from pushctl.contact.ground_field import FrictionField
from pushctl.contact.prescribed import push_substeps
from pushctl.contact.recycle import ArrayRecycler
from pushctl.contact.rows import PRONG_ROWS, edge_array, mask_indices, prong_contacts
from pushctl.contact.step_solver import SLIP_COS_TOLERANCE, StepSolver, StepState
from pushctl.contact.world_config import (
    DEFAULT_OBJECT_POSE,
    MAX_SLIP_ITERATIONS,
    STICK_FRACTION,
    WorldConfig,
)
from pushctl.errors import StateError
from pushctl.objects import ObjectSpec
from pushctl.types import ContactProblem, StepResult, WorldStats

__all__ = [
    "DEFAULT_OBJECT_POSE",
    "MAX_SLIP_ITERATIONS",
    "SLIP_COS_TOLERANCE",
    "STICK_FRACTION",
    "World",
    "WorldConfig",
]

_FLOAT64 = np.dtype(np.float64)
_TERMS = slice(3, 3 + len(ArmTerms._fields))
"""Where an :class:`ArmTerms`' arrays sit in a set of the step end's arrays (after q, the
contact geometry and the gaps; the nominal frame's three follow)."""
_NO_CONTACTS = np.zeros((0, 5))
_NO_JACOBIANS = np.zeros((0, 3, 0))
_NO_ARM_MATRIX = np.zeros((0, 0))


class World:
    """Arm (optional) + pusher + one object on the table (:func:`pushctl.engines.make_world`).

    The state, the step's integration and the contact geometry live here; each (sub)step's
    contact solve in :attr:`solver` (a :class:`~pushctl.contact.step_solver.StepSolver`).
    The pusher is an arm driven by joint torques (:meth:`step`) or prongs on a prescribed
    path (:meth:`push`, no arm): the same rows and ground friction. ``obj``: an ObjectSpec
    or a body with the same mass properties (a kinematic ``Slider``)."""

    def __init__(
        self,
        obj: ObjectSpec,
        arm: ArmModel | None,
        config: WorldConfig,
        friction_field: FrictionField | None = None,
    ) -> None:
        """``friction_field``: μ(p)/μ_g over the table
        (:class:`~pushctl.contact.ground_field.FrictionField`); None: μ_g everywhere."""
        self.object = obj
        self.friction_field = friction_field
        self.arm = arm
        self._config = config
        self.stats = WorldStats()
        self._edges = edge_array(obj.polygon)
        # Support loads are computed at GRAVITY; the friction bounds follow the world's.
        uniform_limits = config.mu_ground * obj.support_loads * (config.gravity / GRAVITY)
        self.solver = StepSolver(obj, config, friction_field, self.stats, uniform_limits)
        self._n_prongs = 0 if arm is None else arm.pusher.n_prongs
        if arm is not None:  # the step end's arrays: q, the contact geometry, the arm terms
            shapes: tuple[tuple[int, ...], ...] = (
                (arm.nq,), (self._n_prongs, 5), (self._n_prongs,), *arm.term_shapes
            )  # fmt: skip
            if arm.nominal_frame >= 0:
                shapes += arm.nominal_shapes
            self._end_arrays = ArrayRecycler(shapes)
        self._nv = 0 if arm is None else arm.nv
        self._damping = np.zeros(self._nv) if arm is None else np.asarray(arm.damping, float)
        self._terms: ArmTerms | None = None
        self._prongs: tuple[int, ...] = ()
        self._contacts, self._gaps = _NO_CONTACTS, np.zeros(0)
        self._kv_zero = np.zeros(self._nv)
        # (gain, its (nv,) array, physical damping + gain): a scalar gain, usually the same
        # every step, keeps its arrays.
        self._kv_scalar: tuple[float, np.ndarray, np.ndarray] = (
            0.0,
            self._kv_zero,
            self._damping + self._kv_zero,
        )
        self.reset()

    @property
    def config(self) -> WorldConfig:
        """The world's settings (its solver's too)."""
        return self._config

    @config.setter
    def config(self, config: WorldConfig) -> None:
        """Replace the settings of the steps to come; ``dt`` and ``substeps`` must stay."""
        self._config = self.solver.config = config

    # ------------------------------------------------------------------ state

    def reset(
        self,
        object_pose=DEFAULT_OBJECT_POSE,
        object_velocity=(0.0, 0.0, 0.0),
        arm_q=None,
        arm_v=None,
    ) -> StepResult:
        """Set the state. ``object_pose`` (x [m], y [m], θ [rad]); ``object_velocity``
        (vx, vy, ω); ``arm_q=None`` is the ready configuration, ``arm_v=None`` rest.
        Returns the state as a zero-force StepResult."""
        self.object_pose = finite_vector("object_pose", object_pose, 3).copy()
        self.object_velocity = finite_vector("object_velocity", object_velocity, 3).copy()
        if self.arm is None:
            self.q, self.v = np.zeros(0), np.zeros(0)
        else:
            q = self.arm.q_ready if arm_q is None else arm_q
            self.q = finite_vector("arm_q", q, self.arm.nq).copy()
            v = np.zeros(self._nv) if arm_v is None else arm_v
            self.v = finite_vector("arm_v", v, self._nv).copy()
        self.solver.reset(self.object_pose[2])  # at rest the boxes align with e_n
        self._energy_ledger = 0.0  # spurious arm kinetic energy not yet removed [J]
        self._refresh_arm_terms()
        self._find_contacts()
        return self._result(np.zeros((self._n_prongs, 2)), 0.0, True, 0)

    def prong_positions(self) -> np.ndarray:
        """World positions [m] of the prongs at the current arm state, (k, 3)."""
        if self._terms is None:
            return np.zeros((0, 3))
        return self._terms.prong_positions.copy()

    @property
    def arm_terms(self) -> ArmTerms | None:
        """The arm's dynamics and kinematics at the current state (None without an arm):
        computed once per step for the world's own use, shared read-only with controllers."""
        return self._terms

    def gravity_torque(self) -> np.ndarray:
        """g(q) [N·m] at the current arm state, (nv,); empty for an object-only world."""
        if self._terms is None:
            return np.zeros(0)
        return self._terms.g.copy()

    # ------------------------------------------------------------------- step

    def step(self, tau=None, implicit_kv=None) -> StepResult:
        """Advance one control step ``dt`` with joint torques ``tau`` (nv,) [N·m].

        ``implicit_kv`` (nv,) or scalar [N·m·s/rad], optional: a joint damping gain applied to
        the *new* joint velocity, i.e. the −K_v q̇ term of a PD law evaluated implicitly (the
        caller then passes τ without it). Explicit damping of a light wrist diverges at
        h = 0.01 s; the implicit form is unconditionally stable. Both are ignored when the
        world has no arm.
        """
        tau_arm, kv = self._check_command(tau, implicit_kv)
        scalar = self._kv_scalar
        damping = scalar[2] if kv is scalar[1] else self._damping + kv
        n_sub = self.config.substeps
        forces, residual, converged, iterations = self._substep(tau_arm, damping)
        for _ in range(n_sub - 1):
            more_forces, more_residual, more_converged, more = self._substep(tau_arm, damping)
            forces = forces + more_forces
            iterations += more
            if more_residual > residual:  # the worst substep's solve is reported
                residual, converged = more_residual, more_converged
        self.stats.steps += 1
        forces = forces / n_sub if n_sub > 1 else forces
        return self._result(forces, residual, converged, iterations)

    def push(self, prong_positions, prong_velocities, radius: float = 0.0) -> StepResult:
        """One step ``dt`` without an arm, pushed by prongs of ``radius`` [m] at
        ``prong_positions`` (k, 2) [m] moving at ``prong_velocities`` (k, 2) [m/s]
        (:func:`pushctl.contact.prescribed.push_substeps`)."""
        if self.arm is not None:
            raise StateError("push() moves prescribed prongs: this world has an arm (step)")
        state = push_substeps(self.solver, self._edges, self.object_pose, self.object_velocity,
                              prong_positions, prong_velocities, radius, self.config)  # fmt: skip
        self.object_pose, self.object_velocity, forces, residual, converged, pivots, gaps = state
        self._gaps, self.stats.steps = gaps, self.stats.steps + 1
        return self._result(forces, residual, converged, pivots)

    def contact_problem(self, tau=None, implicit_kv=None) -> ContactProblem:
        """The MLCP the next (sub)step would solve, without stepping: for inspection and
        benchmarks. Arguments as in :meth:`step`."""
        tau_arm, kv = self._check_command(tau, implicit_kv)
        prongs, state = self._step_state(tau_arm, self._damping + kv)
        return self.solver.problem(state, prongs)

    def _substep(self, tau: np.ndarray, damping: np.ndarray):
        """One (sub)step: the contact solve, then the object and the arm moved. Returns
        (prong forces (k, 2) [N], the solve's residual, whether it converged, its pivots)."""
        prongs, state = self._step_state(tau, damping)
        solved = self.solver.solve(state, prongs)
        if len(prongs) == self._n_prongs:
            forces = solved.forces
        else:
            forces = np.zeros((self._n_prongs, 2))
            for row, prong in enumerate(prongs):  # a loop, not a list index
                forces[prong] = solved.forces[row]
        # semi-implicit Euler: the pose moved with the new velocity (θ is not wrapped: the
        # plan and the metrics compare continuous angles)
        self.object_velocity, self.object_pose = solved.v_obj, solved.pose
        if self.arm is not None:
            self._advance_arm(solved.v_arm, self.solver.model.h)  # which finds the contacts
        else:
            self._find_contacts()
        return forces, solved.residual, solved.converged, solved.pivots

    def _step_state(
        self, tau: np.ndarray, damping: np.ndarray
    ) -> tuple[tuple[int, ...], StepState]:
        """The prongs in contact and the step's state: the kernels' leading arguments
        (:data:`~pushctl.contact.step_solver.STEP_STATE`). ``damping`` (nv,) [N·m·s/rad]:
        all joint damping applied implicitly."""
        terms = self._terms
        prongs: tuple[int, ...]
        if terms is None:
            prongs, contacts, jacobians = (), _NO_CONTACTS, _NO_JACOBIANS
            M, nle = _NO_ARM_MATRIX, self.v
        else:
            prongs, contacts = self._prongs, self._contacts
            jacobians = terms.prong_jacobians
            if len(prongs) < self._n_prongs:  # a kept index array, not a list
                jacobians = jacobians.take(PRONG_ROWS[prongs], axis=0)
            M, nle = terms.M, terms.nle
        state = (contacts, jacobians, M, nle, self.v, tau, damping, self.object_pose,
                 self.object_velocity)  # fmt: skip
        return prongs, state

    def _advance_arm(self, v_arm: np.ndarray, h: float) -> None:
        """Move the arm with its new velocity, then remove spurious energy it has gained;
        find the prongs' contacts at the new state (what :meth:`_find_contacts` does).

        In continuous time the Coriolis forces do no work: ½ q̇ᵀ Ṁ q̇ − q̇ᵀ C q̇ = 0. Semi-implicit
        Euler evaluates the two halves at different instants, and on a configuration-dependent
        M(q) their sum ``½ v⁺ᵀ (M(q⁺) − M(q)) v⁺ − h v⁺ᵀ C(q, v) v`` is an O(h²) energy per
        step of either sign (``make bench`` reports how much it removes from a fast free arm
        in 20 s: that is what the uncorrected step would have created). The steps' errors are
        summed in a ledger; whenever the sum is positive it is removed by scaling the new
        joint velocity and the ledger is cleared (an inequality form of the energy projection
        of geometric integration). Torque, gravity, damping and contact work are untouched.
        """
        arm, old = self.arm, self._terms
        assert arm is not None and old is not None  # only called for a world with an arm
        native = arm.native_handle()
        self.v = v_arm
        if native:  # integrate, the arm terms, the energy check and the geometry: one call
            new, energy, mask = self._advance_arm_native(native, old, v_arm, h)
        else:
            self.q = arm.integrate(self.q, v_arm, h)
            self._refresh_arm_terms()
            new = self._terms
            assert new is not None
            # the energy check and the prongs' geometry at the new state in one compiled call
            self._energy_ledger, energy, self._contacts, self._gaps, mask = arm_moved(
                self._energy_ledger, v_arm, old.M, old.nle, old.g, new.M, h, self._edges,
                self.object_pose, new.prong_positions, self.config.contact_margin,
            )  # fmt: skip
        self._prongs = mask_indices(mask)
        if self._energy_ledger > 0.0 and energy > 0.0:
            scale = math.sqrt(max(energy - self._energy_ledger, 0.0) / energy)
            self.stats.energy_removed += energy * (1.0 - scale**2)
            self._energy_ledger = 0.0
            self.v = scale * v_arm
            # c(q, v) is quadratic in v: rescale it instead of recomputing the terms.
            self._terms = new._replace(nle=new.g + scale**2 * (new.nle - new.g))
            self.stats.energy_corrections += 1

    def _advance_arm_native(self, handle: int, old: ArmTerms, v_arm: np.ndarray, h: float):
        """:meth:`_advance_arm`'s integration, arm terms, energy check and geometry as one
        call into the arm terms' library (:func:`native_arm_moved`: the same bits as the
        calls it replaces), into arrays made here. Sets q, the terms, the ledger, the
        contacts and the gaps; returns (the new terms, their kinetic energy [J], the
        contact mask)."""
        arm = self.arm
        assert arm is not None
        k = self._n_prongs
        arrays = self._end_arrays.take()  # q, geometry, gaps, the terms, the nominal frame's
        q, geometry, gaps, terms = arrays[0], arrays[1], arrays[2], arrays[_TERMS]
        common = (handle, self.q, v_arm, h, arm.prong_frames, arm.pusher_frame_id)
        tail = (self._energy_ledger, old.M, old.nle, old.g, self._edges, self.object_pose,
                self.config.contact_margin, q, *terms)  # fmt: skip
        nominal = arrays[_TERMS.stop :]  # the nominal frame's three, if the arm has one
        kernel: Any
        if nominal:
            args = (*common, arm.nominal_frame, *tail, *nominal, geometry, gaps)
            kernel = native_arm_moved_nominal
        else:
            args = (*common, *tail, geometry, gaps)
            kernel = native_arm_moved
        ledger, energy, contacts, mask = kernel(*args)
        if nominal:
            arm.record_nominal_pass(terms[-1], nominal)
        self.q, self._energy_ledger, self._gaps = q, ledger, gaps
        self._contacts = geometry if contacts == k else geometry[:contacts]
        self._terms = new = ArmTerms(*terms)
        return new, energy, mask

    # ---------------------------------------------------------------- helpers

    def _refresh_arm_terms(self) -> None:
        """Arm terms at the current state, computed once: the next step and the gaps use them."""
        self._terms = None if self.arm is None else self.arm.compute(self.q, self.v)

    def _find_contacts(self) -> None:
        """Prong–footprint geometry at the current state, found once: the step's result
        reports the gaps and the next step's rows use the contacts."""
        if self._terms is None:
            self._prongs, self._contacts, self._gaps = (), _NO_CONTACTS, np.zeros(0)
            return
        self._prongs, self._contacts, self._gaps = prong_contacts(
            self.object.polygon,
            self.object_pose,
            self._terms.prong_positions,
            self.config.contact_margin,
            self._edges,
        )

    def _check_command(self, tau, implicit_kv) -> tuple[np.ndarray, np.ndarray]:
        """Validated (tau (nv,), kv (nv,)); StateError naming the argument otherwise."""
        if self.arm is None:
            return np.zeros(0), np.zeros(0)
        # Fast path for the usual float64 vector: the sum of its entries is finite unless an
        # entry is NaN or ±inf (or the sum overflows: the full check then decides), cheaper
        # than a dot product with zeros or isfinite(...).all().
        # The dtype is compared with ==, not `is`: an array made by a compiled kernel loaded
        # from numba's disk cache (the PD law's torque) has a float64 dtype of its own.
        # C-contiguous too: one compiled signature of the step's kernels.
        if not (
            type(tau) is np.ndarray
            and tau.dtype == _FLOAT64
            and tau.shape == self._kv_zero.shape
            and tau.flags.c_contiguous
            and math.isfinite(sum(tau.tolist()))
        ):
            tau = np.ascontiguousarray(finite_vector("tau", tau, self._nv))
        if implicit_kv is None:
            return tau, self._kv_zero
        scalar = self._kv_scalar
        if type(implicit_kv) is float and implicit_kv == scalar[0]:  # validated when kept
            return tau, scalar[1]
        if isinstance(implicit_kv, (int, float)):
            # A scalar gain, usually the same every step: keep its array.
            if not (math.isfinite(implicit_kv) and implicit_kv >= 0.0):
                raise StateError(
                    f"implicit_kv must be finite and >= 0 N·m·s/rad, got {implicit_kv!r}"
                )
            if implicit_kv != self._kv_scalar[0]:
                kv = np.full(self._nv, float(implicit_kv))
                self._kv_scalar = (implicit_kv, kv, self._damping + kv)
            return tau, self._kv_scalar[1]
        kv = finite_vector("implicit_kv", implicit_kv, self._nv)
        # A gain array is the proxy's every step (its friction): the min of its list, not
        # kv.min() (finite, checked above, so the two agree).
        if min(kv.tolist()) < 0.0:
            raise StateError(f"implicit_kv must be >= 0 N·m·s/rad, got {kv.tolist()}")
        return tau, kv

    def _result(self, forces, residual: float, converged: bool, iterations: int) -> StepResult:
        """The state as a StepResult sharing the world's arrays: every step replaces them
        with arrays no one else holds (new ones, or an earlier step's that nothing outside
        the world references any more: :mod:`pushctl.contact.recycle`), and nothing writes
        into an array a caller holds, so no copies are needed."""
        return StepResult.sharing(
            self.object_pose,
            self.object_velocity,
            forces,
            self._gaps,
            self.q,
            self.v,
            float(residual),
            bool(converged),
            iterations,
        )

"""The world step: arm + pusher + planar object + table, one box-friction MLCP per step.

Generalised velocity ``v = [q̇_arm (nv); v_obj (3)]`` with ``v_obj = (vx, vy, ω)`` in the world
frame. Per step of length h (docs/design.md §3, the paper's eq. 6–8):

1. arm terms at (q, q̇): M (with armature), c + g, prong positions and Jacobians;
2. free velocity with implicit joint damping: ``(M + h K_d) q̇_free = M q̇ + h (τ − c − g)``,
   where K_d is the physical viscous damping plus any ``implicit_kv`` the controller hands
   over (its K_v, so a stiff PD stays stable at h = 0.01 s); the object has no applied
   force besides contact and friction, so ``v_obj,free = v_obj``;
3. contact rows A (m, nv + 3) from :mod:`pushctl.contact.rows`: a normal row (unilateral,
   position-stabilised) and a tangential row (box friction |p_t| ≤ μ_c p_n) per prong within
   ``contact_margin`` of the footprint, then two ground-friction rows per support point;
4. ``D = A M̃⁻¹ Aᵀ``, ``b = A v_free + stabilisation``; :func:`solve_box_mlcp` for the
   impulses p = h λ; ``v⁺ = v_free + M̃⁻¹ Aᵀ p``; positions integrated with v⁺.

Contact geometry is planar: a prong is a point, tested against the object's footprint
polygon in the table plane (its height is held by the controller, not by the contact).
Joint limits are not constraints of the world: keeping the arm inside them is the
controller's job.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from pushctl.arm import ArmModel, ArmTerms
from pushctl.checks import finite_vector
from pushctl.config import GRAVITY
from pushctl.contact.ground_field import FrictionField
from pushctl.contact.recycle import ArrayRecycler
from pushctl.contact.rows import edge_array, mask_indices, prong_contacts
from pushctl.contact.step_end import arm_moved, native_arm_moved, native_arm_moved_nominal
from pushctl.contact.substep import (
    _NO_CONTACTS,
    MAX_SLIP_ITERATIONS,
    SLIP_COS_TOLERANCE,
    STICK_FRACTION,
    TIE_BREAK,
    ContactModel,
    SubstepSolver,
)
from pushctl.errors import ConfigError, StateError
from pushctl.objects import ObjectSpec
from pushctl.types import ContactProblem, StepResult, WorldStats

__all__ = ["MAX_SLIP_ITERATIONS", "SLIP_COS_TOLERANCE", "STICK_FRACTION", "World", "WorldConfig"]

_FLOAT64 = np.dtype(np.float64)
_TERMS = slice(3, 3 + len(ArmTerms._fields))
"""Where an :class:`ArmTerms`' arrays sit in a set of the step end's arrays (after q, the
contact geometry and the gaps; the nominal frame's three follow)."""


DEFAULT_OBJECT_POSE = (0.42, 0.0, 0.0)
"""Object pose (x [m], y [m], θ [rad]) of ``World.reset()`` without arguments: 12 cm ahead
of the ready pusher of the Kinova arm, pushed face towards it."""


@dataclass(frozen=True)
class WorldConfig:
    """Numerical and friction parameters of the world step (SI units).

    ``dt`` [s] is the control and output step; ``substeps`` splits it internally.
    ``contact_margin`` [m]: prongs nearer than this to the footprint enter the MLCP (with a
    positive gap the row only acts if the step would close it: speculative contact).
    ``stabilisation`` (0, 1]: fraction of a penetration removed per (sub)step.
    ``gravity`` [m/s²]: magnitude, for the arm and the object's support loads.
    ``slip_iterations``: re-solves of a step whose ground friction directions move (see
    ``World._substep``); a step not settled after them keeps its first solution. 6, the
    default, is what ``results/`` was made with; fewer saves solves where objects slip, but
    under a tenth of a training push step's time (docs/reproducibility-and-speed.md, *The
    slip loop's length*).
    ``stick_fraction`` [0, 1): the stick rule (:func:`~pushctl.contact.kernels.refine_slip`):
    a sliding support point that moves and whose along-row friction impulse comes out
    below this fraction of its bound gets the rest box, and the step is solved again. 0,
    the default, turns it off and is what ``results/`` was made with; 1 − 10⁻⁶
    (:data:`STICK_FRACTION`) is the rule as measured (docs/reproducibility-and-speed.md,
    ninth to eleventh passes), not yet validated enough to be the default.
    """

    dt: float = 0.01
    mu_ground: float = 0.3
    mu_contact: float = 0.4
    substeps: int = 1
    contact_margin: float = 0.01
    stabilisation: float = 0.3
    gravity: float = GRAVITY
    slip_iterations: int = MAX_SLIP_ITERATIONS
    stick_fraction: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.dt) and self.dt > 0.0):
            raise ConfigError(f"dt must be a positive number of seconds, got {self.dt!r}")
        for name in ("mu_ground", "mu_contact"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ConfigError(f"{name} must be a finite number >= 0, got {value!r}")
        if not (isinstance(self.substeps, int) and self.substeps >= 1):
            raise ConfigError(f"substeps must be an integer >= 1, got {self.substeps!r}")
        iterations = self.slip_iterations
        if isinstance(iterations, bool) or not (isinstance(iterations, int) and iterations >= 0):
            raise ConfigError(f"slip_iterations must be an integer >= 0, got {iterations!r}")
        stick = self.stick_fraction
        if isinstance(stick, bool) or not (isinstance(stick, (int, float)) and 0 <= stick < 1):
            raise ConfigError(f"stick_fraction must be a number in [0, 1), got {stick!r}")
        object.__setattr__(self, "stick_fraction", float(stick))  # one compiled signature
        if not (math.isfinite(self.contact_margin) and self.contact_margin > 0.0):
            raise ConfigError(f"contact_margin must be > 0 m, got {self.contact_margin!r}")
        if not (0.0 < self.stabilisation <= 1.0):
            raise ConfigError(f"stabilisation must be in (0, 1], got {self.stabilisation!r}")
        if not (math.isfinite(self.gravity) and self.gravity >= 0.0):
            raise ConfigError(f"gravity must be a finite number >= 0 m/s², got {self.gravity!r}")


class World(SubstepSolver):
    """Arm (optional) + pusher + one object on the table. Build it with :func:`make_world`.

    The state, the step's orchestration and integration live here; solving one (sub)step's
    MLCP (its inputs, the compiled warm solve, the friction boxes' refinement, the full
    MLCP) in :class:`~pushctl.contact.substep.SubstepSolver`."""

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
        self.config = config
        self.stats = WorldStats()
        self._M_obj_inv = np.array([1.0 / obj.mass, 1.0 / obj.mass, 1.0 / obj.inertia_z])
        self._support_points = np.ascontiguousarray(obj.support_points, dtype=float)
        self._edges = edge_array(obj.polygon)
        # Support loads are computed at GRAVITY; the friction bounds follow the world's.
        self._uniform_limits = config.mu_ground * obj.support_loads * (config.gravity / GRAVITY)
        # the bounds of the step: the uniform ones scaled by the friction field, if any
        self._friction_limits = self._uniform_limits.copy()
        self._bounds_at = None  # the field and pose they were last computed for
        self._step_recyclers = {}  # slip_step's output arrays, per number of prongs touching
        # the step's two kernels' entry points, resolved at their first calls (direct_calls)
        self._slip_call = self._end_call = None
        self._slip_directions = np.zeros_like(self._support_points)
        self._sliding = np.zeros(len(self._support_points), dtype=np.bool_)
        # The kernels' world side, once: its arrays are the ones above, updated in place.
        self._model = ContactModel(
            obj_mass_inv=self._M_obj_inv,
            support_points=self._support_points,
            friction_limits=self._friction_limits,
            slip_directions=self._slip_directions,
            sliding=self._sliding,
            h=config.dt / config.substeps,
            stabilisation=config.stabilisation,
            tie_break=TIE_BREAK,
            mu_contact=config.mu_contact,
        )
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

    def __getstate__(self) -> dict:
        """A copy or a pickle resolves the step's kernels again at its first step: an entry
        point does not pickle."""
        state = self.__dict__.copy()
        state["_slip_call"] = state["_end_call"] = None
        return state

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
        # At rest the ground boxes align with e_n until a slip direction is seen.
        theta = self.object_pose[2]
        self._slip_directions[:] = (math.cos(theta), math.sin(theta))
        self._sliding[:] = False
        self._last_prongs: tuple[int, ...] | None = None
        self._last_p: np.ndarray | None = None
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
        h = self.config.dt / n_sub
        forces, residual, converged, iterations = self._substep(h, tau_arm, damping)
        for _ in range(n_sub - 1):
            more_forces, more_residual, more_converged, more = self._substep(h, tau_arm, damping)
            forces = forces + more_forces
            iterations += more
            if more_residual > residual:  # the worst substep's solve is reported
                residual, converged = more_residual, more_converged
        self.stats.steps += 1
        forces = forces / n_sub if n_sub > 1 else forces
        return self._result(forces, residual, converged, iterations)

    def contact_problem(self, tau=None, implicit_kv=None) -> ContactProblem:
        """The MLCP the next (sub)step would solve, without stepping: for inspection and
        benchmarks. Arguments as in :meth:`step`."""
        tau_arm, kv = self._check_command(tau, implicit_kv)
        directions, sliding = self._slip_directions.copy(), self._sliding.copy()
        h = self.config.dt / self.config.substeps
        self._start_slip_state()
        problem = self._build_problem(h, tau_arm, self._damping + kv)
        self._slip_directions[:], self._sliding[:] = directions, sliding  # keep the state
        return problem

    def _advance_object(self, v_obj: np.ndarray, h: float) -> None:
        """Semi-implicit Euler: the pose moves with the new velocity. θ is not wrapped: the
        plan and the metrics compare continuous angles."""
        self.object_velocity = v_obj
        self.object_pose = self.object_pose + h * v_obj

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
        call = self._end_call or self._resolve("_end_call", kernel, args)
        ledger, energy, contacts, mask = call(*args)
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
        # entry is NaN or ±inf (or the sum overflows: the full check then decides), 0.2 µs
        # where a dot product with zeros took 0.6 and isfinite(...).all() 1.5 (measured).
        # The dtype is compared with ==, not `is`: an array made by a compiled kernel loaded
        # from numba's disk cache (the PD law's torque) has a float64 dtype of its own.
        # C-contiguous too: the step's kernels are called past numba's dispatcher, which
        # would have typed a strided vector (pushctl.contact.direct_calls).
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
        # A gain array is the proxy's every step (its friction): the min of its list, 0.3 µs
        # where kv.min() took 1.5 (finite, checked above, so the two agree).
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

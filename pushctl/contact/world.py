"""The world step: arm + pusher + planar object + table, one box-friction MLCP per step.

Generalised velocity ``v = [q̇_arm (nv); v_obj (3)]`` with ``v_obj = (vx, vy, ω)`` in the world
frame. Per step of length h (DESIGN.md §3, the paper's eq. 6–8):

1. arm terms at (q, q̇): M (with armature), c + g, prong positions and Jacobians;
2. free velocity with implicit joint damping: ``(M + h K_d) q̇_free = M q̇ + h (τ − c − g)``,
   where K_d is the physical viscous damping plus any ``implicit_kv`` the controller hands
   over (its K_v, so a stiff PD stays stable at h = 0.01 s); the object has no applied
   force besides contact and friction, so ``v_obj,free = v_obj``;
3. contact rows A (m, nv + 3): each prong within ``contact_margin`` of the footprint gives a
   normal row (unilateral, position-stabilised) and a tangential row (box friction
   |p_t| ≤ μ_c p_n); each support point gives ground-friction rows with fixed bounds
   ±h μ_g N_j, aligned with its slip direction (one row while it slides, two at rest);
4. ``D = A M̃⁻¹ Aᵀ``, ``b = A v_free + stabilisation``; :func:`solve_box_mlcp` for the
   impulses p = h λ; ``v⁺ = v_free + M̃⁻¹ Aᵀ p``; positions integrated with v⁺.

Contact geometry is planar: a prong is a point, tested against the object's footprint
polygon in the table plane (its height is held by the controller, not by the contact).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pushctl.config import GRAVITY
from pushctl.contact.mlcp import MLCPResult, solve_box_mlcp
from pushctl.errors import ConfigError, StateError
from pushctl.objects import ObjectSpec

# A support point moving slower than this [m/s] counts as sticking: both friction rows get
# their full bound. Faster, friction acts only against the slip (the cross row is dropped),
# so the box is isotropic in the plane and does not lock the yaw of a sliding object.
_SLIP_SPEED = 1e-6


@dataclass(frozen=True)
class WorldConfig:
    """Numerical and friction parameters of the world step (SI units).

    ``dt`` [s] is the control and output step; ``substeps`` splits it internally.
    ``contact_margin`` [m]: prongs nearer than this to the footprint enter the MLCP (with a
    positive gap the row only acts if the step would close it: speculative contact).
    ``stabilisation`` (0, 1]: fraction of a penetration removed per (sub)step.
    """

    dt: float = 0.01
    mu_ground: float = 0.3
    mu_contact: float = 0.4
    substeps: int = 1
    contact_margin: float = 0.01
    stabilisation: float = 0.3
    gravity: float = GRAVITY

    def __post_init__(self) -> None:
        if not (math.isfinite(self.dt) and self.dt > 0.0):
            raise ConfigError(f"dt must be a positive number of seconds, got {self.dt!r}")
        for name in ("mu_ground", "mu_contact"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ConfigError(f"{name} must be a finite number >= 0, got {value!r}")
        if not (isinstance(self.substeps, int) and self.substeps >= 1):
            raise ConfigError(f"substeps must be an integer >= 1, got {self.substeps!r}")
        if not (math.isfinite(self.contact_margin) and self.contact_margin > 0.0):
            raise ConfigError(f"contact_margin must be > 0 m, got {self.contact_margin!r}")
        if not (0.0 < self.stabilisation <= 1.0):
            raise ConfigError(f"stabilisation must be in (0, 1], got {self.stabilisation!r}")
        if not (math.isfinite(self.gravity) and self.gravity >= 0.0):
            raise ConfigError(f"gravity must be a finite number >= 0 m/s², got {self.gravity!r}")


@dataclass(frozen=True)
class StepResult:
    """The world after one step. Forces are averaged over the step's substeps.

    ``contact_forces`` (k, 2): normal and tangential force [N] of each prong on the object in
    the contact frame (e_n into the object, e_t = e_z × e_n); zero for a prong out of contact.
    ``prong_gaps`` (k,): signed distance [m] of each prong to the footprint (negative:
    penetration). ``mlcp_residual``: the largest natural-map residual of the step's solves.
    """

    object_pose: np.ndarray
    object_velocity: np.ndarray
    contact_forces: np.ndarray
    prong_gaps: np.ndarray
    arm_q: np.ndarray
    arm_v: np.ndarray
    mlcp_residual: float
    mlcp_converged: bool
    mlcp_iterations: int


@dataclass
class WorldStats:
    """Counters over the life of a world: steps taken and MLCP solves that fell back."""

    steps: int = 0
    solves: int = 0
    fallbacks: int = 0
    warm_starts: int = 0
    energy_corrections: int = 0
    max_residual: float = 0.0


@dataclass(frozen=True)
class ContactProblem:
    """One step's box-friction MLCP in impulses p = h λ, and what is needed to apply it.

    ``D (m, m) = A M̃⁻¹ Aᵀ``, ``b (m,)``, bounds and friction indices as in
    :func:`solve_box_mlcp`. Rows: per prong in contact (normal, tangential), then the
    ground-friction rows of each support point.
    """

    h: float
    D: np.ndarray
    b: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    findex: np.ndarray
    mu: np.ndarray
    A_arm: np.ndarray  # (m, nv)
    v_arm_free: np.ndarray  # (nv,) [rad/s]
    Minv_At_arm: np.ndarray  # (nv, m)
    Minv_At_obj: np.ndarray  # (3, m)
    prong_rows: list[int]
    key: tuple


@dataclass
class _Rows:
    """The contact rows of one (sub)step, assembled before the MLCP solve."""

    A_arm: np.ndarray  # (m, nv)
    A_obj: np.ndarray  # (m, 3)
    bias: np.ndarray  # (m,) stabilisation velocity added to A v_free [m/s]
    lo: np.ndarray
    hi: np.ndarray
    findex: np.ndarray
    mu: np.ndarray
    prong_rows: list[int] = field(default_factory=list)  # normal-row index per prong, -1 if none
    key: tuple = ()


class World:
    """Arm (optional) + pusher + one object on the table. Build it with :func:`make_world`."""

    def __init__(self, obj: ObjectSpec, arm, config: WorldConfig) -> None:
        self.object = obj
        self.arm = arm
        self.config = config
        self.stats = WorldStats()
        self._M_obj_inv = np.array([1.0 / obj.mass, 1.0 / obj.mass, 1.0 / obj.inertia_z])
        # Ground-friction bounds scale with gravity; support loads are computed at GRAVITY.
        self._support_friction = config.mu_ground * obj.support_loads * (config.gravity / GRAVITY)
        self._n_prongs = 0 if arm is None else arm.pusher.n_prongs
        self._nv = 0 if arm is None else arm.nv
        self._damping = np.zeros(self._nv) if arm is None else np.asarray(arm.damping, float)
        self._last_key: tuple = ()
        self._last_p: np.ndarray | None = None
        self.reset()

    # ------------------------------------------------------------------ state

    def reset(
        self,
        object_pose=(0.42, 0.0, 0.0),
        object_velocity=(0.0, 0.0, 0.0),
        arm_q=None,
        arm_v=None,
    ) -> StepResult:
        """Set the state. ``object_pose`` (x [m], y [m], θ [rad]); ``arm_q=None`` is the ready
        configuration, ``arm_v=None`` rest. Returns the state as a zero-force StepResult."""
        self.object_pose = _finite_vector(object_pose, 3, "object_pose")
        self.object_velocity = _finite_vector(object_velocity, 3, "object_velocity")
        if self.arm is None:
            self.q = np.zeros(0)
            self.v = np.zeros(0)
        else:
            q = self.arm.q_ready if arm_q is None else arm_q
            self.q = _finite_vector(q, self.arm.nq, "arm_q")
            self.v = (
                np.zeros(self._nv) if arm_v is None else _finite_vector(arm_v, self._nv, "arm_v")
            )
        # At rest the ground boxes align with the object's e_n until a slip direction is seen.
        theta = self.object_pose[2]
        self._slip_dirs = np.tile(
            [math.cos(theta), math.sin(theta)], (len(self.object.support_points), 1)
        )
        self._last_key, self._last_p = (), None
        self._energy_ledger = 0.0  # spurious arm kinetic energy not yet removed [J]
        self._refresh_arm_terms()
        return self._result(np.zeros((self._n_prongs, 2)), self._prong_gaps(), None)

    def prong_positions(self) -> np.ndarray:
        """World positions [m] of the prongs at the current arm state, (k, 3)."""
        if self.arm is None:
            return np.zeros((0, 3))
        return self._terms.prong_positions.copy()

    def gravity_torque(self) -> np.ndarray:
        """g(q) [N·m] at the current arm state, (nv,); empty for an object-only world."""
        if self.arm is None:
            return np.zeros(0)
        return self.arm.gravity(self.q)

    # ------------------------------------------------------------------- step

    def step(self, tau=None, implicit_kv=None) -> StepResult:
        """Advance one control step ``dt`` with joint torques ``tau`` (nv,) [N·m].

        ``implicit_kv`` (nv,) or scalar [N·m·s/rad], optional: a joint damping gain applied to
        the *new* joint velocity, i.e. the −K_v q̇ term of a PD law evaluated implicitly (the
        caller then passes τ without it). Explicit damping of a light wrist diverges at
        h = 0.01 s; the implicit form is unconditionally stable. Ignored when arm is None.
        """
        tau_arm, kv = self._check_command(tau, implicit_kv)
        n_sub = self.config.substeps
        h = self.config.dt / n_sub
        force_sum = np.zeros((self._n_prongs, 2))
        worst: MLCPResult | None = None
        iterations = 0
        for _ in range(n_sub):
            forces, result = self._substep(h, tau_arm, kv)
            force_sum += forces
            if result is not None:
                iterations += result.iterations
                if worst is None or result.residual > worst.residual:
                    worst = result
        self.stats.steps += 1
        gaps = self._prong_gaps()
        return self._result(force_sum / n_sub, gaps, worst, iterations)

    def contact_problem(self, tau=None, implicit_kv=None) -> ContactProblem:
        """The MLCP the next (sub)step would solve, without stepping: for inspection and
        benchmarks. Arguments as in :meth:`step`."""
        tau_arm, kv = self._check_command(tau, implicit_kv)
        return self._build_problem(self.config.dt / self.config.substeps, tau_arm, kv)

    def _build_problem(self, h: float, tau: np.ndarray, kv: np.ndarray) -> ContactProblem:
        """Free velocities and the contact MLCP of one time step of length h."""
        rows = self._assemble_rows(self._terms, h)
        m = len(rows.lo)
        if self.arm is None:
            v_arm_free, Minv_At_arm = np.zeros(0), np.zeros((0, m))
        else:
            terms = self._terms
            M_tilde = terms.M + np.diag(h * (self._damping + kv))
            rhs = terms.M @ self.v + h * (tau - terms.nle)
            # One solve gives the free velocity and M̃⁻¹ A_armᵀ together.
            sol = np.linalg.solve(M_tilde, np.column_stack((rhs, rows.A_arm.T)))
            v_arm_free, Minv_At_arm = sol[:, 0], sol[:, 1:]
        Minv_At_obj = self._M_obj_inv[:, None] * rows.A_obj.T
        D = rows.A_obj @ Minv_At_obj + rows.A_arm @ Minv_At_arm
        b = rows.A_obj @ self.object_velocity + rows.A_arm @ v_arm_free + rows.bias
        return ContactProblem(
            h=h,
            D=D,
            b=b,
            lo=rows.lo,
            hi=rows.hi,
            findex=rows.findex,
            mu=rows.mu,
            A_arm=rows.A_arm,
            v_arm_free=v_arm_free,
            Minv_At_arm=Minv_At_arm,
            Minv_At_obj=Minv_At_obj,
            prong_rows=rows.prong_rows,
            key=rows.key,
        )

    def _substep(self, h: float, tau: np.ndarray, kv: np.ndarray):
        """One MLCP time step of length h. Returns (prong forces (k, 2) [N], MLCP result)."""
        problem = self._build_problem(h, tau, kv)
        forces = np.zeros((self._n_prongs, 2))
        result = None
        v_arm, v_obj = problem.v_arm_free, self.object_velocity
        arm_impulse = np.zeros(self._nv)  # generalised contact impulse on the arm [N·m·s]
        if len(problem.b):
            warm = self._last_p if problem.key == self._last_key else None
            result = solve_box_mlcp(
                problem.D,
                problem.b,
                problem.lo,
                problem.hi,
                problem.findex,
                problem.mu,
                warm_start=warm,
            )
            self._record(result, problem.key)
            p = result.p
            v_arm = v_arm + problem.Minv_At_arm @ p
            v_obj = v_obj + problem.Minv_At_obj @ p
            arm_impulse = problem.A_arm.T @ p
            for i, row in enumerate(problem.prong_rows):
                if row >= 0:
                    forces[i] = p[row : row + 2] / h
        self._advance_object(v_obj, h)
        if self.arm is not None:
            self._advance_arm(v_arm, h)
        return forces, result

    def _advance_object(self, v_obj: np.ndarray, h: float) -> None:
        """Semi-implicit Euler: the pose moves with the new velocity. θ is not wrapped: the
        plan and the metrics compare continuous angles."""
        self.object_velocity = v_obj
        self.object_pose = self.object_pose + h * v_obj

    def _advance_arm(self, v_arm: np.ndarray, h: float) -> None:
        """Move the arm with its new velocity, then remove spurious energy it has gained.

        In continuous time the Coriolis forces do no work: ½ q̇ᵀ Ṁ q̇ − q̇ᵀ C q̇ = 0. Semi-implicit
        Euler evaluates the two halves at different instants, and on a configuration-dependent
        M(q) their sum ``½ v⁺ᵀ (M(q⁺) − M(q)) v⁺ − h v⁺ᵀ C(q, v) v`` is an O(h²) energy per
        step of either sign (measured on the Kinova arm without gravity, before this
        correction: +1.5 % in 20 s at 0.3 rad/s, +19–30 % at 1 rad/s). The steps' errors are
        summed in a ledger; whenever the sum is positive it is removed by scaling the new
        joint velocity and the ledger is cleared (an inequality form of the energy projection
        of geometric integration). Torque, gravity, damping and contact work are untouched.
        """
        old = self._terms
        coriolis_power = v_arm @ (old.nle - old.g)  # v⁺ᵀ C(q, v) v [W]
        self.q = self.arm.integrate(self.q, v_arm, h)
        self.v = v_arm
        self._refresh_arm_terms()
        new = self._terms
        energy = 0.5 * v_arm @ new.M @ v_arm
        self._energy_ledger += energy - 0.5 * v_arm @ old.M @ v_arm - h * coriolis_power
        if self._energy_ledger > 0.0 and energy > 0.0:
            scale = math.sqrt(max(energy - self._energy_ledger, 0.0) / energy)
            self._energy_ledger = 0.0
            self.v = scale * v_arm
            # c(q, v) is quadratic in v: rescale it instead of recomputing the terms.
            self._terms = new._replace(nle=new.g + scale**2 * (new.nle - new.g))
            self.stats.energy_corrections += 1

    def _record(self, result: MLCPResult, key: tuple) -> None:
        self.stats.solves += 1
        self.stats.fallbacks += int(not result.converged)
        self.stats.warm_starts += int(result.method == "warm-start")
        self.stats.max_residual = max(self.stats.max_residual, result.residual)
        self._last_key, self._last_p = key, result.p

    # --------------------------------------------------------------- assembly

    def _assemble_rows(self, terms, h: float) -> _Rows:
        """Prong rows (normal, tangential per prong in contact) then ground rows."""
        c, s = math.cos(self.object_pose[2]), math.sin(self.object_pose[2])
        x0, y0 = self.object_pose[0], self.object_pose[1]
        arm_rows, obj_rows, bias, lo, hi, findex, mu = [], [], [], [], [], [], []
        prong_rows, key = [], []
        stab = self.config.stabilisation
        query = self.object.polygon.query
        for i in range(self._n_prongs):
            px, py = terms.prong_positions[i, 0] - x0, terms.prong_positions[i, 1] - y0
            gap, n_lx, n_ly, cl_x, cl_y = query(c * px + s * py, -s * px + c * py)
            if gap >= self.config.contact_margin:
                prong_rows.append(-1)
                continue
            # e_n: into the object (minus the outward normal); e_t = e_z × e_n.
            nx, ny = -(c * n_lx - s * n_ly), -(s * n_lx + c * n_ly)
            # r: from the centre of mass to the contact point on the surface, world axes.
            rx, ry = c * cl_x - s * cl_y, s * cl_x + c * cl_y
            J = terms.prong_jacobians[i]
            for ex, ey in ((nx, ny), (-ny, nx)):
                # Relative velocity of the object's contact point w.r.t. the prong along e.
                arm_rows.append(-(ex * J[0] + ey * J[1]))
                obj_rows.append((ex, ey, rx * ey - ry * ex))
            prong_rows.append(len(lo))
            bias.extend((gap / h if gap >= 0.0 else stab * gap / h, 0.0))
            lo.extend((0.0, 0.0))
            hi.extend((np.inf, 0.0))
            findex.extend((-1, len(lo) - 2))
            mu.extend((0.0, self.config.mu_contact))
            key.append(i)
        key.append(-1)
        self._ground_rows(c, s, h, obj_rows, bias, lo, hi, findex, mu, key)
        m = len(lo)
        A_arm = np.array(arm_rows).reshape(-1, self._nv) if arm_rows else np.zeros((0, self._nv))
        if len(arm_rows) < m:
            A_arm = np.vstack((A_arm, np.zeros((m - len(arm_rows), self._nv))))
        return _Rows(
            A_arm=A_arm,
            A_obj=np.array(obj_rows, dtype=float).reshape(m, 3),
            bias=np.array(bias),
            lo=np.array(lo),
            hi=np.array(hi),
            findex=np.array(findex, dtype=np.int64),
            mu=np.array(mu),
            prong_rows=prong_rows,
            key=tuple(key),
        )

    def _ground_rows(self, c, s, h, obj_rows, bias, lo, hi, findex, mu, key) -> None:
        """Box friction at each support point, aligned with its slip direction."""
        vx, vy, omega = self.object_velocity
        for j, (sx, sy) in enumerate(self.object.support_points):
            rx, ry = c * sx - s * sy, s * sx + c * sy
            ux, uy = vx - omega * ry, vy + omega * rx
            speed = math.hypot(ux, uy)
            bound = h * self._support_friction[j]
            if speed > _SLIP_SPEED:
                dx, dy = ux / speed, uy / speed
                self._slip_dirs[j] = (dx, dy)
                directions = ((dx, dy),)
            else:
                dx, dy = self._slip_dirs[j]
                directions = ((dx, dy), (-dy, dx))
            for ex, ey in directions:
                obj_rows.append((ex, ey, rx * ey - ry * ex))
                bias.append(0.0)
                lo.append(-bound)
                hi.append(bound)
                findex.append(-1)
                mu.append(0.0)
            key.append(len(directions))

    # ---------------------------------------------------------------- helpers

    def _refresh_arm_terms(self) -> None:
        """Arm terms at the current state, computed once: the next step and the gaps use them."""
        self._terms = None if self.arm is None else self.arm.compute(self.q, self.v)

    def _prong_gaps(self) -> np.ndarray:
        """Signed distance [m] of each prong to the footprint at the current state, (k,)."""
        if self.arm is None:
            return np.zeros(0)
        positions = self._terms.prong_positions
        c, s = math.cos(self.object_pose[2]), math.sin(self.object_pose[2])
        gaps = np.empty(self._n_prongs)
        for i in range(self._n_prongs):
            px, py = positions[i, 0] - self.object_pose[0], positions[i, 1] - self.object_pose[1]
            gaps[i] = self.object.polygon.query(c * px + s * py, -s * px + c * py)[0]
        return gaps

    def _check_command(self, tau, implicit_kv):
        if self.arm is None:
            return np.zeros(0), np.zeros(0)
        tau = _finite_vector(tau, self._nv, "tau", StateError)
        if implicit_kv is None:
            return tau, np.zeros(self._nv)
        kv = (
            np.broadcast_to(np.asarray(implicit_kv, dtype=float), (self._nv,))
            if np.ndim(implicit_kv) == 0
            else _finite_vector(implicit_kv, self._nv, "implicit_kv", StateError)
        )
        if not np.all(np.isfinite(kv)) or np.any(kv < 0.0):
            raise StateError(f"implicit_kv must be finite and >= 0 N·m·s/rad, got {implicit_kv!r}")
        return tau, kv

    def _result(self, forces, gaps, result: MLCPResult | None, iterations: int = 0) -> StepResult:
        return StepResult(
            object_pose=self.object_pose.copy(),
            object_velocity=self.object_velocity.copy(),
            contact_forces=forces,
            prong_gaps=gaps,
            arm_q=self.q.copy(),
            arm_v=self.v.copy(),
            mlcp_residual=0.0 if result is None else float(result.residual),
            mlcp_converged=True if result is None else bool(result.converged),
            mlcp_iterations=iterations,
        )


def _finite_vector(value, n: int, name: str, error=StateError) -> np.ndarray:
    """``value`` as a float vector of length n, or a one-line error saying what is accepted."""
    try:
        array = np.array(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise error(f"{name} must be a sequence of {n} numbers, got {value!r}") from None
    if array.shape != (n,) or np.ndim(value) > 1:
        raise error(f"{name} must have length {n}, got shape {np.shape(value)}")
    if not np.all(np.isfinite(array)):
        raise error(f"{name} must be finite (no NaN or infinity), got {array.tolist()}")
    return array

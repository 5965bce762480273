"""Force distribution (the paper's eq. 11–13): the prong forces that make the object follow
its plan.

At every planned instant the object needs, from the pusher, the wrench
``w = M_ob a_des − f_ground`` (Newton–Euler; ground friction from :mod:`.ground`), which
this module expresses in the object's local frame as (w_n, w_t, w_τ): force along e_n,
along e_t [N] and torque about the centre of mass [N·m]. Prong i at r_i = (−d, δ + o_i)
(d: centre of mass to the pushed face, o_i: the prong's offset on the plate, δ: the plate's
offset along the face) pushes with (F_n,i, F_t,i). Per step the QP

    min_F  ½‖S (G(δ) F − w)‖² + ½ ε ‖F‖²   s.t.  |F_t,i| ≤ μ_c F_n,i   (so F_n,i ≥ 0)

is solved with ProxQP, where G(δ) (3, 2k) maps prong forces to the wrench and
S = diag(1, 1, 1/L) weighs the torque row by the face half-width L, so the torque residual
counts in newtons like the others (torques are ~0.01 N·m against ~1 N of force). The tiny ε
breaks the tie among the many exact solutions (2k unknowns, 3 equations) towards minimum
norm, as the simulator's 1e-6·D_ii term does. The residual ‖S (G F − w)‖ is the step's
Newton–Euler residual [N]; a step is feasible when it is below ``feasibility_tolerance``.

The offset δ is one value per plan (the plate does not slide along the face by design). It
is chosen by scipy's bounded scalar search inside the admissible interval (prongs on the
face, ``face_margin`` inside its ends), first to minimise the worst residual and then to
maximise the smallest share of the push carried by any prong over the plan: the plate is
centred on the line of action of the required force, so no prong is close to lifting off.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from pushctl import native
from pushctl.errors import ConfigError
from pushctl.machine.proxqp_build import proxqp
from pushctl.objects import ObjectSpec
from pushctl.planning.ground import sliding_friction
from pushctl.planning.infeasible import explain
from pushctl.planning.trajectory import Trajectory

# Weight of the worst residual [N] against the prong-share term [-] in the offset search.
_RESIDUAL_WEIGHT = 1e3
_NO_BOUND = 1e20
# ProxQP's absolute tolerance on the scaled problem [-] and its iteration cap.
_QP_TOLERANCE = 1e-12
_QP_MAX_ITER = 1000
_SOLVED = proxqp.QPSolverOutput.PROXQP_SOLVED
_WARM = proxqp.InitialGuess.WARM_START_WITH_PREVIOUS_RESULT


@dataclass(frozen=True)
class ForceSettings:
    """Parameters of the force distribution.

    ``mu_contact`` prong–object friction μ_c [-]; ``mu_ground`` object–table friction μ_g [-];
    ``face_margin`` [m]: the prongs stay this far inside the ends of the pushed face;
    ``regularisation`` ε [-] relative to the mean diagonal of the weighted normal matrix;
    ``feasibility_tolerance`` [N]: the largest Newton–Euler residual of a feasible step;
    ``search_samples``: steps the offset search evaluates (evenly spaced; the final
    distribution is solved and checked on every step).
    """

    mu_contact: float = 0.4
    mu_ground: float = 0.3
    face_margin: float = 0.003
    regularisation: float = 1e-6
    feasibility_tolerance: float = 1e-5
    search_samples: int = 200

    def __post_init__(self) -> None:
        if not (math.isfinite(self.mu_contact) and 0.0 < self.mu_contact <= 5.0):
            raise ConfigError(f"mu_contact must be in (0, 5], got {self.mu_contact!r}")
        if not (math.isfinite(self.mu_ground) and 0.0 <= self.mu_ground <= 5.0):
            raise ConfigError(f"mu_ground must be in [0, 5], got {self.mu_ground!r}")
        if not (math.isfinite(self.face_margin) and self.face_margin >= 0.0):
            raise ConfigError(f"face_margin must be >= 0 m, got {self.face_margin!r}")


@dataclass(frozen=True)
class ForcePlan:
    """The force distribution of a plan with N samples and k prongs.

    ``offset`` δ [m] of the plate's centre along the face (e_t) from the centre of mass's
    foot on it; ``offset_range`` (lo, hi) [m] its admissible interval; ``prong_points``
    (k, 2) r_i [m] in the object frame; ``wrench`` (N, 3) the required (w_n, w_t, w_τ)
    [N, N, N·m], object frame; ``forces`` (N, k, 2) (F_n,i, F_t,i) [N]; ``torques`` (N, k)
    τ_z,i = r_i × F_i [N·m]; ``residual`` (N,) [N]; ``feasible``; ``reason``: why not, with
    the first infeasible step, else None.
    """

    offset: float
    offset_range: tuple[float, float]
    prong_points: np.ndarray
    wrench: np.ndarray
    forces: np.ndarray
    torques: np.ndarray
    residual: np.ndarray
    feasible: bool
    reason: str | None

    @property
    def total_torque(self) -> np.ndarray:
        """Σ_i τ_z,i (N,) [N·m]."""
        return self.torques.sum(axis=1)


def required_wrench(
    trajectory: Trajectory,
    obj: ObjectSpec,
    mu_ground: float,
    gravity: float,
    friction_limits: np.ndarray | None = None,
) -> np.ndarray:
    """The wrench the pusher must apply at each sample, object frame, (N, 3) [N, N, N·m].
    ``friction_limits`` (N, S) [N]: per-sample sliding friction of each support point
    (:func:`~pushctl.planning.ground.sliding_friction`'s ``limits``), None for μ_g N_j."""
    # the direction of motion per unit arc fraction, (dp/ds, dθ/ds): defined at rest too
    turn = np.full(len(trajectory.t), trajectory.delta_theta)
    direction = np.column_stack([trajectory.path_tangent, turn])
    friction = sliding_friction(
        obj, mu_ground, trajectory.pose, direction, gravity, friction_limits
    )
    inertial = trajectory.acceleration * np.array([obj.mass, obj.mass, obj.inertia_z])
    world = inertial - friction
    cos, sin = np.cos(trajectory.pose[:, 2]), np.sin(trajectory.pose[:, 2])
    return np.column_stack(
        [cos * world[:, 0] + sin * world[:, 1], -sin * world[:, 0] + cos * world[:, 1], world[:, 2]]
    )


def admissible_offsets(
    obj: ObjectSpec, prong_offsets: np.ndarray, margin: float
) -> tuple[float, float]:
    """Interval (lo, hi) [m] of plate offsets δ keeping every prong on the face, ``margin``
    inside its ends. ConfigError if the prongs do not fit."""
    t_min, t_max = (float(v) for v in obj.face_extent)
    lo = t_min + margin - float(prong_offsets.min())
    hi = t_max - margin - float(prong_offsets.max())
    if lo > hi + 1e-12:
        raise ConfigError(
            f"the prongs span {1e3 * np.ptp(prong_offsets):.1f} mm but the pushed face of "
            f"{obj.name!r} leaves {1e3 * (t_max - t_min - 2 * margin):.1f} mm inside its "
            f"{1e3 * margin:.1f} mm margins"
        )
    return lo, max(lo, hi)


class _StepQP:
    """The per-step QP for one offset: G, S and the cone rows are fixed, only w changes."""

    def __init__(self, points: np.ndarray, mu: float, half_width: float, settings: ForceSettings):
        k = len(points)
        self.G = np.zeros((3, 2 * k))
        self.G[0, 0::2] = 1.0
        self.G[1, 1::2] = 1.0
        self.G[2, 0::2] = -points[:, 1]  # τ = r_n F_t − r_t F_n
        self.G[2, 1::2] = points[:, 0]
        self.weights = np.array([1.0, 1.0, 1.0 / half_width])
        weighted = self.weights[:, None] * self.G
        hessian = weighted.T @ weighted
        hessian += settings.regularisation * np.mean(np.diag(hessian)) * np.eye(2 * k)
        cone = np.zeros((2 * k, 2 * k))
        for i in range(k):
            cone[2 * i, 2 * i : 2 * i + 2] = (-mu, 1.0)  # F_t − μ F_n ≤ 0
            cone[2 * i + 1, 2 * i : 2 * i + 2] = (-mu, -1.0)  # −F_t − μ F_n ≤ 0
        self._cone = cone
        self._lower = np.full(2 * k, -_NO_BOUND)
        self._upper = np.zeros(2 * k)
        self._gradient_map = -(weighted.T * self.weights)  # g = −Gᵀ S² w
        self._hessian = np.ascontiguousarray(hessian)  # the compiled solve reads raw memory
        self._qp: proxqp.dense.QP | None = None  # made by the first solve through Python

    def _make_qp(self) -> proxqp.dense.QP:
        """The one QP object of this offset: warm-started from step to step."""
        n = self._hessian.shape[0]
        qp = proxqp.dense.QP(n, 0, n)
        qp.settings.eps_abs = _QP_TOLERANCE
        qp.settings.eps_rel = 0.0
        qp.settings.max_iter = _QP_MAX_ITER
        qp.init(self._hessian, np.zeros(n), None, None, self._cone, self._lower, self._upper)
        qp.settings.initial_guess = _WARM
        return qp

    def _solve_one(self, gradient: np.ndarray) -> np.ndarray:
        """Warm start from the previous step; on any status but SOLVED (ProxQP now and then
        reports a warm-started instance of this always-feasible QP primal infeasible after
        one iteration) solve it again from scratch. NaN if that fails too."""
        if self._qp is None:
            self._qp = self._make_qp()
        qp = self._qp
        qp.update(None, gradient, None, None, self._cone, self._lower, self._upper)
        qp.solve()
        if qp.results.info.status == _SOLVED:
            return qp.results.x.copy()
        return self._solve_cold(gradient)

    def _solve_cold(self, gradient: np.ndarray) -> np.ndarray:
        """The QP of ``gradient`` solved from scratch by a QP of its own; NaN if it fails."""
        cold = proxqp.dense.solve(
            self._hessian, gradient, None, None, self._cone, self._lower, self._upper,
            eps_abs=_QP_TOLERANCE, eps_rel=0.0, max_iter=_QP_MAX_ITER,
        )  # fmt: skip
        if cold.info.status == _SOLVED:
            return cold.x.copy()
        return np.full(len(gradient), np.nan)

    def solve(self, wrenches: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Forces (N, 2k) and weighted residuals (N,) [N] for wrenches (N, 3); a step whose
        QP fails gets NaN forces and a NaN residual.

        The QP runs on wrenches divided by their largest magnitude, so its absolute
        tolerance is relative to the plan's forces whatever their size. Each instance
        solves one sequence (its offset's steps, warm-started one from the next): the
        compiled path's QP object lives for one call, so a second call on an instance that
        solved compiled would not warm-start from the first (no caller makes one)."""
        scale = float(np.abs(wrenches).max()) or 1.0
        gradients = (wrenches / scale) @ self._gradient_map.T
        if self._qp is None and native.available():
            solutions = self._solve_compiled(gradients)
        else:
            solutions = np.array([self._solve_one(gradient) for gradient in gradients])
        forces = scale * solutions
        residual = np.linalg.norm((forces @ self.G.T - wrenches) * self.weights, axis=1)
        return forces, residual

    def _solve_compiled(self, gradients: np.ndarray) -> np.ndarray:
        """:meth:`_solve_one` for every gradient (N, 2k) in turn, in one call into pushctl's
        compiled library (:mod:`pushctl.native`: the same ProxQP calls, the same bits,
        without a Python round trip per QP); the warm solves it does not report solved
        are solved again from scratch here, as :meth:`_solve_one` does."""
        gradients = np.ascontiguousarray(gradients, dtype=np.float64)
        count, n = gradients.shape
        solutions = np.empty((count, n))
        solved = np.empty(count, dtype=np.int8)
        native.library().pushctl_force_qps(
            n, len(self._lower), self._hessian.ctypes.data, self._cone.ctypes.data,
            self._lower.ctypes.data, self._upper.ctypes.data, count, gradients.ctypes.data,
            _QP_TOLERANCE, _QP_MAX_ITER, solutions.ctypes.data, solved.ctypes.data,
        )  # fmt: skip
        for row in np.flatnonzero(solved == 0):
            solutions[row] = self._solve_cold(gradients[row])
        return solutions


def _prong_points(obj: ObjectSpec, prong_offsets: np.ndarray, offset: float) -> np.ndarray:
    return np.column_stack([np.full(len(prong_offsets), -obj.face_offset), offset + prong_offsets])


def distribute_forces(
    trajectory: Trajectory,
    obj: ObjectSpec,
    prong_offsets: np.ndarray,
    settings: ForceSettings,
    gravity: float,
    offset: float | None = None,
    friction_limits: np.ndarray | None = None,
) -> ForcePlan:
    """Choose the plate offset and the prong forces at every sample of ``trajectory``.

    ``prong_offsets`` (k,) [m]: the prongs' positions along the plate
    (:meth:`PusherConfig.prong_offsets`). ``offset`` [m]: use this plate offset instead of
    searching for one (the forces a plan made with other parameters needs at its offset).
    ``friction_limits`` (N, S) [N]: each support point's sliding friction per sample, for a
    plant whose ground friction varies over the table (None: μ_g N_j everywhere).
    Never raises for an infeasible plan: the result's ``feasible`` and ``reason`` say what
    failed.
    """
    prong_offsets = np.asarray(prong_offsets, dtype=float)
    wrench = required_wrench(trajectory, obj, settings.mu_ground, gravity, friction_limits)
    lo, hi = admissible_offsets(obj, prong_offsets, settings.face_margin)
    half_width = 0.5 * float(np.ptp(obj.face_extent))
    sample = np.unique(
        np.linspace(0, len(wrench) - 1, min(len(wrench), settings.search_samples)).astype(int)
    )

    def cost(offset: float) -> float:
        points = _prong_points(obj, prong_offsets, offset)
        forces, residual = _StepQP(points, settings.mu_contact, half_width, settings).solve(
            wrench[sample]
        )
        normals = np.nan_to_num(forces[:, 0::2], nan=0.0)
        share = normals.min(axis=1) / np.maximum(normals.sum(axis=1), 1e-12)
        worst = float(np.nan_to_num(residual, nan=np.abs(wrench).max()).max())
        return _RESIDUAL_WEIGHT * worst - float(share.min())

    if offset is not None:
        offset = float(offset)
    elif hi - lo > 1e-9:
        offset = float(
            minimize_scalar(cost, bounds=(lo, hi), method="bounded", options={"xatol": 1e-6}).x
        )
    else:
        offset = lo
    points = _prong_points(obj, prong_offsets, offset)
    flat, residual = _StepQP(points, settings.mu_contact, half_width, settings).solve(wrench)
    forces = flat.reshape(len(wrench), -1, 2)
    torques = points[:, 0] * forces[:, :, 1] - points[:, 1] * forces[:, :, 0]
    bad = np.flatnonzero(~(residual <= settings.feasibility_tolerance))  # NaN counts as bad
    reason = None
    if bad.size:
        reason = explain(
            trajectory, wrench, points, settings.mu_contact, int(bad[0]), int(bad.size)
        )
    return ForcePlan(
        offset=offset,
        offset_range=(lo, hi),
        prong_points=points,
        wrench=wrench,
        forces=forces,
        torques=torques,
        residual=residual,
        feasible=not bad.size,
        reason=reason,
    )

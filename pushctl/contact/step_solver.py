"""The contact solve of one world (sub)step: its MLCP, solved with the ground's friction
boxes refined against the solved slip (:class:`StepSolver`, held by
:class:`~pushctl.contact.world.World`).

The whole solve is one compiled call (:func:`~pushctl.contact.compiled.step.slip_step`).
Only a solve that the compiled pivoting does not verify comes back here: ProxQP solves
that problem (:func:`~pushctl.contact.mlcp.solve_after_pivoting`) and the compiled loop
resumes (:func:`~pushctl.contact.compiled.step.resume_step`).
"""

from __future__ import annotations

import math
from typing import NamedTuple, TypeAlias

import numpy as np

from pushctl.contact.compiled.assembly import apply_impulses, assemble, slip_state
from pushctl.contact.compiled.step import (
    NEEDS_PROXQP,
    UNSETTLED,
    fixed_problem,
    fixed_step,
    resume_step,
    slip_step,
)
from pushctl.contact.ground_field import FrictionField
from pushctl.contact.mlcp import DEFAULT_TOL, MLCPResult, cold_pivot_budget, solve_after_pivoting
from pushctl.contact.recycle import ArrayRecycler
from pushctl.contact.world_config import GROUND_COMPLIANCE, WorldConfig
from pushctl.objects import ObjectSpec
from pushctl.types import ContactProblem, WorldStats

STEP_STATE = (
    "contacts", "jacobians", "M", "nle", "v_arm", "tau", "joint_damping", "pose", "velocity"
)  # fmt: skip
"""The leading parameters of the step's kernels (:func:`~pushctl.contact.compiled.assembly.
assemble`, :func:`~pushctl.contact.compiled.step.slip_step`, ``resume_step``): the state of
one step, which changes every step (shapes and units in ``assemble``). The world passes them
as a plain tuple in this order, then the solver's :class:`ContactModel`."""

StepState: TypeAlias = tuple[
    np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
    np.ndarray, np.ndarray,
]  # fmt: skip
"""The step's state as the world passes it, one array per name of :data:`STEP_STATE`. Its
fixed length lets a type checker count the kernels' arguments after ``*state``."""

TIE_BREAK = 1e-6
"""Relative diagonal term added to the prong rows of D [-] (docs/design.md §3: 1e-6·diag D)."""

SLIP_COS_TOLERANCE = math.cos(math.radians(5.0))
"""A sliding support point whose velocity after a step leaves the slip direction its friction
box was built on by more than 5° gets a corrected box and the step is solved again."""


class ContactModel(NamedTuple):
    """The world's side of the step's kernels, fixed for one world (built once, its arrays
    updated in place): their parameters after :data:`STEP_STATE`, in this order, called as
    ``kernel(*state, *model, ...)``. Arrays are float64 unless said otherwise. Passed
    unpacked: numba types a NamedTuple argument in Python at every call."""

    obj_mass_inv: np.ndarray
    """(3,) (1/m, 1/m, 1/I_z) [1/kg, 1/kg, 1/(kg·m²)]."""
    support_points: np.ndarray
    """(S, 2) the object's support points, object frame [m]."""
    friction_limits: np.ndarray
    """(S,) μ(p_j) N_j at each support point [N] (rewritten in place where a friction field
    makes μ vary over the table)."""
    slip_directions: np.ndarray
    """(S, 2) each support point's friction box direction (unit), world frame; updated in
    place by the kernels (``slip_box``); fixed to the table for the other models, whose
    arrays hold each support point once per row pair (:func:`fixed_rows`)."""
    sliding: np.ndarray
    """(S,) bool: whether each support point slides (its box has no cross bound); always
    False for the fixed models."""
    h: float
    """The (sub)step [s]."""
    stabilisation: float
    """Fraction of a penetration removed per (sub)step, (0, 1]."""
    tie_break: float
    """Relative diagonal term on the prong rows of D [-]."""
    mu_contact: float
    """Prong–object Coulomb friction μ_c."""


class SolvedStep(NamedTuple):
    """A solved (sub)step: new arm velocity (nv,) [rad/s], object velocity (3,) and pose
    (3,) after the step, the forces (k, 2) [N] (normal, tangential) of the k prongs in
    contact, the kept solve's residual, whether it converged and its pivots."""

    v_arm: np.ndarray
    v_obj: np.ndarray
    pose: np.ndarray
    forces: np.ndarray
    residual: float
    converged: bool
    pivots: int


class StepSolver:
    """Solves a world's (sub)steps: owns the friction boxes of the object's support points,
    their bounds (from a friction field, if any) and the previous step's impulses (the next
    warm start); counts its solves in ``stats`` (the world's)."""

    def __init__(
        self,
        obj: ObjectSpec,
        config: WorldConfig,
        friction_field: FrictionField | None,
        stats: WorldStats,
        uniform_limits: np.ndarray,
    ) -> None:
        """``uniform_limits`` (S,) [N]: μ_g N_j at each support point without a field."""
        self.config = config
        self.friction_field = friction_field
        self.stats = stats
        self.pivot_budget = cold_pivot_budget()
        self._bounds_at: tuple[FrictionField, bytes] | None = None
        support_points = np.ascontiguousarray(obj.support_points, dtype=float)
        self._fixed_directions: np.ndarray | None = None
        if config.friction_model != "slip_box":
            support_points, uniform_limits, self._fixed_directions = fixed_rows(
                support_points, uniform_limits, config.friction_model, config.facets
            )
        self._uniform_limits = uniform_limits
        self.model = ContactModel(
            obj_mass_inv=np.array([1.0 / obj.mass, 1.0 / obj.mass, 1.0 / obj.inertia_z]),
            support_points=support_points,
            friction_limits=uniform_limits.copy(),
            slip_directions=np.zeros_like(support_points),
            sliding=np.zeros(len(support_points), dtype=np.bool_),
            h=config.dt / config.substeps,
            stabilisation=config.stabilisation,
            tie_break=TIE_BREAK,
            mu_contact=config.mu_contact,
        )
        self._outputs: dict[int, ArrayRecycler] = {}  # per number of prongs in contact
        self.reset(0.0)

    def reset(self, theta: float) -> None:
        """No warm start; the boxes of an object at rest at heading ``theta`` [rad] (along
        its e_n until a slip direction is seen; the fixed models' stay on the table)."""
        if self._fixed_directions is None:
            self.model.slip_directions[:] = (math.cos(theta), math.sin(theta))
        else:
            self.model.slip_directions[:] = self._fixed_directions
        self.model.sliding[:] = False
        self.last_prongs: tuple[int, ...] | None = None
        self.last_p: np.ndarray | None = None

    def solve(self, state: StepState, prongs: tuple[int, ...]) -> SolvedStep:
        """The (sub)step of ``state`` (the kernels' leading arguments, :data:`STEP_STATE`)
        with ``prongs`` in contact.

        Ground friction is Coulomb's, against each support point's slip velocity *after*
        the step: a first solve with each box aligned with the point's velocity before the
        step, then, where the solved velocity leaves a box's direction by more than 5°, the
        box turned half-way towards it and the step solved again, until they agree. Without
        this a turning object's rotation rate alternated step by step between stuck and
        twice its true value (a lagging box is frictionless across the motion). Not settled
        after ``config.slip_iterations`` re-solves, the step keeps its first solution (the
        one-step-lag model, dissipative whatever the directions)."""
        pose = state[7]
        if self.friction_field is not None:
            self._update_friction_bounds(pose)
        guess = self.last_p if prongs == self.last_prongs else None
        n_rows = 2 * len(prongs) + 2 * len(self.model.support_points)
        outputs = self._take_outputs(state[4].shape[0], len(prongs), n_rows)
        if self._fixed_directions is not None:
            return self._solve_fixed(state, prongs, guess, outputs)
        config = self.config
        status, attempt, solves, warm, worst, iterations, residual, pivots, failed = slip_step(
            *state, *self.model, _NO_GUESS if guess is None else guess, guess is not None,
            DEFAULT_TOL, self.pivot_budget, SLIP_COS_TOLERANCE, config.stick_fraction,
            config.slip_iterations, *outputs,
        )  # fmt: skip
        self._count(solves, warm, worst, iterations)
        converged = True
        if status == NEEDS_PROXQP:
            first = None
            if attempt >= 0:  # the outputs hold the step's first solve
                first = (residual, pivots, *(array.copy() for array in outputs[:3]), True)
            status, residual, converged, pivots = self._with_proxqp(
                state, guess, attempt, failed, first, outputs
            )
        if status == UNSETTLED:  # the step keeps its first solution and its boxes
            slip_state(pose, state[8], self.model.support_points, self.model.slip_directions,
                       self.model.sliding)  # fmt: skip
            self.stats.slip_unsettled += 1
        v_arm, v_obj, forces, last_p, next_pose = outputs
        self.last_prongs, self.last_p = prongs, last_p
        return SolvedStep(v_arm, v_obj, next_pose, forces, residual, converged, pivots)

    def problem(self, state: StepState, prongs: tuple[int, ...]) -> ContactProblem:
        """The MLCP the next (sub)step would solve first, without solving it (the boxes and
        bounds are left as they were)."""
        model = self.model
        if self.friction_field is not None:
            self._update_friction_bounds(state[7])
        if self._fixed_directions is not None:
            return self._problem(state, prongs)
        directions, sliding = model.slip_directions.copy(), model.sliding.copy()
        slip_state(state[7], state[8], model.support_points, model.slip_directions,
                   model.sliding)  # fmt: skip
        problem = self._problem(state, prongs)
        model.slip_directions[:], model.sliding[:] = directions, sliding
        return problem

    def _problem(self, state: StepState, prongs: tuple[int, ...]) -> ContactProblem:
        """The MLCP of ``state`` with the current boxes."""
        if self._fixed_directions is None:
            assembled = assemble(*state, *self.model)
        else:
            assembled = fixed_problem(*state, *self.model, GROUND_COMPLIANCE)
        D, b, lo, hi, findex, mu, v_arm_free, Minv_At_arm, Minv_At_obj, A_arm = assembled
        h = self.model.h
        return ContactProblem(
            h, D, b, lo, hi, findex, mu, prongs, A_arm, v_arm_free, Minv_At_arm, Minv_At_obj
        )

    def _solve_fixed(
        self,
        state: StepState,
        prongs: tuple[int, ...],
        guess: np.ndarray | None,
        outputs: tuple[np.ndarray, ...],
    ) -> SolvedStep:
        """:meth:`solve` for ground friction fixed to the table: one solve, no refinement;
        ProxQP only where the compiled pivoting verifies nothing. When the prongs in contact
        changed, the last ground impulses still start the solve (the prongs' at 0); with
        none, :meth:`_sliding_guess`. The pivots are cheap here (the rows at a bound are
        eliminated): up to one per row from each start before ProxQP."""
        ground = 2 * len(self.model.support_points)
        if guess is None and self.last_p is not None and len(self.last_p) >= ground:
            guess = np.concatenate((np.zeros(2 * len(prongs)), self.last_p[-ground:]))
        elif guess is None:
            guess = self._sliding_guess(state, len(prongs))
        budget = max(self.pivot_budget, ground + 2 * len(prongs))
        status, warm, residual, pivots = fixed_step(
            *state, *self.model, GROUND_COMPLIANCE, _NO_GUESS if guess is None else guess,
            guess is not None, DEFAULT_TOL, budget, *outputs,
        )  # fmt: skip
        converged = True
        if status == NEEDS_PROXQP:
            result, va, vo, f = self._proxqp_solve(state, guess, pivots)
            self._record(result)
            residual, converged, pivots = result.residual, result.converged, result.iterations
            v_arm, v_obj, forces, last_p, next_pose = outputs
            v_arm[:], v_obj[:], forces[:], last_p[:] = va, vo, f, result.p
            next_pose[:] = state[7] + self.model.h * vo
        else:
            self._count(1, warm, residual, 0)
        v_arm, v_obj, forces, last_p, next_pose = outputs
        self.last_prongs, self.last_p = prongs, last_p
        return SolvedStep(v_arm, v_obj, next_pose, forces, residual, converged, pivots)

    def _sliding_guess(self, state: StepState, n_prongs: int) -> np.ndarray:
        """A first guess (m,) of the fixed models' impulses with no earlier step to start
        from: the prongs pressing and sticking, every ground row at the bound that opposes
        a translation at the prongs' mean velocity (at rest without prongs: the object's
        velocity), free where the row is nearly across it. Only its active set is used."""
        velocity = state[4].reshape(-1, 2).mean(axis=0) if n_prongs else state[8][:2]
        directions = self.model.slip_directions
        along = directions @ velocity
        across = directions[:, 1] * velocity[0] * -1.0 + directions[:, 0] * velocity[1]
        speed = float(np.hypot(*velocity))
        rows = np.column_stack((along, across)).reshape(-1)
        bounds = np.repeat(self.model.friction_limits * self.model.h, 2)
        ground = np.where(np.abs(rows) > 1e-3 * speed, -np.sign(rows) * bounds, 0.0)
        prongs = np.tile([1.0, 0.0], n_prongs)
        return np.ascontiguousarray(np.concatenate((prongs, ground)))

    def _with_proxqp(self, state, guess, attempt, failed, first, outputs):
        """Finish a step whose solve at loop index ``attempt`` (−1: the first, from
        ``guess``) verified nothing in ``failed`` pivots: ProxQP solves it and the compiled
        loop resumes, as often as needed. ``first``: the step's first solve (residual,
        pivots, v_arm, v_obj, forces, converged), None if it is the one ProxQP solves.
        Returns the step's (status, residual, converged, pivots)."""
        config, last_p = self.config, outputs[3]
        while True:
            used = guess if attempt < 0 else last_p.copy()
            result, va, vo, f = self._proxqp_solve(state, used, failed)
            self._record(result)
            latest = (result.residual, result.iterations, va, vo, f, result.converged)
            first = latest if first is None else first
            status, attempt, solves, warm, worst, iterations, residual, pivots, failed = (
                resume_step(
                    *state, *self.model, DEFAULT_TOL, self.pivot_budget, SLIP_COS_TOLERANCE,
                    config.stick_fraction, config.slip_iterations, attempt + 1,
                    np.ascontiguousarray(result.p), *latest[:5], *first[:5], *outputs,
                )
            )  # fmt: skip
            self._count(solves, warm, worst, iterations)
            if status != NEEDS_PROXQP:
                break
        if status == UNSETTLED:
            return status, residual, first[5], pivots
        # settled on ProxQP's solve (no solve after it) or on a later, verified one
        return status, residual, latest[5] if solves == 0 else True, pivots

    def _proxqp_solve(self, state: StepState, guess: np.ndarray | None, pivots: int):
        """The step's MLCP with the current boxes by ProxQP and pivoting, after the compiled
        pivoting from ``guess`` (None or empty: none) verified nothing in ``pivots`` pivots:
        (MLCPResult, v_arm, v_obj, forces)."""
        if guess is not None and len(guess) == 0:
            guess = None
        problem = self._problem(state, ())
        threshold = DEFAULT_TOL * max(1.0, float(np.abs(problem.b).max()))
        result = solve_after_pivoting(
            problem.D, problem.b, problem.lo, problem.hi, problem.findex, problem.mu,
            guess, threshold, pivots,
        )  # fmt: skip
        v_arm, v_obj, forces = apply_impulses(
            result.p, problem.v_arm_free, problem.Minv_At_arm, state[8], problem.Minv_At_obj,
            self.model.h,
        )  # fmt: skip
        return result, v_arm, v_obj, forces

    def _count(self, solves: int, warm: int, worst: float, iterations: int) -> None:
        """Add compiled solves to the stats: ``solves`` verified (``warm`` of them warm
        starts, ``worst`` their largest residual) and ``iterations`` re-solves."""
        stats = self.stats
        stats.solves += solves
        stats.warm_starts += warm
        stats.max_residual = max(stats.max_residual, worst)
        stats.slip_iterations += iterations

    def _record(self, result: MLCPResult) -> None:
        """Add a ProxQP solve to the stats."""
        stats = self.stats
        stats.solves += 1
        stats.fallbacks += not result.converged
        stats.warm_starts += result.method == "warm-start"
        stats.max_residual = max(stats.max_residual, result.residual)

    def _take_outputs(self, nv: int, n_prongs: int, n_rows: int) -> tuple[np.ndarray, ...]:
        """Arrays for :func:`slip_step`'s outputs: v_arm (nv,), v_obj (3,), forces
        (n_prongs, 2), the impulses (n_rows,) and the pose (3,), from an
        :class:`~pushctl.contact.recycle.ArrayRecycler` per contact count."""
        recycler = self._outputs.get(n_prongs)
        if recycler is None:
            shapes = ((nv,), (3,), (n_prongs, 2), (n_rows,), (3,))
            recycler = self._outputs[n_prongs] = ArrayRecycler(shapes)
        return recycler.take()

    def _update_friction_bounds(self, pose: np.ndarray) -> None:
        """Each support point's μ(p_j) N_j from the friction field at its table position;
        the warm start's ground impulses (the last 2 S rows) scale with their bounds, so a
        row that slid at its old bound is read as sliding at the new one. Nothing is
        computed where the object has not moved since (the same pose to the bit, the same
        field): most steps of an approach, before the prongs reach the object."""
        field = self.friction_field
        assert field is not None
        key = pose.tobytes()
        at = self._bounds_at
        if at is not None and at[1] == key and at[0] is field:
            return
        self.last_p = field.update_support_bounds(
            pose, self.model.support_points, self._uniform_limits, self.model.friction_limits,
            self.last_p,
        )  # fmt: skip
        self._bounds_at = (field, key)


def fixed_rows(
    support_points: np.ndarray, limits: np.ndarray, model: str, facets: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Support points (S·c, 2), their bounds (S·c,) [N] and row directions (S·c, 2) for a
    friction model fixed to the table: each of the S points ``support_points`` (S, 2) with
    bound ``limits`` (S,) once per row pair (c pairs: a direction and its normal, as the
    slip box's rows). ``axis_box``: one pair along the table's axes at the full bound;
    ``polygon``: facets/4 pairs along kπ/(facets/2), each row at π/facets of the bound."""
    if model == "axis_box":
        pairs, share = 1, 1.0
    else:
        pairs, share = facets // 4, math.pi / facets
    angles = np.arange(pairs) * math.pi / (2 * pairs)
    directions = np.stack((np.cos(angles), np.sin(angles)), 1)
    points = np.ascontiguousarray(np.repeat(support_points, pairs, axis=0))
    bounds = np.repeat(limits * share, pairs)
    return points, bounds, np.ascontiguousarray(np.tile(directions, (len(support_points), 1)))


_NO_GUESS = np.zeros(0)

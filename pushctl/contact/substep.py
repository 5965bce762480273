"""One (sub)step of the world's contact dynamics: the MLCP's inputs, its solve, and the
friction boxes of the ground refined against the solved slip (a mixin of
:class:`~pushctl.contact.world.World`, whose state it reads and advances).

A step whose prongs touched as in the step before is one compiled call
(:func:`~pushctl.contact.cold_step.slip_step`): the previous step's active set, verified,
with the refine-and-re-solve loop, and where that active set fails, the full MLCP and the
rest of the loop (compiled pivoting for each solve). A new contact set starts with the full
MLCP (:func:`~pushctl.contact.cold_step.cold_slip_step`). Only a solve that the pivoting
does not verify leaves the compiled code: the step is then made in parts, ProxQP solves that
problem and the loop continues in Python (:meth:`SubstepSolver._settle_slip`). Every path
makes the same calls in the same order, so the same bits.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from pushctl.arm import ArmModel, ArmTerms
from pushctl.contact.cold_step import (
    COLD_SETTLED,
    COLD_UNSETTLED,
    FROM_WARM,
    HELD,
    PIVOTED,
    STEP_UNSETTLED,
    STEP_UNVERIFIED,
    UNVERIFIED,
    cold_contact_step,
    cold_slip_step,
    slip_step,
)
from pushctl.contact.direct_calls import entry_point
from pushctl.contact.ground_field import FrictionField
from pushctl.contact.kernels import (
    SLIP_SETTLED,
    SLIP_UNSETTLED,
    SLIP_WARM_FAILED,
    apply_impulses,
    assemble,
    refine_slip,
    slip_state,
    warm_slip_step,
)
from pushctl.contact.mlcp import (
    DEFAULT_TOL,
    MLCPResult,
    cold_pivot_budget,
    solve_after_pivoting,
)
from pushctl.contact.recycle import ArrayRecycler
from pushctl.contact.rows import PRONG_ROWS
from pushctl.types import ContactProblem, WorldStats

STEP_STATE = (
    "contacts", "jacobians", "M", "nle", "v_arm", "tau", "joint_damping", "pose", "velocity"
)  # fmt: skip
"""The leading parameters of the step's kernels (:func:`~pushctl.contact.kernels.assemble`,
``warm_contact_step``, ``warm_slip_step``): the state of one step, which changes every step
(shapes and units in ``assemble``). The world passes them as a plain tuple in this order,
then its :class:`ContactModel` (tests/contact/test_rows_compiled.py checks both against the
kernels' signatures)."""


class ContactModel(NamedTuple):
    """The world's side of the step's kernels, fixed for one world (built once, its arrays
    updated in place): their parameters after :data:`STEP_STATE`, in this order; the world
    calls them as ``kernel(*state, *model, ...)``. Arrays are float64 unless said otherwise.

    Not one structure passed into the compiled code: numba dispatches a NamedTuple argument
    through Python-level typing (about 2.3 µs more per call than flat arrays and floats,
    measured), a structref or jitclass argument defeats its disk cache, and building a
    NamedTuple of the step's state every step would cost about 1 µs (3 % of a world step,
    measured with ``python -m pushctl.bench.compare``): unpacked, the names cost nothing.
    """

    obj_mass_inv: np.ndarray
    """(3,) (1/m, 1/m, 1/I_z) [1/kg, 1/kg, 1/(kg·m²)]."""
    support_points: np.ndarray
    """(S, 2) the object's support points, object frame [m]."""
    friction_limits: np.ndarray
    """(S,) μ(p_j) N_j at each support point [N] (rewritten in place where a friction field
    makes μ vary over the table)."""
    slip_directions: np.ndarray
    """(S, 2) each support point's friction box direction (unit), world frame; updated in
    place by :func:`~pushctl.contact.kernels.slip_state` and
    :func:`~pushctl.contact.kernels.refine_slip`."""
    sliding: np.ndarray
    """(S,) bool: whether each support point slides (its box has no cross bound); updated
    in place with ``slip_directions``."""
    h: float
    """The (sub)step [s]."""
    stabilisation: float
    """Fraction of a penetration removed per (sub)step, (0, 1]."""
    tie_break: float
    """Relative diagonal term on the prong rows of D [-]."""
    mu_contact: float
    """Prong–object Coulomb friction μ_c."""


TIE_BREAK = 1e-6
"""Relative diagonal term added to the prong rows of D [-] (docs/design.md §3: 1e-6·diag D)."""

SLIP_COS_TOLERANCE = math.cos(math.radians(5.0))
"""A sliding support point whose velocity after a step leaves the slip direction its friction
box was built on by more than 5° gets a corrected box and the step is solved again."""

MAX_SLIP_ITERATIONS = 6
"""Re-solves of one step for its friction directions (``WorldConfig.slip_iterations``'s
default). If they have not settled by then, the step keeps its first solution (the boxes
aligned with the velocity before the step)."""

STICK_FRACTION = 1.0 - 1e-6
"""The stick rule's threshold as measured (``WorldConfig.stick_fraction``, off by default): a
moving sliding point whose along-row friction impulse is below this fraction of its bound is
not at its bound, so not sliding."""

_NO_CONTACTS = np.zeros((0, 5))
_NO_GUESS = np.zeros(0)  # the guess argument of cold_contact_step without one
_NO_FIRST = (False, 0.0, np.zeros(0), np.zeros(0), np.zeros((0, 2)))  # cold_slip_step: none
_PIVOT_BUDGET = cold_pivot_budget()
_METHODS = {HELD: "warm-start", FROM_WARM: "warm-start", PIVOTED: "active-set"}
_NO_JACOBIANS = np.zeros((0, 3, 0))
_NO_ARM_MATRIX = np.zeros((0, 0))


class SubstepSolver:
    """The (sub)step's MLCP for :class:`~pushctl.contact.world.World` (the attributes below
    are the world's)."""

    arm: ArmModel | None
    config: Any  # WorldConfig (not imported: world.py imports this module)
    stats: WorldStats
    friction_field: FrictionField | None
    object_pose: np.ndarray
    object_velocity: np.ndarray
    v: np.ndarray
    _terms: ArmTerms | None
    _prongs: tuple[int, ...]
    _contacts: np.ndarray
    _n_prongs: int
    _nv: int
    _M_obj_inv: np.ndarray
    _support_points: np.ndarray
    _friction_limits: np.ndarray
    _uniform_limits: np.ndarray
    _slip_directions: np.ndarray
    _sliding: np.ndarray
    _model: ContactModel
    _last_prongs: tuple[int, ...] | None
    _last_p: np.ndarray | None
    _bounds_at: tuple[FrictionField, bytes] | None
    _step_recyclers: dict[int, ArrayRecycler]
    _slip_call: Callable[..., Any] | None  # slip_step's entry point, once resolved

    def _advance_object(self, v_obj: np.ndarray, h: float) -> None: ...
    def _advance_arm(self, v_arm: np.ndarray, h: float) -> None: ...
    def _find_contacts(self) -> None: ...

    def _start_slip_state(self) -> None:
        """Friction boxes for the next step, from the object's velocity (see :meth:`_substep`),
        and their bounds from the friction field at the support points' table positions."""
        if self.friction_field is not None:
            self._update_friction_bounds()
        self._restore_slip_boxes()

    def _keep_first_solution(self) -> None:
        """A step that did not settle keeps its first solution: its boxes again
        (:meth:`_restore_slip_boxes`), counted in ``stats.slip_unsettled``."""
        self._restore_slip_boxes()
        self.stats.slip_unsettled += 1

    def _restore_slip_boxes(self) -> None:
        """The friction boxes from the object's velocity before the step, for a step that
        keeps its first solution: the object has not moved yet, so the bounds
        :meth:`_substep` took from the friction field at this pose stand (computing them
        again gave the same limits and scaled the warm start by exactly 1: 11 µs a query
        of a field, on 12–52 % of an acting ``Push-v0`` push's world steps, for nothing)."""
        slip_state(
            self.object_pose,
            self.object_velocity,
            self._support_points,
            self._slip_directions,
            self._sliding,
        )

    def _update_friction_bounds(self) -> None:
        """Each support point's μ(p_j) N_j from the friction field at its table position.
        The warm start's ground impulses (the last 2 S rows) scale with their bounds, so a
        row that slid at its old bound is read as sliding at the new one.

        Nothing is computed where the object has not moved since the bounds were last
        computed (the same pose to the bit, the same field): they would come out the same
        and scale the warm start by exactly 1 (a bound is > 0, and x / x is 1). That is most
        steps of a reset's approach, before the prongs reach the object (2250 of 2560 over
        four resets); the query is 512 cosines, about 6 µs."""
        field = self.friction_field
        assert field is not None
        pose = self.object_pose.tobytes()
        at = self._bounds_at
        if at is not None and at[1] == pose and at[0] is field:
            return
        # in place: the ContactModel holds the limits' array
        self._last_p = field.update_support_bounds(
            self.object_pose,
            self._support_points,
            self._uniform_limits,
            self._friction_limits,
            self._last_p,
        )
        self._bounds_at = (field, pose)

    def _step_inputs(
        self, h: float, tau: np.ndarray, damping: np.ndarray
    ) -> tuple[tuple[int, ...], tuple]:
        """The prongs in contact and the step's state: the kernels' leading arguments in the
        order of :data:`STEP_STATE` (the world's
        :class:`ContactModel` follows them). ``damping`` (nv,)
        [N·m·s/rad]: all joint damping applied implicitly; ``h`` is the model's."""
        terms = self._terms
        prongs: tuple[int, ...]
        if terms is None:
            prongs, contacts, jacobians = (), _NO_CONTACTS, _NO_JACOBIANS
            M, nle = _NO_ARM_MATRIX, self.v
        else:
            prongs, contacts = self._prongs, self._contacts
            jacobians = terms.prong_jacobians
            if len(prongs) < self._n_prongs:  # take with a kept index array: 1.2 µs less
                jacobians = jacobians.take(PRONG_ROWS[prongs], axis=0)  # than a list index
            M, nle = terms.M, terms.nle
        assert h == self._model.h
        # contacts, jacobians, M, nle, v_arm, tau, joint_damping, pose, velocity
        state = (contacts, jacobians, M, nle, self.v, tau, damping, self.object_pose,
                 self.object_velocity)  # fmt: skip
        return prongs, state

    def _build_problem(self, h: float, tau: np.ndarray, damping: np.ndarray) -> ContactProblem:
        """Free velocities and the contact MLCP of one time step of length h."""
        prongs, inputs = self._step_inputs(h, tau, damping)
        assembled = assemble(*inputs, *self._model)  # type: ignore[call-arg]  # numba
        D, b, lo, hi, findex, mu, v_arm_free, Minv_At_arm, Minv_At_obj, A_arm = assembled
        return ContactProblem(
            h, D, b, lo, hi, findex, mu, prongs, A_arm, v_arm_free, Minv_At_arm, Minv_At_obj
        )

    def _substep(self, h: float, tau: np.ndarray, damping: np.ndarray):
        """One MLCP time step of length h. Returns (prong forces (k, 2) [N], the MLCP's
        residual, whether it converged, its iterations).

        Ground friction is Coulomb's, against each support point's slip velocity *after*
        the step. The step is first solved with each point's box aligned with its velocity
        before the step (:func:`slip_state`): a sliding box bounds friction along that
        direction only. Where the solved velocity leaves a box's direction by more than
        5°, the box is turned half-way towards it (:func:`refine_slip`) and the step solved
        again, until the directions agree. Without this a turning object's rotation rate
        alternated step by step between stuck and twice its true value (a lagging box is
        frictionless across the motion). Near stick–slip transitions the iteration may
        not settle within ``config.slip_iterations``: the step then keeps its first solution,
        the one-step-lag model, whose friction is dissipative whatever the directions.
        """
        if self.friction_field is not None:
            self._update_friction_bounds()
        prongs, inputs = self._step_inputs(h, tau, damping)
        guess = self._last_p if prongs == self._last_prongs else None
        solved = None if guess is None else self._compiled_step(inputs, prongs, guess)
        if solved is None:  # a new contact set, or ProxQP's turn: the step in parts
            solved = self._step_in_parts(h, tau, damping, inputs, prongs, guess)
        v_arm, contact_forces, residual, converged, n_iterations = solved
        if len(prongs) == self._n_prongs:
            forces = contact_forces
        else:
            forces = np.zeros((self._n_prongs, 2))
            for row, prong in enumerate(prongs):  # a loop: 1 µs less than a list index
                forces[prong] = contact_forces[row]
        if self.arm is not None:
            self._advance_arm(v_arm, h)  # which also finds the contacts
        else:
            self._find_contacts()
        return forces, residual, converged, n_iterations

    def _compiled_step(
        self, inputs: tuple, prongs: tuple[int, ...], guess: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, float, bool, int] | None:
        """The step from the previous impulses ``guess`` in one compiled call
        (:func:`slip_step`: the warm loop, and the cold loop where a warm solve fails).
        Returns ``(v_arm, contact_forces, residual, converged, iterations)`` with the object
        advanced, or None when a solve needs ProxQP: then only the friction boxes have
        changed, which the step in parts sets again first (:func:`warm_slip_step` begins with
        :func:`slip_state`)."""
        # its outputs, made here (numba's boxing of returned arrays cost more) or taken again
        v_arm, v_obj, contact_forces, last_p, pose = self._step_arrays(len(prongs), guess.size)
        args = (
            *inputs, *self._model, guess, DEFAULT_TOL, SLIP_COS_TOLERANCE,
            self.config.stick_fraction, self.config.slip_iterations, _PIVOT_BUDGET, v_arm, v_obj,
            contact_forces, last_p, pose,
        )  # fmt: skip
        call = self._slip_call or self._resolve("_slip_call", slip_step, args)
        status, solves, warm_starts, residual, iterations, worst, pivots, _ = call(*args)
        if status == STEP_UNVERIFIED:
            return None
        self._count_loop(prongs, last_p, solves, warm_starts, worst, iterations)
        if status == STEP_UNSETTLED:  # the step keeps its first solution and its boxes
            self._keep_first_solution()
        self.object_velocity, self.object_pose = v_obj, pose
        return v_arm, contact_forces, residual, True, pivots

    def _resolve(self, name: str, kernel: Any, args: tuple) -> Callable[..., Any]:
        """``kernel``'s compiled entry point for the types of ``args``
        (:func:`~pushctl.contact.direct_calls.entry_point`), kept as this world's attribute
        ``name``: its later steps call it past numba's dispatcher, with arguments of the same
        types."""
        call = entry_point(kernel, args)
        setattr(self, name, call)
        return call

    def _step_arrays(self, n_prongs: int, n_rows: int) -> tuple[np.ndarray, ...]:
        """Arrays for :func:`slip_step`'s outputs with ``n_prongs`` prongs in contact and
        ``n_rows`` MLCP rows: v_arm (nv,), v_obj (3,), forces (n_prongs, 2), the impulses
        (n_rows,) and the pose (3,), each contact count's from its own
        :class:`~pushctl.contact.recycle.ArrayRecycler`."""
        recycler = self._step_recyclers.get(n_prongs)
        if recycler is None:
            shapes = ((self._nv,), (3,), (n_prongs, 2), (n_rows,), (3,))
            recycler = self._step_recyclers[n_prongs] = ArrayRecycler(shapes)
        return recycler.take()

    def _count_loop(self, prongs, last_p, solves, warm_starts, worst, iterations) -> None:
        """Count a compiled loop's ``solves`` verified solves (``warm_starts`` of them warm,
        ``worst`` their largest residual, ``iterations`` re-solves) in the stats; its latest
        impulses ``last_p`` are the next step's warm start while ``prongs`` touch."""
        stats = self.stats
        stats.solves += solves
        stats.warm_starts += warm_starts
        stats.max_residual = max(stats.max_residual, worst)
        stats.slip_iterations += iterations
        self._last_prongs, self._last_p = prongs, last_p

    def _step_in_parts(
        self,
        h: float,
        tau: np.ndarray,
        damping: np.ndarray,
        inputs: tuple,
        prongs: tuple[int, ...],
        guess: np.ndarray | None,
    ) -> tuple[np.ndarray, np.ndarray, float, bool, int]:
        """:meth:`_compiled_step` as the calls it joins: the warm loop
        (:func:`warm_slip_step`) and then the cold loop (:meth:`_cold_path`), which hands a
        solve that the pivoting does not verify to ProxQP. For a new contact set (``guess``
        None) the cold loop alone. Returns as :meth:`_compiled_step`."""
        start, status = 0, 0
        if guess is None:  # the boxes here; warm_slip_step sets them itself
            slip_state(self.object_pose, self.object_velocity, self._support_points,
                       self._slip_directions, self._sliding)  # fmt: skip
        else:  # the warm loop alone, its outputs made here as in _compiled_step
            empty = np.empty
            v_arm, v_obj = empty(self._nv), empty(3)
            contact_forces, last_p = empty((len(prongs), 2)), empty(guess.size)
            pose = empty(3)
            status, solves, residual, attempt, iterations, worst = warm_slip_step(
                *inputs, *self._model, guess, DEFAULT_TOL, SLIP_COS_TOLERANCE,
                self.config.stick_fraction, self.config.slip_iterations, v_arm, v_obj,
                contact_forces, last_p, pose,
            )  # type: ignore[call-arg]  # fmt: skip  # numba's Dispatcher hides the signature
        if status:
            self._count_loop(prongs, last_p, solves, solves, worst, iterations)
        if status in (SLIP_SETTLED, SLIP_UNSETTLED):
            # Verified warm solves only: no MLCPResult, the pose advanced in the kernel.
            if status == SLIP_UNSETTLED:  # the step keeps its first solution and its boxes
                self._keep_first_solution()
            converged, n_iterations = True, 0
            self.object_velocity, self.object_pose = v_obj, pose
        else:
            if status == SLIP_WARM_FAILED:
                first: tuple | None = (WarmSolve(residual), v_arm, v_obj, contact_forces)
                self.stats.slip_iterations += 1
                # (the same warm active set fails again in the cold path: no bits change)
                guess, start = last_p, attempt + 1
            else:  # no warm start, or it failed in the call above: the full MLCP
                first = None
            solution = self._cold_path(h, tau, damping, inputs, prongs, guess, first, start)
            result, v_arm, v_obj, contact_forces = solution
            residual, converged, n_iterations = result.residual, result.converged, result.iterations
            self._advance_object(v_obj, h)
        return v_arm, contact_forces, residual, converged, n_iterations

    def _cold_path(self, h, tau, damping, inputs, prongs, guess, first, start: int):
        """The step's full MLCP from ``guess`` (None: none) and the refine-and-re-solve loop
        from loop index ``start``, in one compiled call (:func:`cold_slip_step`: the calls of
        :meth:`_solve_step` and :meth:`_settle_slip` in the same order); only a solve that
        the pivoting does not verify goes to ProxQP, and the loop then goes on in Python.
        ``first``: the warm path's first solution, kept if the loop does not settle (None:
        the first solve here). Returns the step's solution as :meth:`_solve_step` does."""
        has_guess, has_first = guess is not None, first is not None
        first_args = (True, first[0].residual, *first[1:]) if has_first else _NO_FIRST
        (status, attempt, solves, warm_starts, worst, iterations, kept, last_p, used_guess,
         pivots) = cold_slip_step(
            *inputs, *self._model, guess if has_guess else _NO_GUESS, has_guess, DEFAULT_TOL,
            _PIVOT_BUDGET, SLIP_COS_TOLERANCE, self.config.stick_fraction,
            self.config.slip_iterations, start, *first_args,
        )  # type: ignore[call-arg]  # fmt: skip
        if solves:  # none: the first solve verified nothing (no impulses, no re-solves)
            self._count_loop(prongs, last_p, solves, warm_starts, worst, iterations)
        residual, v_arm, v_obj, forces, kept_pivots = kept
        kept_solution = (WarmSolve(residual, True, kept_pivots), v_arm, v_obj, forces)
        if status == COLD_SETTLED:
            return kept_solution
        if status == COLD_UNSETTLED:  # the step keeps its first solution and its boxes
            self._keep_first_solution()
            return kept_solution
        # COLD_UNVERIFIED: the solve at loop index `attempt` goes to ProxQP
        solution = self._proxqp_step(h, tau, damping, used_guess, pivots)
        self._record(solution[0], prongs)
        if not has_first:  # the first solve is the step's first solution
            first = solution if attempt < start else kept_solution
        return self._settle_slip(h, tau, damping, inputs, prongs, first, solution, attempt + 1)

    def _cold_path_in_python(self, h, tau, damping, inputs, prongs, guess, first, start: int):
        """:meth:`_cold_path` as the Python loop it compiles, one :meth:`_solve_step` (one
        :func:`cold_contact_step` call) per solve: the reference the tests compare it with,
        and what ``python -m pushctl.bench.compare`` runs to record the cold problems."""
        solution = self._solve_step(h, tau, damping, inputs, guess)
        self._record(solution[0], prongs)
        first = solution if first is None else first
        return self._settle_slip(h, tau, damping, inputs, prongs, first, solution, start)

    def _settle_slip(self, h, tau, damping, inputs, prongs, first, solution, start: int):
        """The refine-and-re-solve loop of :meth:`_substep` from loop index ``start``, in
        Python (a solve on it needed the full MLCP): returns the step's solution."""
        max_iterations = self.config.slip_iterations
        for attempt in range(start, max_iterations + 1):
            if not refine_slip(
                self.object_pose, solution[2], self._support_points, self._slip_directions,
                self._sliding, SLIP_COS_TOLERANCE, solution[0].p, self._friction_limits, h,
                self.config.stick_fraction,
            ):  # fmt: skip
                break
            if attempt == max_iterations:  # not settled: keep the first solution
                solution = first
                self._keep_first_solution()  # (the velocity is still the old one)
                break
            self.stats.slip_iterations += 1
            solution = self._solve_step(h, tau, damping, inputs, solution[0].p)
            self._record(solution[0], prongs)
        return solution

    def _solve_step(self, h: float, tau: np.ndarray, damping: np.ndarray, inputs, guess):
        """The step's MLCP with the current friction boxes: (MLCPResult, v_arm (nv,), v_obj (3,),
        forces (p, 2) of the prongs in contact). ``inputs``: :meth:`_step_inputs`' (they hold
        the box arrays, which :func:`refine_slip` changes in place). While the same prongs
        touch, the previous impulses' active set (``guess``) usually still holds; otherwise
        the compiled pivoting from it and two fixed starts solves the step, both in one
        compiled call (:func:`~pushctl.contact.cold_step.cold_contact_step`: the calls of
        :func:`solve_box_mlcp`, so its bits); ProxQP (:func:`solve_after_pivoting`) only when
        the pivoting verifies nothing."""
        has_guess = guess is not None
        how, p, w, residual, pivots, v_arm, v_obj, contact_forces = cold_contact_step(
            *inputs, *self._model, guess if has_guess else _NO_GUESS, has_guess, DEFAULT_TOL,
            _PIVOT_BUDGET,
        )  # type: ignore[call-arg]  # fmt: skip  # numba's Dispatcher hides the signature
        if how != UNVERIFIED:
            method = _METHODS.get(how, "warm-start" if has_guess else "proxqp+active-set")
            result = MLCPResult(p, w, float(residual), pivots, True, method)
            return result, v_arm, v_obj, contact_forces
        return self._proxqp_step(h, tau, damping, guess, pivots)

    def _proxqp_step(self, h: float, tau: np.ndarray, damping: np.ndarray, guess, pivots: int):
        """The step's MLCP by ProxQP and pivoting (:func:`solve_after_pivoting`), after the
        compiled pivoting from ``guess`` (None or empty: none) verified nothing in
        ``pivots`` pivots: (MLCPResult, v_arm, v_obj, forces) as :meth:`_solve_step`."""
        if guess is not None and len(guess) == 0:
            guess = None
        problem = self._build_problem(h, tau, damping)
        threshold = DEFAULT_TOL * max(1.0, float(np.abs(problem.b).max()))
        result = solve_after_pivoting(
            problem.D, problem.b, problem.lo, problem.hi, problem.findex, problem.mu,
            guess, threshold, pivots,
        )  # fmt: skip
        v_arm, v_obj, contact_forces = apply_impulses(
            result.p, problem.v_arm_free, problem.Minv_At_arm, self.object_velocity,
            problem.Minv_At_obj, h,
        )  # fmt: skip
        return result, v_arm, v_obj, contact_forces

    def _record(self, result: MLCPResult, prongs: tuple[int, ...]) -> None:
        stats = self.stats
        stats.solves += 1
        stats.fallbacks += not result.converged
        stats.warm_starts += result.method == "warm-start"
        stats.max_residual = max(stats.max_residual, result.residual)
        # contiguous, as every guess the step's kernels are called with (direct_calls)
        self._last_prongs, self._last_p = prongs, np.ascontiguousarray(result.p)


class WarmSolve(NamedTuple):
    """What the step reads of a verified compiled warm solve it may keep (its impulses are
    not written by :func:`warm_slip_step`): the fields of an :class:`MLCPResult` that
    :meth:`SubstepSolver._substep` reads."""

    residual: float
    converged: bool = True
    iterations: int = 0

"""The fixed friction models' MLCP solved in the object's velocity space
(:mod:`pushctl.contact.compiled.object_space`) against the dense solve of the same problem:
the same impulses to round-off, from a cold and from a warm start, with one prong or two,
and every solve of a replayed push verified without the dense path."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pushctl.contact import solve_box_mlcp
from pushctl.contact.compiled.assembly import arm_part, rows_on
from pushctl.contact.compiled.object_space import (
    MAX_ITERATIONS,
    row_diagonals,
    solve_object_space,
)
from pushctl.contact.compiled.step import fixed_problem
from pushctl.contact.step_solver import TIE_BREAK, fixed_rows
from pushctl.contact.world_config import GROUND_COMPLIANCE

MASS_INV = np.array([1 / 0.8, 1 / 0.8, 1 / 1.1e-3])


def _state(rng, prongs: int, facets: int):
    """A random step of a 90 mm plate pushed by ``prongs`` prongs on its −x face, with 16
    support points of the ``facets``-gon: the kernels' arguments."""
    support = rng.uniform(-0.045, 0.045, size=(16, 2))
    limits = np.full(16, 0.8 * 9.81 * 0.4 / 16)
    points, bounds, directions = fixed_rows(support, limits, "polygon", facets)
    contacts = np.zeros((prongs, 5))
    for k in range(prongs):
        contacts[k] = (rng.uniform(-1e-4, 1e-4), 1.0, 0.0, -0.045, rng.uniform(-0.04, 0.04))
    speed = rng.uniform(0.005, 0.02)
    heading = rng.uniform(-0.3, 0.3)
    v_prongs = np.tile([speed * math.cos(heading), speed * math.sin(heading)], prongs)
    pose = np.array([0.0, 0.0, rng.uniform(-1, 1)])
    velocity = rng.normal(scale=(0.005, 0.005, 0.1))
    return contacts, v_prongs, pose, velocity, points, bounds, np.ascontiguousarray(directions)


def _both(state, guess):
    contacts, v_prongs, pose, velocity, points, bounds, directions = state
    h, mu = 0.1, 0.3
    sliding = np.zeros(len(points), dtype=np.bool_)
    empty, jac = np.zeros((0, 0)), np.zeros((len(contacts), 3, 0))
    zero = np.zeros(0)
    args = (contacts, jac, empty, zero, v_prongs, zero, zero, pose, velocity, MASS_INV,
            points, bounds, directions, sliding, h, 0.3, TIE_BREAK, mu)  # fmt: skip
    D, b, lo, hi, findex, mus = fixed_problem(*args, GROUND_COMPLIANCE)[:6]
    dense = solve_box_mlcp(D, b, lo, hi, findex, mus, warm_start=guess(len(b)), validate=False)
    arm = arm_part(*args[:7], h)
    A, b2, lo2, hi2, fx, mu2 = rows_on(arm, contacts, pose, velocity, points, bounds,
                                       directions, sliding, h, 0.3, mu)  # fmt: skip
    n_prong = 2 * len(contacts)
    diag = row_diagonals(A, MASS_INV, arm[3], n_prong, TIE_BREAK, GROUND_COMPLIANCE)
    threshold = 1e-9 * max(1.0, np.abs(b2).max())
    p, residual, verified, _ = solve_object_space(
        n_prong,
        arm[3],
        A,
        b2,
        lo2,
        hi2,
        fx,
        mu2,
        MASS_INV,
        diag,
        guess(len(b)),
        threshold,
        MAX_ITERATIONS,
    )
    return dense, p, residual, verified


@pytest.mark.parametrize("facets", [8, 16, 32])
@pytest.mark.parametrize("prongs", [1, 2])
def test_object_space_matches_the_dense_solve(facets, prongs):
    """From no impulses (harder than a step's start, the last step's impulses) it verifies
    most random steps, and where it verifies it is the dense solution; from the dense
    solution it verifies at once."""
    rng = np.random.default_rng(facets * 10 + prongs)
    verified_cold = 0
    for _ in range(20):
        state = _state(rng, prongs, facets)
        dense, p, _, verified = _both(state, np.zeros)
        assert dense.converged
        scale = max(1.0, np.abs(dense.p).max())
        if verified:
            verified_cold += 1
            assert np.abs(p - dense.p).max() < 1e-9 * scale
        solution = dense.p.copy()
        _, p, _, verified = _both(state, lambda n, solution=solution: solution.copy())
        assert verified and np.abs(p - dense.p).max() < 1e-9 * scale
    assert verified_cold >= 10

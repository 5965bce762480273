"""The compiled hot path against plain-numpy references."""

import math

import numpy as np
import pytest

import pushctl
from pushctl.contact.active_set import labels_at, solve_labels
from pushctl.contact.compiled.assembly import active_set_step
from pushctl.contact.mlcp import _box_problem
from pushctl.contact.mlcp_checks import validated_arrays


def random_mlcp(rng, n_contacts, n_fixed, singular):
    """Box-friction MLCP: n_contacts (normal, friction) pairs, then n_fixed fixed-bound rows."""
    n = 2 * n_contacts + n_fixed
    G = rng.normal(size=(n, n - 2 if singular else n))
    D = G @ G.T + (0.0 if singular else 0.1) * np.eye(n)
    b = rng.normal(size=n)
    lo, hi = np.zeros(n), np.full(n, np.inf)
    findex, mu = np.full(n, -1, dtype=np.int64), np.zeros(n)
    findex[1 : 2 * n_contacts : 2] = np.arange(0, 2 * n_contacts, 2)
    mu[1 : 2 * n_contacts : 2] = rng.uniform(0.1, 1.0, n_contacts)
    bound = rng.uniform(0.1, 1.0, n_fixed)
    lo[2 * n_contacts :], hi[2 * n_contacts :] = -bound, bound
    return D, b, lo, hi, findex, mu


@pytest.mark.parametrize("singular", [False, True])
def test_active_set_kernel_matches_the_numpy_solve(singular):
    rng = np.random.default_rng(11)
    checked = 0
    for _ in range(200):
        args = random_mlcp(rng, int(rng.integers(1, 4)), int(rng.integers(0, 5)), singular)
        D, b, lo, hi, findex, mu = validated_arrays(*args, 1e-9)
        prob = _box_problem(D, b, lo, hi, findex, mu, 1e-9)
        guess = rng.normal(scale=0.5, size=len(b))
        p_kernel, w, residual, _ = active_set_step(D, b, lo, hi, findex, mu, guess, 1e-9)
        p_numpy = solve_labels(prob, labels_at(prob, guess))
        if np.all(np.isfinite(p_numpy)) and np.abs(p_numpy).max() < 1e6:
            np.testing.assert_allclose(p_kernel, p_numpy, rtol=1e-7, atol=1e-9)
            np.testing.assert_allclose(w, D @ p_kernel + b, atol=1e-12)
            checked += 1
    assert checked > 150


def test_kernel_verifies_the_solution_it_is_given():
    rng = np.random.default_rng(5)
    for _ in range(100):
        args = random_mlcp(rng, 2, 4, singular=False)
        solution = pushctl.solve_box_mlcp(*args)
        D, b, lo, hi, findex, mu = validated_arrays(*args, 1e-9)
        p, _, residual, verified = active_set_step(D, b, lo, hi, findex, mu, solution.p, 1e-9)
        assert verified and residual <= 1e-9
        np.testing.assert_allclose(p, solution.p, atol=1e-9)


def test_step_assembly_matches_explicit_matrices():
    """D = A M̃⁻¹ Aᵀ and b = A v_free + bias, with A built here row by row from the geometry."""
    world = pushctl.make_world(object="cube")
    prongs = world.prong_positions()[:, :2]
    rng = np.random.default_rng(2)
    state = world.reset(
        object_pose=(prongs[:, 0].mean() + world.object.face_offset, 0.01, 0.05),
        object_velocity=(0.02, -0.01, 0.1),
        arm_v=rng.normal(scale=0.05, size=7),
    )
    tau, kv, h = rng.normal(size=7), 3.0, world.config.dt
    problem = world.contact_problem(tau, implicit_kv=kv)
    assert problem.prongs == (0, 1)

    terms, spec = world.arm.compute(world.q, world.v), world.object
    x, y, theta = world.object_pose
    c, s = math.cos(theta), math.sin(theta)
    rows = []
    for i in problem.prongs:
        local = np.array([[c, s], [-s, c]]) @ (terms.prong_positions[i, :2] - (x, y))
        _, nx, ny, cx, cy = spec.polygon.query(*local)
        e_n = -np.array([c * nx - s * ny, s * nx + c * ny])
        r = np.array([c * cx - s * cy, s * cx + c * cy])
        for e in (e_n, np.array([-e_n[1], e_n[0]])):
            obj = [e[0], e[1], r[0] * e[1] - r[1] * e[0]]
            rows.append(np.concatenate((-e @ terms.prong_jacobians[i, :2], obj)))
    velocity = world.object_velocity
    for sx, sy in spec.support_points:
        r = np.array([c * sx - s * sy, s * sx + c * sy])
        slip = velocity[:2] + velocity[2] * np.array([-r[1], r[0]])
        d = slip / np.linalg.norm(slip)
        for e in (d, np.array([-d[1], d[0]])):
            rows.append(np.concatenate((np.zeros(7), [e[0], e[1], r[0] * e[1] - r[1] * e[0]])))
    A = np.array(rows)
    M_tilde = np.zeros((10, 10))
    M_tilde[:7, :7] = terms.M + h * kv * np.eye(7)
    M_tilde[7:, 7:] = np.diag([spec.mass, spec.mass, spec.inertia_z])
    D = A @ np.linalg.solve(M_tilde, A.T)
    D[[0, 1, 2, 3], [0, 1, 2, 3]] *= 1 + 1e-6  # the documented tie-break on the prong rows
    v_free = np.concatenate(
        (np.linalg.solve(M_tilde[:7, :7], terms.M @ world.v + h * (tau - terms.nle)), velocity)
    )
    np.testing.assert_allclose(problem.D, D, rtol=1e-9, atol=1e-12)
    gaps = state.prong_gaps
    bias = np.zeros(len(A))
    bias[[0, 2]] = [g / h if g >= 0 else world.config.stabilisation * g / h for g in gaps]
    np.testing.assert_allclose(problem.b, A @ v_free + bias, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(problem.v_arm_free, v_free[:7], rtol=1e-10, atol=1e-13)

"""Worlds with an arm: agreement with Pinocchio, energy, stability of damping, contact."""

import numpy as np
import pytest

import pushctl
from pushctl.config import PusherConfig

FAR_AWAY = (3.0, 3.0, 0.0)  # an object pose no arm can touch


@pytest.fixture(scope="module")
def free_world():
    world = pushctl.make_world(object="cube", arm="kinova-gen2-7dof", damping=[0.0] * 7)
    return world


def random_state(world, rng):
    arm = world.arm
    q = arm.q_ready + rng.uniform(-0.3, 0.3, arm.nq)
    return np.clip(q, arm.q_lower, arm.q_upper), rng.uniform(-0.5, 0.5, arm.nv)


def test_free_arm_step_equals_pinocchio_aba(free_world):
    """Without contact the step's free velocity is v + h·ABA(q, v, τ) to round-off; the step
    returns it unless the energy guard removed a Coriolis surplus, which it only shrinks."""
    world, arm = free_world, free_world.arm
    h = world.config.dt
    rng = np.random.default_rng(7)
    exact = 0
    for _ in range(40):
        q, v = random_state(world, rng)
        tau = rng.uniform(-5, 5, arm.nv)
        world.reset(object_pose=FAR_AWAY, arm_q=q, arm_v=v)
        v_aba = v + h * arm.forward_dynamics(q, v, tau)
        np.testing.assert_allclose(
            world.contact_problem(tau).v_arm_free, v_aba, rtol=1e-10, atol=1e-12
        )
        corrections = world.stats.energy_corrections
        result = world.step(tau)
        np.testing.assert_allclose(result.arm_q, arm.integrate(q, v_aba, h), rtol=0, atol=1e-12)
        if world.stats.energy_corrections == corrections:
            exact += 1
            np.testing.assert_allclose(result.arm_v, v_aba, rtol=1e-10, atol=1e-12)
        else:
            scale = np.linalg.norm(result.arm_v) / np.linalg.norm(v_aba)
            np.testing.assert_allclose(result.arm_v, scale * v_aba, rtol=1e-10, atol=1e-12)
            assert 1 - 5e-3 < scale < 1
    assert exact >= 10


@pytest.mark.parametrize("arm_name", ["kinova-gen2-7dof", "panda"])
def test_unactuated_arm_without_gravity_does_not_gain_energy(arm_name):
    world = pushctl.make_world(arm=arm_name, gravity=0.0, damping=[0.0] * 7)
    arm = world.arm
    rng = np.random.default_rng(3)
    world.reset(object_pose=FAR_AWAY, arm_v=0.5 * rng.normal(size=arm.nv))
    energy0 = arm.kinetic_energy(world.q, world.v)
    energies = []
    for _ in range(300):
        result = world.step(np.zeros(arm.nv))
        energies.append(arm.kinetic_energy(result.arm_q, result.arm_v))
    assert max(energies) <= energy0 * (1 + 1e-12)
    # First-order stepping dissipates ½|Δv|²_M per step: measured 5 % (Kinova) and 11 %
    # (Panda) over these 3 s of fast free motion. More would mean a damping bug.
    assert energies[-1] > 0.8 * energy0


def test_the_energy_ledger_removes_what_explicit_coriolis_terms_create():
    """Without the ledger a fast free arm gains energy (O(h) drift); the ledger removes it."""
    world = pushctl.make_world(gravity=0.0, damping=[0.0] * 7)
    rng = np.random.default_rng(3)
    world.reset(object_pose=FAR_AWAY, arm_v=rng.normal(size=7))  # ~1 rad/s per joint
    energy0 = world.arm.kinetic_energy(world.q, world.v)
    for _ in range(2000):
        world.step(np.zeros(7))
    assert world.stats.energy_removed > 0.05 * energy0  # it had work to do
    assert world.arm.kinetic_energy(world.q, world.v) <= energy0


def _velocity_growth(world, kv, implicit, steps=300):
    """Largest ‖q̇‖ over `steps` of pure joint damping about the ready pose, relative to the
    start (and the final one): > 1 means the damping pumped energy in."""
    nv = world.arm.nv
    v0 = np.full(nv, 1e-3)
    world.reset(object_pose=FAR_AWAY, arm_v=v0)
    norms = []
    for _ in range(steps):
        if implicit:
            result = world.step(np.zeros(nv), implicit_kv=kv)
        else:
            result = world.step(-kv * world.v)
        norms.append(np.linalg.norm(result.arm_v) / np.linalg.norm(v0))
    return max(norms), norms[-1]


@pytest.mark.parametrize("armature", [0.0, 0.02])
def test_explicit_damping_stability_boundary_is_2_lambda_min_over_h(armature):
    """Explicit K_v is stable iff h K_v λ_max(M⁻¹) < 2: the boundary moves with armature."""
    world = pushctl.make_world(gravity=0.0, damping=[0.0] * 7, armature=[armature] * 7)
    M = world.arm.compute(world.arm.q_ready, np.zeros(7)).M
    critical = 2 * np.linalg.eigvalsh(M)[0] / world.config.dt
    assert critical >= 2 * armature / world.config.dt
    peak, final = _velocity_growth(world, 0.8 * critical, implicit=False)
    assert peak < 1.0 and final < 0.9
    peak, _ = _velocity_growth(world, 1.25 * critical, implicit=False)
    assert peak > 100.0


@pytest.mark.parametrize("kv", [0.5, 5.0, 50.0, 200.0])
def test_implicit_damping_is_stable_for_stiff_gains(kv):
    world = pushctl.make_world(gravity=0.0, damping=[0.0] * 7, armature=[0.0] * 7)
    peak, final = _velocity_growth(world, kv, implicit=True)
    assert peak < 1.0 and final < 0.5


def touching_pose(world):
    """Object pose (3,) with its pushed face on the prongs of the ready configuration."""
    prongs = world.prong_positions()
    middle = prongs[:, :2].mean(axis=0)
    return (middle[0] + world.object.face_offset, middle[1], 0.0)


def press(world, push, steps, kp, kv=5.0):
    """Press the prongs on the object with ``push`` (3,) [N] through the prong Jacobians,
    gravity compensated, with a joint spring ``kp`` to the ready pose; yields step results."""
    arm = world.arm
    for _ in range(steps):
        terms = arm.compute(world.q, world.v)
        tau = terms.g + kp * (arm.q_ready - world.q)
        tau += sum(J.T @ push for J in terms.prong_jacobians) / arm.pusher.n_prongs
        yield world.step(tau, implicit_kv=kv)


@pytest.mark.parametrize("object_name", ["cube", "wedge"])
def test_pusher_pressing_a_stuck_object_penetrates_less_than_a_millimetre(object_name):
    world = pushctl.make_world(object=object_name, mu_ground=3.0)  # the object cannot slide
    world.reset(object_pose=touching_pose(world))
    results = list(press(world, np.array([4.0, 0.0, 0.0]), steps=300, kp=30.0))
    assert max(-r.prong_gaps.min() for r in results) < 1e-3
    assert max(r.mlcp_residual for r in results) < 1e-8
    total_normal = [r.contact_forces[:, 0].sum() for r in results]
    assert np.mean(total_normal[-50:]) == pytest.approx(4.0, rel=0.1)  # prongs carry the push


@pytest.mark.parametrize("object_name", ["cube", "wedge"])
def test_pusher_pushing_a_sliding_object_keeps_contact_without_penetration(object_name):
    world = pushctl.make_world(object=object_name, mu_ground=0.3)
    start = touching_pose(world)
    world.reset(object_pose=start)
    friction = 0.3 * world.object.mass * 9.81
    results = list(press(world, np.array([1.5 * friction, 0.0, 0.0]), steps=60, kp=0.0))
    assert max(-r.prong_gaps.min() for r in results) < 1e-3
    assert all(np.all(r.contact_forces[:, 0] > 0.0) for r in results[5:])
    assert results[-1].object_pose[0] - start[0] > 0.005  # it slid forward


def test_prong_forces_stay_in_their_friction_cone():
    world = pushctl.make_world(object="cube", mu_contact=0.2, mu_ground=3.0)
    world.reset(object_pose=touching_pose(world))
    slipped = 0
    # Oblique: asks for more tangential force than μ_c allows, so the prongs slip.
    for result in press(world, np.array([3.0, 1.5, 0.0]), steps=100, kp=30.0):
        normal, tangential = result.contact_forces.T
        assert np.all(normal >= -1e-12)
        assert np.all(np.abs(tangential) <= 0.2 * normal + 1e-9)
        slipped += int(np.any(np.abs(tangential) > 0.2 * normal - 1e-9) and normal.sum() > 0.1)
    assert slipped > 50  # the cone's edge was reached: the test exercised sliding


@pytest.mark.parametrize("arm_name", ["kinova-j2s6s200", "panda"])
def test_other_arms_press_without_penetration(arm_name):
    world = pushctl.make_world(object="cube", arm=arm_name, mu_ground=3.0)
    world.reset(object_pose=touching_pose(world))
    results = list(press(world, np.array([3.0, 0.0, 0.0]), steps=200, kp=30.0))
    assert max(-r.prong_gaps.min() for r in results) < 1e-3
    assert np.mean([r.contact_forces[:, 0].sum() for r in results[-50:]]) == pytest.approx(
        3.0, rel=0.1
    )


@pytest.mark.parametrize("theta_deg", [15.0, 30.0])  # the face turns away from prong 0
def test_prong_beside_a_rotated_corner_touches_the_corner(theta_deg):
    """A prong just outside the corner of a rotated cube is 1 mm from it, not deep behind
    the pushed face's plane: pressing turns the cube instead of kicking it away."""
    world = pushctl.make_world(object="cube", mu_ground=0.3)
    prong = world.prong_positions()[1, :2]
    half, theta = world.object.face_offset, np.radians(theta_deg)
    rotation = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    corner = np.array([-half, half])  # local; the prong sits outside it along the bisector
    bisector = rotation @ np.array([-1.0, 1.0]) / np.sqrt(2)
    centre = prong - 0.001 * bisector - rotation @ corner
    world.reset(object_pose=(centre[0], centre[1], theta))
    assert world.step(world.gravity_torque()).prong_gaps[1] == pytest.approx(0.001, abs=2e-4)
    world.reset(object_pose=(centre[0], centre[1], theta))
    results = list(press(world, np.array([1.5, 0.0, 0.0]), steps=100, kp=0.0))
    assert max(-r.prong_gaps.min() for r in results) < 1e-3
    assert max(np.abs(r.object_velocity[:2]).max() for r in results) < 0.5  # no kick
    assert max(r.contact_forces[1, 0] for r in results) > 0.1  # and the corner was pushed


def test_contact_problem_is_a_well_formed_mlcp():
    world = pushctl.make_world(object="wedge")
    world.reset(object_pose=touching_pose(world))
    problem = world.contact_problem(world.gravity_torque(), implicit_kv=2.0)
    n_support = len(world.object.support_points)
    assert problem.prongs == (0, 1)
    assert problem.D.shape == (4 + 2 * n_support,) * 2
    np.testing.assert_allclose(problem.D, problem.D.T, atol=1e-12)
    assert np.linalg.eigvalsh(problem.D).min() > -1e-10  # A M̃⁻¹ Aᵀ is positive semi-definite
    assert list(problem.findex[:4]) == [-1, 0, -1, 2] and np.all(problem.findex[4:] == -1)
    np.testing.assert_allclose(problem.mu[[1, 3]], world.config.mu_contact)
    solution = pushctl.solve_box_mlcp(
        problem.D, problem.b, problem.lo, problem.hi, problem.findex, problem.mu
    )
    assert solution.converged and solution.residual < 1e-9


@pytest.mark.parametrize(("n_prongs", "spacing"), [(1, 0.0), (3, 0.035), (4, 0.025)])
def test_any_number_of_prongs_shares_the_push(n_prongs, spacing):
    pusher = PusherConfig(mass=0.03, n_prongs=n_prongs, prong_spacing=spacing)
    world = pushctl.make_world(object="cube", mu_ground=3.0, pusher=pusher)
    world.reset(object_pose=touching_pose(world))
    results = list(press(world, np.array([3.0, 0.0, 0.0]), steps=200, kp=30.0))
    normal = np.mean([r.contact_forces[:, 0] for r in results[-50:]], axis=0)
    assert normal.shape == (n_prongs,)
    assert normal.sum() == pytest.approx(3.0, rel=0.1)
    assert np.all(normal > 0.2 * 3.0 / n_prongs)  # every prong takes part
    assert max(-r.prong_gaps.min() for r in results) < 1e-3

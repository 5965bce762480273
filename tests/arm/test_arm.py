"""Arm models: loading, pusher body and frames, ready poses, dynamics terms, validation."""

import numpy as np
import pinocchio as pin
import pytest

from pushctl.arm import ARM_NAMES, ArmConfig, load_arm
from pushctl.arm.ik import IKSettings
from pushctl.arm.specs import ARM_SPECS
from pushctl.config import PusherConfig
from pushctl.errors import ConfigError, StateError

EXPECTED_NV = {"kinova-gen2-7dof": 7, "kinova-j2s6s200": 6, "panda": 7}
READY = {
    "kinova-gen2-7dof": (0.30, 0.0, 0.06),
    "kinova-j2s6s200": (0.30, 0.0, 0.06),
    "panda": (0.35, 0.0, 0.06),
}


@pytest.fixture(scope="module", params=ARM_NAMES)
def arm(request):
    return load_arm(ArmConfig(name=request.param))


@pytest.fixture(scope="module")
def kinova():
    return load_arm(ArmConfig())


def random_states(arm, rng, n):
    """n states (q, v) near the ready pose, inside the limits."""
    for _ in range(n):
        q = np.clip(arm.q_ready + rng.uniform(-0.4, 0.4, arm.nq), arm.q_lower, arm.q_upper)
        yield q, rng.uniform(-1.0, 1.0, arm.nv)


def test_default_arm_is_the_paper_arm():
    assert ArmConfig().name == ARM_NAMES[0] == "kinova-gen2-7dof"


def test_arm_dimensions_and_limits(arm):
    nv = EXPECTED_NV[arm.name]
    assert (arm.nq, arm.nv) == (nv, nv)
    for vector in (arm.armature, arm.damping, arm.torque_limit, arm.velocity_limit):
        assert vector.shape == (nv,) and np.all(np.isfinite(vector)) and np.all(vector >= 0)
    assert np.all(arm.torque_limit > 0) and np.all(arm.velocity_limit > 0)
    assert np.all(arm.q_lower < arm.q_upper) and np.all(np.isfinite(arm.q_lower))
    assert len(arm.prong_frame_ids) == arm.pusher.n_prongs == 2


def test_ready_pose_puts_the_pusher_frame_on_the_world_axes(arm):
    placement = arm.pusher_placement(arm.q_ready)
    assert np.linalg.norm(placement.translation - READY[arm.name]) <= 1e-3
    assert np.linalg.norm(pin.log3(placement.rotation)) <= np.deg2rad(0.5)
    assert np.all(arm.q_ready >= arm.q_lower) and np.all(arm.q_ready <= arm.q_upper)
    assert arm.pusher_condition_number(arm.q_ready) < 20.0


def test_ready_prongs_sit_on_the_face_at_their_offsets(arm):
    terms = arm.compute(arm.q_ready, np.zeros(arm.nv))
    offsets = arm.pusher.prong_offsets()
    expected = np.array(READY[arm.name]) + np.outer(offsets, [0.0, 1.0, 0.0])
    np.testing.assert_allclose(terms.prong_positions, expected, atol=1e-6)


def test_end_effector_holds_the_plate_by_its_top_edge(arm):
    """EE origin: plate thickness/2 behind the front face, height/2 above the prongs."""
    ee = arm.frame_id(ARM_SPECS[arm.name].ee_frame)
    ee_position = arm.frame_placement(arm.q_ready, ee).translation
    offset = ee_position - np.array(READY[arm.name])
    np.testing.assert_allclose(offset, [-0.015, 0.0, 0.024], atol=1e-6)


def test_pusher_mass_is_added_to_the_model_exactly(arm):
    bare = ARM_SPECS[arm.name].build()
    bare_mass = sum(inertia.mass for inertia in bare.inertias)
    assert arm.total_mass() - bare_mass == pytest.approx(arm.pusher.mass, abs=1e-12)
    heavy = load_arm(ArmConfig(name=arm.name, pusher=PusherConfig(mass=0.040)))
    assert heavy.total_mass() - bare_mass == pytest.approx(0.040, abs=1e-12)


def test_pusher_gravity_load_acts_at_the_plate_centre(kinova):
    """g(q) with the pusher − g(q) without it = Jcᵀ m g at the plate's centre."""
    bare = ARM_SPECS[kinova.name].build()
    bare_data = bare.createData()
    plate_centre = pin.SE3(np.eye(3), np.array([-0.015, 0.0, 0.0]))
    for q, _ in random_states(kinova, np.random.default_rng(1), 5):
        jac = kinova.frame_jacobian(q, kinova.pusher_frame_id, pin.LOCAL)
        jac_centre = plate_centre.inverse().toActionMatrix() @ jac  # local axes at the centre
        rotation = kinova.pusher_placement(q).rotation
        weight_local = rotation.T @ np.array([0.0, 0.0, -9.81 * kinova.pusher.mass])
        expected = -jac_centre[:3].T @ weight_local
        delta = kinova.gravity(q) - pin.computeGeneralizedGravity(bare, bare_data, q)
        np.testing.assert_allclose(delta, expected, atol=1e-12)


def test_mass_matrix_symmetric_positive_definite_with_armature(arm):
    no_armature = load_arm(ArmConfig(name=arm.name, armature=(0.0,) * arm.nv))
    for q, v in random_states(arm, np.random.default_rng(2), 10):
        mass = arm.compute(q, v).M
        np.testing.assert_array_equal(mass, mass.T)
        assert np.linalg.eigvalsh(mass).min() > 0
        bare = no_armature.compute(q, v).M
        np.testing.assert_allclose(mass - bare, np.diag(arm.armature), atol=1e-12)


def test_compute_agrees_with_separate_pinocchio_calls(arm):
    model, data = arm.model, arm.model.createData()
    for q, v in random_states(arm, np.random.default_rng(3), 10):
        terms = arm.compute(q, v)
        mass = pin.crba(model, data, q)
        np.testing.assert_allclose(terms.M, np.triu(mass) + np.triu(mass, 1).T, atol=1e-12)
        np.testing.assert_allclose(
            terms.nle, pin.rnea(model, data, q, v, np.zeros(arm.nv)), atol=1e-10
        )
        np.testing.assert_allclose(terms.nle, pin.nonLinearEffects(model, data, q, v), atol=1e-12)
        pin.framesForwardKinematics(model, data, q)
        for i, frame_id in enumerate(arm.prong_frame_ids):
            np.testing.assert_allclose(
                terms.prong_positions[i], data.oMf[frame_id].translation, atol=1e-12
            )
            jac = pin.computeFrameJacobian(model, data, q, frame_id, pin.LOCAL_WORLD_ALIGNED)
            np.testing.assert_allclose(terms.prong_jacobians[i], jac[:3], atol=1e-12)


def test_compute_returns_fresh_arrays(kinova):
    first = kinova.compute(kinova.q_ready, np.zeros(7))
    saved = [array.copy() for array in first]
    kinova.compute(kinova.q_ready + 0.1, np.ones(7))
    for array, copy in zip(first, saved, strict=True):
        np.testing.assert_array_equal(array, copy)


def test_prong_jacobians_match_finite_differences(arm):
    eps = 1e-6
    for q, _ in random_states(arm, np.random.default_rng(4), 3):
        jacobians = arm.compute(q, np.zeros(arm.nv)).prong_jacobians
        for j in range(arm.nv):
            step = np.zeros(arm.nv)
            step[j] = eps
            plus = arm.compute(arm.integrate(q, step, 1.0), np.zeros(arm.nv)).prong_positions
            minus = arm.compute(arm.integrate(q, -step, 1.0), np.zeros(arm.nv)).prong_positions
            np.testing.assert_allclose(jacobians[:, :, j], (plus - minus) / (2 * eps), atol=1e-8)


def test_forward_dynamics_inverts_the_equations_of_motion(arm):
    damped = load_arm(ArmConfig(name=arm.name, damping=(0.5,) * arm.nv))
    rng = np.random.default_rng(5)
    for q, v in random_states(damped, rng, 5):
        tau = rng.uniform(-5.0, 5.0, arm.nv)
        accel = damped.forward_dynamics(q, v, tau)
        terms = damped.compute(q, v)
        np.testing.assert_allclose(terms.M @ accel + terms.nle + 0.5 * v, tau, atol=1e-9)


def test_kinetic_energy_is_half_v_m_v(arm):
    for q, v in random_states(arm, np.random.default_rng(6), 3):
        mass = arm.compute(q, v).M
        assert arm.kinetic_energy(q, v) == pytest.approx(0.5 * v @ mass @ v, rel=1e-12)


def test_integrate_is_explicit_euler_on_angles(arm):
    q, v = arm.q_ready, np.linspace(-1.0, 1.0, arm.nv)
    np.testing.assert_allclose(arm.integrate(q, v, 0.01), q + 0.01 * v, atol=1e-15)


def test_set_gravity_scales_the_gravity_torques():
    arm = load_arm(ArmConfig())
    g_nominal = arm.gravity(arm.q_ready)
    arm.set_gravity(0.0)
    np.testing.assert_allclose(arm.gravity(arm.q_ready), 0.0, atol=1e-15)
    arm.set_gravity(2 * 9.81)
    np.testing.assert_allclose(arm.gravity(arm.q_ready), 2 * g_nominal, rtol=1e-12)
    with pytest.raises(ConfigError):
        arm.set_gravity(float("nan"))


def test_inverse_kinematics_reaches_a_rotated_push_pose_deterministically(kinova):
    target = pin.SE3(pin.utils.rotate("z", np.deg2rad(30.0)), np.array([0.55, 0.08, 0.044]))
    first = kinova.inverse_kinematics(target, kinova.q_ready)
    second = kinova.inverse_kinematics(target, kinova.q_ready)
    assert first.converged and first.position_error < 1e-8 and first.rotation_error < 1e-8
    np.testing.assert_array_equal(first.q, second.q)
    reached = kinova.pusher_placement(first.q)
    np.testing.assert_allclose(reached.translation, target.translation, atol=1e-8)
    assert np.all(first.q >= kinova.q_lower) and np.all(first.q <= kinova.q_upper)


def test_inverse_kinematics_reports_an_unreachable_target(kinova):
    far = pin.SE3(np.eye(3), np.array([2.0, 0.0, 0.06]))
    result = kinova.inverse_kinematics(far, kinova.q_ready, settings=IKSettings(max_iterations=50))
    assert not result.converged and result.position_error > 0.5


def test_defaults_are_documented_values():
    kinova = ArmConfig().resolved_armature()
    np.testing.assert_allclose(kinova, [0.128] * 4 + [0.0512] * 3)
    np.testing.assert_array_equal(ArmConfig().resolved_damping(), np.zeros(7))
    np.testing.assert_allclose(ArmConfig(name="panda").resolved_armature(), [0.1] * 7)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"name": "ur5"},
        {"name": None},
        {"armature": (0.1,) * 6},
        {"armature": (0.1,) * 6 + (-0.1,)},
        {"armature": (0.1,) * 6 + (float("nan"),)},
        {"armature": "heavy"},
        {"damping": (0.0,) * 8},
        {"name": "kinova-j2s6s200", "damping": (0.0,) * 7},
        {"pusher": "plate"},
    ],
)
def test_bad_config_raises_config_error(kwargs):
    with pytest.raises(ConfigError):
        ArmConfig(**kwargs)


def test_unknown_arm_message_lists_the_names():
    with pytest.raises(ConfigError, match="kinova-gen2-7dof, kinova-j2s6s200, panda"):
        ArmConfig(name="ur5")


def test_armature_message_says_what_is_accepted():
    with pytest.raises(ConfigError, match="armature must be 7 finite numbers >= 0"):
        ArmConfig(armature=(0.1,) * 6)


def test_lists_are_accepted_and_stored_as_tuples():
    config = ArmConfig(armature=[0.2] * 7, damping=np.zeros(7))
    assert config.armature == (0.2,) * 7 and config.damping == (0.0,) * 7
    hash(config)


def test_state_checks(kinova):
    np.testing.assert_array_equal(kinova.check_q([0.0] * 7), np.zeros(7))
    with pytest.raises(
        StateError, match=r"^tau must be a finite vector of length 7, got shape \(6,\)$"
    ):
        kinova.check_tau(np.zeros(6))
    with pytest.raises(StateError, match="v must be a finite vector of length 7"):
        kinova.check_v([0.0] * 6 + [float("inf")])
    with pytest.raises(StateError, match="q must be"):
        kinova.check_q("abc")
    with pytest.raises(StateError):
        kinova.check_q(np.zeros((7, 1)))

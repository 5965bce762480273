"""The project's Kinova j2s7s300 URDF against the published figures (docs/kinova-facts.md §1–§7)."""

import importlib.resources

import numpy as np
import pinocchio as pin
import pytest

from pushctl.arm import kinova_urdf
from pushctl.arm.specs import ARM_SPECS

HOME = np.array([4.71, 2.84, 0.00, 0.75, 4.62, 4.48, 4.88])
VERTICAL = np.full(7, 3.1415)
POSE_A = np.array([0.0049, 2.2236, 3.1751, 1.7228, 3.1047, 2.3362, 6.2757])


@pytest.fixture(scope="module")
def kinova():
    """The bare shipped model (no pusher) with its Data and end-effector frame id."""
    model = ARM_SPECS["kinova-gen2-7dof"].build()
    return model, model.createData(), model.getFrameId("j2s7s300_end_effector")


def ee_placement(kinova, q):
    model, data, ee = kinova
    pin.framesForwardKinematics(model, data, q)
    return data.oMf[ee]


def test_shipped_urdf_equals_generator_output():
    shipped = importlib.resources.files("pushctl.arm") / "data" / kinova_urdf.URDF_FILENAME
    assert shipped.read_text(encoding="utf-8") == kinova_urdf.kinova_gen2_7dof_urdf()


def test_dof_limits_and_efforts(kinova):
    model, _, _ = kinova
    assert (model.nq, model.nv) == (7, 7)
    two_pi = 2 * np.pi
    np.testing.assert_allclose(model.lowerPositionLimit[[0, 2, 4, 6]], -two_pi, atol=1e-10)
    np.testing.assert_allclose(model.upperPositionLimit[[1, 3, 5]], [5.462881, 5.759587, 5.148721])
    np.testing.assert_allclose(model.effortLimit, [40, 80, 40, 40, 20, 20, 20])
    np.testing.assert_allclose(model.velocityLimit, [0.628319] * 4 + [0.837758] * 3)


def test_masses_include_the_six_finger_links(kinova):
    model, _, _ = kinova
    masses = [inertia.mass for inertia in model.inertias]  # [0] is the fixed base
    assert sum(masses) == pytest.approx(5.55724, abs=1e-9)
    assert sum(masses[1:]) == pytest.approx(5.08940, abs=1e-9)


def test_lumped_hand_equals_pinocchio_sum_of_bodies():
    """Parallel-axis lumping checked against Pinocchio's own spatial-inertia algebra."""
    hand = kinova_urdf.LINK_INERTIALS[-1]
    total = pin.Inertia(hand.mass, np.array(hand.com, dtype=float), np.diag(hand.diag))
    finger = kinova_urdf.FINGER_LINK
    finger_inertia = pin.Inertia(finger.mass, np.array(finger.com), np.diag(finger.diag))
    for (xyz, rpy), distal in [(b, d) for b in kinova_urdf.FINGER_BASES for d in (False, True)]:
        placement = pin.SE3(pin.rpy.rpyToMatrix(*rpy), np.array(xyz, dtype=float))
        if distal:
            placement = placement * pin.SE3(np.eye(3), np.array(kinova_urdf.DISTAL_XYZ))
        total += placement.act(finger_inertia)
    mass, com, inertia = kinova_urdf.lumped_hand_inertial()
    assert mass == pytest.approx(total.mass, abs=1e-12)
    np.testing.assert_allclose(com, total.lever, atol=1e-12)
    np.testing.assert_allclose(inertia, total.inertia, atol=1e-12)
    assert np.all(np.linalg.eigvalsh(inertia) > 0)


def test_end_effector_at_vertical_and_home(kinova):
    np.testing.assert_allclose(
        ee_placement(kinova, VERTICAL).translation, [0, -0.0130, 1.2603], atol=5e-4
    )
    np.testing.assert_allclose(
        ee_placement(kinova, HOME).translation, [0.2659, -0.2121, 0.5031], atol=5e-4
    )


def test_gravity_torques_at_home_with_fingers(kinova):
    model, data, _ = kinova
    expected = [0, -1.8155, 0.6458, 5.9955, -1.6463, 0.9820, 0.0105]
    np.testing.assert_allclose(
        pin.computeGeneralizedGravity(model, data, HOME), expected, atol=1e-3
    )


def test_jacobian_rank_home_and_vertical(kinova):
    model, data, ee = kinova
    for q, rank in ((HOME, 6), (VERTICAL, 3)):
        jac = pin.computeFrameJacobian(model, data, q, ee, pin.LOCAL_WORLD_ALIGNED)
        assert np.linalg.matrix_rank(jac, tol=1e-3) == rank


def test_pose_a_puts_the_tool_down_at_the_table(kinova):
    model, data, ee = kinova
    placement = ee_placement(kinova, POSE_A)
    np.testing.assert_allclose(placement.translation, [0.55, 0.0, 0.045], atol=1e-3)
    np.testing.assert_allclose(placement.rotation[:, 2], [0, 0, -1], atol=1e-3)
    # and the end-effector y axis is the one along world +x (the pusher's push direction)
    np.testing.assert_allclose(placement.rotation[:, 1], [1, 0, 0], atol=0.1)
    jac = pin.computeFrameJacobian(model, data, POSE_A, ee, pin.LOCAL_WORLD_ALIGNED)
    assert np.linalg.cond(jac) == pytest.approx(10.8, abs=0.1)

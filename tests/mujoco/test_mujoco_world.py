"""The MuJoCo world (pushctl.mujoco): built from the same specs, same interface as ours."""

import math

import mujoco
import numpy as np
import pytest

import pushctl
from pushctl.errors import ConfigError, StateError


@pytest.fixture(scope="module")
def cube_world():
    return pushctl.make_world("cube", engine="mujoco")


def test_mujoco_arm_model_matches_pinocchio_from_the_same_urdf(cube_world):
    """MuJoCo parses the URDF itself: its kinematics, M(q) (armature included) and g(q) must
    agree with Pinocchio's on random configurations, or the two plants are different arms."""
    world, arm = cube_world, cube_world.arm
    rng = np.random.default_rng(5)
    for _ in range(5):
        q = arm.q_ready + rng.normal(0.0, 0.4, arm.nq)
        world.reset(object_pose=(2.0, 0.0, 0.0), arm_q=q)
        terms = arm.compute(q, np.zeros(arm.nv))
        mass = np.zeros((world.model.nv, world.model.nv))
        mujoco.mj_fullM(world.model, world.data, mass)
        assert np.allclose(mass[: arm.nv, : arm.nv], terms.M, atol=1e-10)
        assert np.allclose(world.gravity_torque(), terms.g, atol=1e-9)
        assert np.allclose(world.prong_positions(), terms.prong_positions, atol=1e-12)


def test_mujoco_pusher_carries_the_mounting_error_as_ours_does():
    """A plant unknown: the plate turned on its mount and each prong off its nominal spot.
    Both engines build the same mis-mounted pusher, so MuJoCo's prong points must be ours
    (Pinocchio's frames) on random configurations, and differ from the nominal pusher's."""
    from pushctl.config import PusherConfig

    nominal = PusherConfig(mass=0.03)
    mounted = PusherConfig(
        mass=0.03, mount_yaw=0.03, prong_errors=((0.001, -0.0008), (-0.0005, 0.001))
    )
    ours = pushctl.make_world("cube", pusher=mounted)
    theirs = pushctl.make_world("cube", pusher=mounted, engine="mujoco")
    as_designed = pushctl.make_world("cube", pusher=nominal, engine="mujoco")
    rng = np.random.default_rng(11)
    for _ in range(5):
        q = ours.arm.q_ready + rng.normal(0.0, 0.4, ours.arm.nq)
        expected = ours.arm.compute(q, np.zeros(ours.arm.nv)).prong_positions
        for world in (theirs, as_designed):
            world.reset(object_pose=(2.0, 0.0, 0.0), arm_q=q)
        assert np.allclose(theirs.prong_positions(), expected, atol=1e-12)
        assert np.abs(as_designed.prong_positions() - expected).max() > 5e-4


@pytest.mark.parametrize("name", ["cube", "wedge"])
def test_mujoco_object_mass_properties_match_the_spec(name):
    """MuJoCo computes the object's inertia from its box or mesh and mass: I_z about the
    vertical and the centre of mass's height must be the spec's."""
    world = pushctl.make_world(name, arm=None, engine="mujoco")
    spec, model = world.object, world.model
    body = model.body("object").id
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, model.body_iquat[body])
    rotation = rotation.reshape(3, 3)
    inertia = rotation @ np.diag(model.body_inertia[body]) @ rotation.T
    assert model.body_mass[body] == pytest.approx(spec.mass)
    assert inertia[2, 2] == pytest.approx(spec.inertia_z, rel=1e-6)
    assert model.body_ipos[body] == pytest.approx([0.0, 0.0, spec.com_height], abs=1e-9)


def test_polygon_object_from_toml_is_a_prism(tmp_path):
    path = tmp_path / "hexagon.toml"
    corners = [[0.05 * math.cos(a), 0.05 * math.sin(a)] for a in np.arange(6) * math.pi / 3]
    path.write_text(
        f'name = "hexagon"\nmass = 0.25\nheight = 0.06\nfootprint = {corners}\n',
        encoding="utf-8",
    )
    world = pushctl.make_world(str(path), engine="mujoco")
    body = world.model.body("object").id
    assert world.model.body_mass[body] == pytest.approx(0.25)
    assert world.model.body_ipos[body][2] == pytest.approx(0.03, abs=1e-9)
    result = world.step(world.gravity_torque(), implicit_kv=20.0)
    assert result.contact_forces.shape == (2, 2)


def test_step_result_has_the_shapes_and_types_of_ours(cube_world):
    ours = pushctl.make_world("cube")
    for world in (ours, cube_world):
        world.reset()
        result = world.step(world.gravity_torque(), implicit_kv=20.0)
        assert result.object_pose.shape == (3,)
        assert result.contact_forces.shape == (2, 2)
        assert result.prong_gaps.shape == (2,)
        assert result.arm_q.shape == result.arm_v.shape == (7,)
        assert world.arm_terms is not None and world.arm_terms.M.shape == (7, 7)
    # Arm held by gravity compensation: both engines keep it still to a tenth of a mm.
    drift = np.abs(cube_world.q - cube_world.arm.q_ready).max()
    assert drift < 1e-4


def test_object_rests_on_the_soft_floor_without_creep():
    world = pushctl.make_world("cube", arm=None, engine="mujoco")
    world.reset(object_pose=(0.4, 0.1, 0.3))
    for _ in range(300):
        result = world.step()
    assert np.abs(result.object_pose - (0.4, 0.1, 0.3)).max() < 1e-6
    assert -1e-3 < world.object_height < 0.0  # sunk less than a millimetre


def test_bad_inputs_give_one_line_errors(cube_world):
    with pytest.raises(ConfigError, match="unknown engine"):
        pushctl.make_world("cube", engine="bullet")
    with pytest.raises(ConfigError, match="supports the arm"):
        pushctl.make_world("cube", arm="panda", engine="mujoco")
    with pytest.raises(StateError, match="tau"):
        cube_world.step(np.zeros(3))
    with pytest.raises(StateError, match="implicit_kv"):
        cube_world.step(np.zeros(7), implicit_kv=-1.0)

"""The MuJoCo world's read-out (forces in our frames, gaps, object state) in Python floats is
bit for bit the plain numpy computation it replaced (pushctl/mujoco/world.py, for speed)."""

import math

import mujoco
import numpy as np
import pytest

import pushctl
from pushctl.mujoco import MujocoSettings, MujocoWorld, MujocoWorldConfig


def numpy_geometry(world):
    """Gaps (k,) [m] and inward normals (k, 2) of the prong points, numpy's float64 scalars."""
    data, i = world.data, world._obj_q
    x, y = data.qpos[i : i + 2]
    pose = np.array([x, y, world._theta])
    c, s = math.cos(pose[2]), math.sin(pose[2])
    gaps, normals = np.zeros(world._n_prongs), np.zeros((world._n_prongs, 2))
    for k, site in enumerate(world._prong_sites):
        px, py = data.site_xpos[site][:2] - pose[:2]
        gap, nx, ny, _, _ = world.object.polygon.query(c * px + s * py, -s * px + c * py)
        gaps[k] = gap
        normals[k] = (-(c * nx - s * ny), -(s * nx + c * ny))
    return gaps, normals


def numpy_forces(world, normals):
    """(k, 2) [N] the prongs' forces from the last MuJoCo step's contacts, numpy arrays, as
    the step sums them over its (here one) substeps and divides."""
    data, obj, forces = world.data, world._object_geom, np.zeros((world._n_prongs, 2))
    contacts, wrench = data.contact, np.zeros(6)
    for n in range(data.ncon):
        g1, g2 = int(contacts.geom1[n]), int(contacts.geom2[n])
        if (
            obj not in (g1, g2)
            or (prong := world._prong_geoms.get(g1 if g2 == obj else g2)) is None
        ):
            continue
        if world.model.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC:
            address = int(contacts.efc_address[n])
            local = data.efc_force[address : address + 3]
        else:
            mujoco.mj_contactForce(world.model, data, n, wrench)
            local = wrench[:3]
        force = local @ contacts.frame[n].reshape(3, 3)
        if g1 == obj:
            force = -force
        en_x, en_y = normals[prong]
        forces[prong, 0] += force[0] * en_x + force[1] * en_y
        forces[prong, 1] += -force[0] * en_y + force[1] * en_x
    return (np.zeros_like(forces) + forces) / world.config.substeps


@pytest.mark.parametrize("name, cone", [("cube", "elliptic"), ("wedge", "pyramidal")])
def test_readout_is_the_numpy_computation_bit_for_bit(name, cone):
    """A push with the prongs on the face and turning: each step's forces, gaps, pose and
    velocity have the bytes (signed zeros included) of the numpy computation."""
    base = pushctl.make_world(name, engine="mujoco")
    config = MujocoWorldConfig(mujoco=MujocoSettings(cone=cone))
    world = MujocoWorld(base.object, base.arm, config)
    arm = world.arm
    start = arm.pusher_placement(arm.q_ready).translation
    world.reset(object_pose=(start[0] + world.object.face_offset + 0.002, start[1], 0.0))
    touching = 0
    for n in range(150):
        terms = world.arm_terms
        target = start + [0.0002 * n, 0.003 * math.sin(0.05 * n), 0.0]
        twist = np.concatenate(
            ([0.02, 0.0, 0.0] + 5.0 * (target - terms.pusher_position), [0, 0, 0.3])
        )
        q_dot = np.linalg.lstsq(terms.pusher_jacobian, twist, rcond=1e-4)[0]
        _, normals = numpy_geometry(world)
        result = world.step(terms.g + 20.0 * q_dot, implicit_kv=20.0)
        gaps, _ = numpy_geometry(world)
        j = world._obj_v
        omega = world.data.xmat[world._body].reshape(3, 3) @ world.data.qvel[j + 3 : j + 6]
        velocity = np.array([world.data.qvel[j], world.data.qvel[j + 1], omega[2]])
        assert result.contact_forces.tobytes() == numpy_forces(world, normals).tobytes()
        assert result.prong_gaps.tobytes() == gaps.tobytes()
        assert result.object_velocity.tobytes() == velocity.tobytes()
        assert result.object_pose.tobytes() == world.object_pose.tobytes()
        touching += bool(result.contact_forces.any())
    assert touching > 50  # steps with a prong force

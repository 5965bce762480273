"""The MuJoCo world: the interface of :class:`pushctl.contact.world.World` on MuJoCo's physics.

The plant (arm dynamics, contacts, friction, integration) is MuJoCo's alone: the arm from
the URDF through MuJoCo's parser, soft convex contacts with an elliptic friction cone, the
``implicitfast`` integrator. Per control step of length dt the joint torque ``tau`` is applied
as a generalised force and the controller's ``implicit_kv`` is added to the joints' damping,
which ``implicitfast`` integrates implicitly (the form that keeps a stiff PD stable at
h = 0.01 s, as in our world).

What the controller reads is what a controller on a real arm reads: the joint state (q, q̇)
and the object's pose and velocity. :attr:`MujocoWorld.arm_terms` is the *controller's* model
of the arm (Pinocchio's, from the same URDF) evaluated at MuJoCo's joint state — as on a real
robot, whose controller carries its own model; the tests check MuJoCo's model agrees with it.
Contact forces, gaps and the object's state come from MuJoCo.

Frames as in our world (docs/design.md §2): ``contact_forces`` (k, 2) is each prong's force on the
object (normal along the inward normal of the footprint face nearest the prong point,
tangential along e_z × e_n), averaged over the substeps; ``prong_gaps`` the planar signed
distance of the prong points to the footprint (negative: penetration).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from pushctl.arm import ArmModel, ArmTerms
from pushctl.checks import finite_vector
from pushctl.config import GRAVITY
from pushctl.contact.world import DEFAULT_OBJECT_POSE
from pushctl.errors import ConfigError, StateError
from pushctl.mujoco.scene import (
    FLOOR_GEOM,
    OBJECT_BODY,
    OBJECT_GEOM,
    MujocoSettings,
    build_model,
    prong_geom_name,
    prong_site_name,
)
from pushctl.objects import ObjectSpec
from pushctl.types import StepResult, WorldStats

_BAD_QACC = int(mujoco.mjtWarning.mjWARN_BADQACC)
_mj_step, _mj_kinematics = mujoco.mj_step, mujoco.mj_kinematics
_warnings: list[str] = []


def _keep_warning(text: str) -> None:
    """MuJoCo's warnings are kept here, not printed: the core never prints. A divergence
    becomes a StateError in :meth:`MujocoWorld.step`."""
    _warnings[:] = [str(text).strip()]


mujoco.set_mju_user_warning(_keep_warning)

SETTLE_TIME = 0.5
"""Time [s] the object alone is let settle into its soft floor contact when the world is
built; :meth:`MujocoWorld.reset` then starts the object at that rest height."""


@dataclass(frozen=True)
class MujocoWorldConfig:
    """The parameters of :func:`pushctl.make_world` a MuJoCo world is built with (SI units):
    ``dt`` [s] control step, Coulomb coefficients, gravity [m/s²], and MuJoCo's settings."""

    dt: float = 0.01
    mu_ground: float = 0.3
    mu_contact: float = 0.4
    gravity: float = GRAVITY
    mujoco: MujocoSettings = MujocoSettings()

    def __post_init__(self) -> None:
        if not (math.isfinite(self.dt) and self.dt > 0.0):
            raise ConfigError(f"dt must be a positive number of seconds, got {self.dt!r}")
        for name in ("mu_ground", "mu_contact"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ConfigError(f"{name} must be a finite number >= 0, got {value!r}")
        if not (math.isfinite(self.gravity) and self.gravity >= 0.0):
            raise ConfigError(f"gravity must be a finite number >= 0 m/s², got {self.gravity!r}")

    @property
    def substeps(self) -> int:
        return self.mujoco.substeps


def _yaw(quat: np.ndarray) -> float:
    """Rotation about world z [rad] of a unit quaternion (w, x, y, z)."""
    w, x, y, z = quat.tolist()
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


class MujocoWorld:
    """Arm (optional) + pusher + one object on the table, simulated by MuJoCo. Build it with
    ``pushctl.make_world(..., engine="mujoco")``."""

    engine = "mujoco"

    def __init__(self, obj: ObjectSpec, arm: ArmModel | None, config: MujocoWorldConfig) -> None:
        self.object, self.arm, self.config = obj, arm, config
        self.stats = WorldStats()
        self.model = build_model(
            obj,
            arm,
            dt=config.dt,
            mu_ground=config.mu_ground,
            mu_contact=config.mu_contact,
            gravity=config.gravity,
            settings=config.mujoco,
        )
        self.data = mujoco.MjData(self.model)
        model = self.model
        self._nv = 0 if arm is None else arm.nv
        self._n_prongs = 0 if arm is None else arm.pusher.n_prongs
        joint = model.joint(OBJECT_BODY)
        self._obj_q, self._obj_v = int(joint.qposadr[0]), int(joint.dofadr[0])
        self._body = model.body(OBJECT_BODY).id
        self._object_geom = model.geom(OBJECT_GEOM).id
        self._floor_geom = model.geom(FLOOR_GEOM).id
        self._prong_geoms = {model.geom(prong_geom_name(i)).id: i for i in range(self._n_prongs)}
        self._prong_sites = [model.site(prong_site_name(i)).id for i in range(self._n_prongs)]
        self._damping = np.zeros(self._nv) if arm is None else np.asarray(arm.damping, float)
        self._elliptic = model.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC
        self._substeps = config.mujoco.substeps
        self._no_forces = [0.0] * (2 * self._n_prongs)
        self._wrench = np.zeros(6)
        self._normals = [(0.0, 0.0)] * self._n_prongs  # (e_n x, e_n y) per prong
        self._rest_height = self._settle_height()
        self.reset()

    # ------------------------------------------------------------------ state

    def _settle_height(self) -> float:
        """Height [m] of the object's body origin resting on the soft floor, from a copy of
        the scene without the arm (which, unactuated, would fall meanwhile)."""
        config = self.config
        model = build_model(
            self.object,
            None,
            dt=config.dt,
            mu_ground=config.mu_ground,
            mu_contact=config.mu_contact,
            gravity=config.gravity,
            settings=config.mujoco,
        )
        data = mujoco.MjData(model)
        for _ in range(round(SETTLE_TIME / model.opt.timestep)):
            mujoco.mj_step(model, data)
        return float(data.qpos[2])

    def reset(
        self,
        object_pose=DEFAULT_OBJECT_POSE,
        object_velocity=(0.0, 0.0, 0.0),
        arm_q=None,
        arm_v=None,
    ) -> StepResult:
        """Set the state, as :meth:`pushctl.contact.world.World.reset`: ``object_pose``
        (x [m], y [m], θ [rad]) at rest on the table, ``object_velocity`` (vx, vy, ω),
        ``arm_q=None`` the ready configuration, ``arm_v=None`` rest."""
        pose = finite_vector("object_pose", object_pose, 3)
        velocity = finite_vector("object_velocity", object_velocity, 3)
        model, data = self.model, self.data
        mujoco.mj_resetData(model, data)
        if self.arm is not None:
            q = self.arm.q_ready if arm_q is None else arm_q
            data.qpos[: self._nv] = finite_vector("arm_q", q, self.arm.nq)
            v = np.zeros(self._nv) if arm_v is None else arm_v
            data.qvel[: self._nv] = finite_vector("arm_v", v, self._nv)
        half = 0.5 * pose[2]
        i, j = self._obj_q, self._obj_v
        data.qpos[i : i + 7] = (
            pose[0],
            pose[1],
            self._rest_height,
            math.cos(half),
            0,
            0,
            math.sin(half),
        )
        # Free joint: linear velocity in world axes, angular in the body's (z is z here).
        data.qvel[j : j + 6] = (velocity[0], velocity[1], 0.0, 0.0, 0.0, velocity[2])
        mujoco.mj_forward(model, data)
        self._theta = float(pose[2])  # continuous (unwrapped) heading
        self._terms: ArmTerms | None = None
        return self._result(np.zeros((self._n_prongs, 2)), 0)

    @property
    def q(self) -> np.ndarray:
        """Arm joint angles (nq,) [rad] (a copy)."""
        return self.data.qpos[: self._nv].copy()

    @property
    def v(self) -> np.ndarray:
        """Arm joint velocities (nv,) [rad/s] (a copy)."""
        return self.data.qvel[: self._nv].copy()

    @property
    def object_pose(self) -> np.ndarray:
        """(x [m], y [m], θ [rad]), θ continuous (not wrapped)."""
        x, y = self.data.qpos[self._obj_q : self._obj_q + 2]
        return np.array([x, y, self._theta])

    @property
    def object_velocity(self) -> np.ndarray:
        """(vx, vy [m/s], ω [rad/s]) in the world frame."""
        j = self._obj_v
        omega_world = self.data.xmat[self._body].reshape(3, 3) @ (self.data.qvel[j + 3 : j + 6])
        return np.array([self.data.qvel[j], self.data.qvel[j + 1], omega_world[2]])

    @property
    def object_height(self) -> float:
        """Height [m] of the object's body origin (its footprint's plane): < 0 is sinking."""
        return float(self.data.qpos[self._obj_q + 2])

    @property
    def arm_terms(self) -> ArmTerms | None:
        """The controller's model (Pinocchio) at MuJoCo's joint state, computed when first
        asked for after a step (None without an arm)."""
        if self.arm is None:
            return None
        if self._terms is None:
            self._terms = self.arm.compute(self.q, self.v)
        return self._terms

    def prong_positions(self) -> np.ndarray:
        """World positions [m] of the prong points in MuJoCo's kinematics, (k, 3)."""
        return np.array([self.data.site_xpos[s] for s in self._prong_sites]).reshape(-1, 3)

    def gravity_torque(self) -> np.ndarray:
        """g(q) [N·m] of MuJoCo's model at the current arm state, (nv,)."""
        if self.arm is None:
            return np.zeros(0)
        scratch = mujoco.MjData(self.model)
        scratch.qpos[:] = self.data.qpos
        mujoco.mj_forward(self.model, scratch)  # qvel = 0: the bias is gravity alone
        return scratch.qfrc_bias[: self._nv].copy()

    # ------------------------------------------------------------------- step

    def step(self, tau=None, implicit_kv=None) -> StepResult:
        """Advance one control step dt with joint torques ``tau`` (nv,) [N·m] and the implicit
        damping gain ``implicit_kv`` (scalar or (nv,)) [N·m·s/rad], as our world's step."""
        model, data = self.model, self.data
        if self.arm is not None:
            tau, kv = self._check_command(tau, implicit_kv)
            np.add(self._damping, kv, out=model.dof_damping[: self._nv])
            data.qfrc_applied[: self._nv] = tau
        # The views are taken again every step, never kept on the world: a deep copy of the
        # world copies its MjData, and kept views would still read the original's.
        niter, warning = data.solver_niter, data.warning.number
        n_sub, forces = self._substeps, self._no_forces
        iterations = 0
        previous = _yaw(data.xquat[self._body])
        for _ in range(n_sub):
            _mj_step(model, data)
            iterations += int(niter[0])
            if warning[_BAD_QACC]:
                self._diverged()
            if self._n_prongs:
                # forces += each substep's: the same additions, in the same order, as the
                # arrays' (k, 2) sum, each entry starting from 0.0
                forces = [f + g for f, g in zip(forces, self._prong_forces(), strict=True)]
        _mj_kinematics(model, data)  # positions of the new state (gaps, yaw)
        yaw = _yaw(data.xquat[self._body])
        self._theta += math.remainder(yaw - previous, 2.0 * math.pi)
        self._terms = None
        self.stats.steps += 1
        self.stats.solves += n_sub
        mean = np.array([f / n_sub for f in forces]).reshape(self._n_prongs, 2)
        return self._result(mean, iterations)

    def _diverged(self) -> None:
        """MuJoCo found a NaN or huge acceleration (and reset its state): stop, saying so."""
        self.data.warning[_BAD_QACC].number = 0
        raise StateError(
            f"the MuJoCo simulation diverged at t = {self.data.time:.3f} s "
            f"({_warnings.pop() if _warnings else 'bad acceleration'}); check the torques and gains"
        )

    def _prong_forces(self) -> list[float]:
        """Each prong's force [N] on the object from the contacts of the step just taken,
        along the inward normal e_n of the footprint face nearest the prong point at the
        control step's start (:meth:`_geometry`) and e_t = e_z × e_n: (2k,) as a list,
        prong i's (normal, tangential) at 2i, 2i + 1.

        Python floats throughout (numpy's scalars cost more per operation): the same
        IEEE operations in the same order as on float64, so the same bits. The contact
        frame's rotation stays numpy's ``local @ frame`` (BLAS's own summation)."""
        forces = [0.0] * (2 * self._n_prongs)
        data, obj = self.data, self._object_geom
        contacts = data.contact
        geom1, geom2 = contacts.geom1.tolist(), contacts.geom2.tolist()
        frames = None
        for n, (g1, g2) in enumerate(zip(geom1, geom2, strict=True)):
            if g1 != obj and g2 != obj:
                continue
            prong = self._prong_geoms.get(g1 if g2 == obj else g2)
            if prong is None:  # the floor
                continue
            if frames is None:  # once per call: each of MuJoCo's views is built anew
                # (ncon, 3, 3): a view, each frames[n] the very (3, 3) block, strides and
                # all, that contacts.frame[n].reshape(3, 3) is
                frames = contacts.frame.reshape(-1, 3, 3)
                addresses, efc_force = contacts.efc_address.tolist(), data.efc_force
            if self._elliptic:  # the constraint force is the contact-frame force itself
                address = addresses[n]
                local = efc_force[address : address + 3]
            else:
                mujoco.mj_contactForce(self.model, data, n, self._wrench)
                local = self._wrench[:3]
            # rows n, t1, t2: the force on geom2, world axes
            fx, fy, _ = (local @ frames[n]).tolist()
            if g1 == obj:
                fx, fy = -fx, -fy
            en_x, en_y = self._normals[prong]
            forces[2 * prong] += fx * en_x + fy * en_y
            forces[2 * prong + 1] += -fx * en_y + fy * en_x
        return forces

    def _geometry(self, x: float, y: float) -> np.ndarray:
        """The prong points against the footprint with the object at (x, y) [m] and
        heading θ: their planar signed distances (k,) [m] (returned) and the inward normals
        of the nearest faces, world axes (kept for the next step's forces). Python floats,
        as in :meth:`_prong_forces`."""
        theta = self._theta
        c, s = math.cos(theta), math.sin(theta)
        gaps, normals, query = [], [], self.object.polygon.query
        points = self.data.site_xpos
        for site in self._prong_sites:
            px, py, _ = points[site].tolist()
            px, py = px - x, py - y
            gap, nx, ny, _, _ = query(c * px + s * py, -s * px + c * py)
            gaps.append(gap)
            normals.append((-(c * nx - s * ny), -(s * nx + c * ny)))
        self._normals = normals
        return np.array(gaps, dtype=float)

    def _check_command(self, tau, implicit_kv) -> tuple[np.ndarray, float | np.ndarray]:
        """Validated (tau (nv,), kv: a float for a scalar or None, else (nv,)); StateError
        naming the argument otherwise. A scalar stays one: added to the (nv,) damping it
        gives what the vector of it would."""
        tau = finite_vector("tau", tau, self._nv)
        if implicit_kv is None:
            return tau, 0.0
        if isinstance(implicit_kv, (int, float)):
            if not (math.isfinite(implicit_kv) and implicit_kv >= 0.0):
                raise StateError(
                    f"implicit_kv must be finite and >= 0 N·m·s/rad, got {implicit_kv!r}"
                )
            return tau, float(implicit_kv)
        kv = finite_vector("implicit_kv", implicit_kv, self._nv)
        if kv.min() < 0.0:
            raise StateError(f"implicit_kv must be >= 0 N·m·s/rad, got {kv.tolist()}")
        return tau, kv

    def _result(self, forces: np.ndarray, iterations: int) -> StepResult:
        """The state after a step or reset, every array new (a StepResult's are never
        written into)."""
        data, i, j = self.data, self._obj_q, self._obj_v
        x, y = data.qpos[i : i + 2].tolist()
        qvel = data.qvel
        # Free joint: angular velocity in the body's axes; the world's ω_z as
        # :attr:`object_velocity` computes it (the same product, so the same bits).
        omega_world = data.xmat[self._body].reshape(3, 3) @ (qvel[j + 3 : j + 6])
        vx, vy = qvel[j : j + 2].tolist()
        nv = self._nv
        return StepResult.sharing(
            object_pose=np.array([x, y, self._theta]),
            object_velocity=np.array([vx, vy, omega_world[2]]),
            contact_forces=forces,
            prong_gaps=self._geometry(x, y),
            arm_q=data.qpos[:nv].copy(),
            arm_v=qvel[:nv].copy(),
            mlcp_residual=0.0,
            mlcp_converged=True,
            mlcp_iterations=iterations,
        )

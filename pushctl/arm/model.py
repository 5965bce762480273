"""Arm models: rigid-body dynamics of the arm with its pusher, through Pinocchio.

``load_arm(ArmConfig(...))`` gives an :class:`ArmModel` holding one Pinocchio ``Model`` and
one ``Data``. Its hot path, :meth:`ArmModel.compute`, returns in one call what the
simulator needs every step: the mass matrix M(q) (with joint armature), c(q, v) + g(q) and
the prong points with their Jacobians. Joint damping is kept out of ``nle``: the simulator
treats it implicitly (``M + h·diag(damping)``); :meth:`ArmModel.forward_dynamics` applies
it explicitly.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pinocchio as pin

from pushctl import native
from pushctl.arm.ik import IKResult, IKSettings, solve_frame_ik
from pushctl.arm.pusher import (
    NOMINAL_PUSHER_FRAME,
    add_frame_on_ee,
    attach_pusher,
    placement_ee_to_pusher,
)
from pushctl.arm.specs import ARM_NAMES, ArmSpec, arm_spec, check_spec_model
from pushctl.arm.values import ArmConfig, ArmTerms, PusherFrame, TermArrays
from pushctl.checks import finite_vector
from pushctl.config import GRAVITY
from pushctl.errors import ConfigError
from pushctl.native.arm_kernels import native_terms, native_terms_nominal

__all__ = ["ARM_NAMES", "ArmConfig", "ArmModel", "ArmTerms", "PusherFrame", "load_arm"]


_WORLD_ALIGNED = pin.LOCAL_WORLD_ALIGNED

_jacobian = pin.getFrameJacobian  # hot path: no attribute lookup
_DATA_VIEWS = (
    "_data_M", "_data_nle", "_data_g", "_pusher_placement", "_prong_placements", "_native"
)  # fmt: skip
"""ArmModel's attributes that view its Data or hold the library's copy of the model (made
again, not copied, with the model)."""
_READY_POSES: dict[tuple, IKResult] = {}
"""Ready-pose IK answers by kinematics (:meth:`ArmModel._solve_ready`), oldest first."""
_READY_POSES_KEPT = 64
"""How many of them are kept: a world arm's mounting error is its own, so few repeat."""


def _fills_lower_triangle(model: pin.Model, data: pin.Data) -> bool:
    """Whether crba/computeAllTerms fill all of M: Pinocchio 2 filled only the upper
    triangle (4.1 fills both). Probed once per model at a generic configuration."""
    q = 0.5 * (model.lowerPositionLimit + model.upperPositionLimit) + 0.1
    pin.computeAllTerms(model, data, q, np.zeros(model.nv))
    crba = pin.crba(model, data, q).copy()
    both = np.allclose(data.M, data.M.T) and np.allclose(crba, crba.T)
    return bool(both and np.any(np.tril(crba, -1) != 0.0))


class ArmModel:
    """One arm with its pusher: Pinocchio model, one Data, limits and the ready pose.

    Attributes: ``name``; ``model`` (pin.Model); ``nq``, ``nv``; ``armature`` (nv,)
    [kg·m²]; ``damping`` (nv,) [N·m·s/rad]; ``torque_limit`` (nv,) [N·m];
    ``velocity_limit`` (nv,) [rad/s]; ``q_lower``, ``q_upper`` (nq,) [rad]; ``q_ready``
    (nq,) [rad], solved once at load; ``ready_pusher_position`` (3,) [m] where it puts the
    pusher frame (axes on the world axes); ``ready_ik`` (its IKResult); ``pusher``
    (PusherConfig); ``pusher_frame_id``; ``prong_frame_ids`` (k,);
    ``nominal_pusher_frame_id``: with a mounting yaw, the massless frame where the pusher
    would be without it (:meth:`nominal_pusher`), else None. Not thread-safe: one Data per
    instance.
    """

    def __init__(self, config: ArmConfig) -> None:
        spec = arm_spec(config.name)
        model = spec.build()
        check_spec_model(spec, model)
        model.armature = config.resolved_armature()
        model.damping = config.resolved_damping()
        model.gravity = pin.Motion(np.array([0.0, 0.0, -GRAVITY]), np.zeros(3))
        eeMp = placement_ee_to_pusher(spec.push_axis_ee, spec.tool_axis_ee, config.pusher)
        self.pusher_frame_id, self.prong_frame_ids = attach_pusher(
            model, spec.ee_frame, eeMp, config.pusher
        )
        # A controller that believes the nominal mounting needs that frame every step: one
        # more frame of this model is a placement and a Jacobian from the same pass, where a
        # model of its own would repeat the whole pass (Episode.controller_terms).
        self.nominal_pusher_frame_id: int | None = None
        if config.pusher.mount_yaw != 0.0:
            eeMn = placement_ee_to_pusher(
                spec.push_axis_ee, spec.tool_axis_ee, config.pusher.nominal
            )
            self.nominal_pusher_frame_id = add_frame_on_ee(
                model, spec.ee_frame, eeMn, NOMINAL_PUSHER_FRAME
            )
        self.spec: ArmSpec = spec
        self.name, self.model, self.data = spec.name, model, model.createData()
        self.nq, self.nv = model.nq, model.nv
        self.pusher = config.pusher
        self.armature = model.armature.copy()
        self.damping = model.damping.copy()
        self.torque_limit = model.effortLimit.copy()
        self.velocity_limit = model.velocityLimit.copy()
        self.q_lower = model.lowerPositionLimit.copy()
        self.q_upper = model.upperPositionLimit.copy()
        self._n_prongs = len(self.prong_frame_ids)
        self.prong_frames = np.array(self.prong_frame_ids, dtype=np.int64)
        """The prong frames' indices as an int64 array (k,), for compiled callers."""
        self.nominal_frame = (
            -1 if self.nominal_pusher_frame_id is None else int(self.nominal_pusher_frame_id)
        )
        """``nominal_pusher_frame_id``, −1 for none, for compiled callers."""
        self._nominal_pass: tuple[np.ndarray, PusherFrame] | None = None
        nv, k = self.nv, self._n_prongs
        self.term_shapes = ((nv, nv), (nv,), (nv,), (k, 3), (k, 3, nv), (3,), (3, 3), (6, nv))
        """The shapes of an :class:`ArmTerms`' eight arrays, in its field order: M, nle, g,
        prong positions and Jacobians, pusher position, rotation and Jacobian."""
        self.nominal_shapes = ((3,), (3, 3), (6, nv))
        """The shapes of the nominal pusher frame's position, rotation and Jacobian."""
        self._symmetrise = not _fills_lower_triangle(model, self.data)
        self._bind_views()
        self.ready_ik = self._solve_ready()
        self.q_ready = self.ready_ik.q.copy()
        self.ready_pusher_position = np.array(spec.ready_position)

    def _solve_ready(self) -> IKResult:
        """Ready pose: pusher frame at the spec's ready position, axes = world axes.

        The IK reads only the kinematics (the joints, their limits, the pusher frame's
        placement on its joint), so an arm with the same kinematics gets a copy of the
        answer an earlier one found: a reset builds three arms, two of them with the
        nominal pusher (the plan's and the controller's; only their masses differ), and the
        IK was most of each arm's build."""
        frame = self.model.frames[self.pusher_frame_id]
        key = (
            self.spec.name,
            int(frame.parentJoint),
            frame.placement.homogeneous.tobytes(),
            self.q_lower.tobytes(),
            self.q_upper.tobytes(),
        )
        known = _READY_POSES.get(key)
        if known is not None:
            return replace(known, q=known.q.copy())
        oMdes = pin.SE3(np.eye(3), np.array(self.spec.ready_position))
        seed = _centre_full_turn_joints(np.array(self.spec.seed_q), self.q_lower, self.q_upper)
        result = self.inverse_kinematics(oMdes, seed)
        if not result.converged:
            raise ConfigError(
                f"arm {self.name!r} cannot reach its ready pusher pose "
                f"(error {result.position_error:.2e} m, {result.rotation_error:.2e} rad)"
            )
        if len(_READY_POSES) >= _READY_POSES_KEPT:  # the oldest goes
            del _READY_POSES[next(iter(_READY_POSES))]
        _READY_POSES[key] = replace(result, q=result.q.copy())
        return result

    def _bind_views(self) -> None:
        """Views of Data's fixed-size M, nle and g, which Pinocchio fills in place: each
        attribute access builds a new view, on the hot path.
        Likewise the world placements of the pusher and prong frames (``data.oMf[i]`` is a
        reference into Data): :meth:`compute` reads them after getFrameJacobian updated them,
        without an updateFramePlacement call each."""
        self._data_M, self._data_nle, self._data_g = self.data.M, self.data.nle, self.data.g
        self._pusher_placement = self.data.oMf[self.pusher_frame_id]
        self._prong_placements = [self.data.oMf[frame] for frame in self.prong_frame_ids]
        self._native: native.NativeArm | None | bool = None  # made on first use

    def _native_arm(self) -> native.NativeArm | bool:
        """The library's copy of the model (:mod:`pushctl.native`), or False where the
        library is not in use."""
        if self._native is None:
            available = native.available()
            self._native = native.NativeArm(self.model.saveToString()) if available else False
        return self._native

    def native_handle(self) -> int:
        """The address of the library's copy of this model, for compiled callers that run
        :meth:`compute`'s pass themselves (``World``'s step end); 0 where the library is
        not in use. Such a caller reports a nominal pusher frame it placed with
        :meth:`record_nominal_pass`."""
        arm = self._native if self._native is not None else self._native_arm()
        return arm.handle if arm else 0  # type: ignore[union-attr]

    def record_nominal_pass(self, pusher_jacobian: np.ndarray, nominal: tuple) -> None:
        """What :meth:`nominal_pusher` returns for the terms whose pusher Jacobian is
        ``pusher_jacobian``: the nominal frame's (position, rotation, Jacobian) placed in
        the same pass by a compiled caller (see :meth:`native_handle`)."""
        self._nominal_pass = (pusher_jacobian, PusherFrame(*nominal))

    def __getstate__(self) -> dict:
        """Copies (``copy.deepcopy`` of an episode) rebind the views to their own Data."""
        state = self.__dict__.copy()
        for key in _DATA_VIEWS:
            del state[key]
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._bind_views()

    # ----------------------------------------------------------------- validation
    def check_q(self, q) -> np.ndarray:
        """``q`` as a float array (nq,) [rad]; StateError if it is not nq finite numbers."""
        return finite_vector("q", q, self.nq)

    def check_v(self, v) -> np.ndarray:
        """``v`` as a float array (nv,) [rad/s]; StateError if it is not nv finite numbers."""
        return finite_vector("v", v, self.nv)

    def check_tau(self, tau) -> np.ndarray:
        """``tau`` as a float array (nv,) [N·m]; StateError if it is not nv finite numbers."""
        return finite_vector("tau", tau, self.nv)

    # ----------------------------------------------------------------- dynamics
    def compute(self, q: np.ndarray, v: np.ndarray) -> ArmTerms:
        """M(q), c(q, v) + g(q), g(q), the prong points and the pusher frame with their
        Jacobians, in one pass.

        ``q`` (nq,) [rad], ``v`` (nv,) [rad/s], float64, not validated here (hot path: use
        ``check_q``/``check_v`` at the boundary). One compiled call where pushctl's compiled
        library is built (:mod:`pushctl.native`: the same Pinocchio instances, the same
        bits), else the same calls through Pinocchio's bindings.
        """
        handle = self.native_handle()
        if handle:
            return self._compute_native(handle, q, v)
        model, data = self.model, self.data
        pin.computeAllTerms(model, data, q, v)  # M, nle, joint placements and Jacobians
        # getFrameJacobian also places its frame (data.oMf, the product updateFramePlacement
        # forms): the placements are read from the bound views of data.oMf after it.
        # np.array of the prongs' rows copies them in one call each.
        jacobians = np.array(
            [_jacobian(model, data, frame, _WORLD_ALIGNED)[:3] for frame in self.prong_frame_ids]
        )
        positions = np.array([placement.translation for placement in self._prong_placements])
        # getFrameJacobian returns a fresh array (Eigen by value): no copy needed.
        pusher_jacobian = _jacobian(model, data, self.pusher_frame_id, _WORLD_ALIGNED)
        pusher = self._pusher_placement
        if self.nominal_pusher_frame_id is not None:
            placement = pin.updateFramePlacement(model, data, self.nominal_pusher_frame_id)
            nominal = PusherFrame(
                placement.translation.copy(),
                placement.rotation.copy(),
                pin.getFrameJacobian(model, data, self.nominal_pusher_frame_id, _WORLD_ALIGNED),
            )
            self._nominal_pass = (pusher_jacobian, nominal)
        mass = self._data_M.copy()
        if self._symmetrise:
            mass = np.triu(mass) + np.triu(mass, 1).T
        return ArmTerms(
            mass,
            self._data_nle.copy(),
            self._data_g.copy(),
            positions,
            jacobians,
            pusher.translation.copy(),
            pusher.rotation.copy(),
            pusher_jacobian,
        )

    def _compute_native(self, handle: int, q: np.ndarray, v: np.ndarray) -> ArmTerms:
        """:meth:`compute` through the library: one compiled call into fresh arrays."""
        terms = self.empty_terms()
        frames = (handle, q, v, self.prong_frames, self.pusher_frame_id)
        if self.nominal_frame < 0:
            native_terms(*frames, *terms)
        else:
            nominal = self.empty_nominal()
            native_terms_nominal(*frames, self.nominal_frame, *terms, *nominal)
            self.record_nominal_pass(terms[-1], nominal)
        return ArmTerms(*terms)

    def empty_terms(self) -> TermArrays:
        """Eight new uninitialised arrays (:attr:`term_shapes`) for a compiled pass to write
        an :class:`ArmTerms` into. Made in Python: numba's boxing of returned arrays costs
        more."""
        return tuple(map(np.empty, self.term_shapes))  # type: ignore[return-value]

    def empty_nominal(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """New arrays for the nominal pusher frame a compiled pass writes
        (:attr:`nominal_shapes`)."""
        return tuple(map(np.empty, self.nominal_shapes))  # type: ignore[return-value]

    def nominal_pusher(self, terms: ArmTerms) -> PusherFrame | None:
        """Where the pusher frame would be without the plate's mounting yaw (the nominal
        mounting a controller believes), at the state of ``terms``: computed in the pass of
        :meth:`compute` that returned them if that was this model's last pass (recognised by
        their ``pusher_jacobian``, an array of that pass only), else None; None also on an
        arm without a mounting yaw."""
        last = self._nominal_pass
        return last[1] if last is not None and last[0] is terms.pusher_jacobian else None

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """M(q) (nv, nv) including armature."""
        mass = pin.crba(self.model, self.data, q).copy()
        return np.triu(mass) + np.triu(mass, 1).T if self._symmetrise else mass

    def set_gravity(self, magnitude: float) -> None:
        """Set the magnitude [m/s²] of gravity, along world −z (default 9.81; 0 turns it off)."""
        if not np.isfinite(magnitude) or magnitude < 0.0:
            raise ConfigError(f"gravity must be a finite magnitude >= 0 m/s², got {magnitude!r}")
        self.model.gravity = pin.Motion(np.array([0.0, 0.0, -float(magnitude)]), np.zeros(3))
        self._native = None  # the library's copy is made again from the changed model

    def gravity(self, q: np.ndarray) -> np.ndarray:
        """g(q) (nv,) [N·m]: joint torques that hold the arm and pusher still."""
        return pin.computeGeneralizedGravity(self.model, self.data, q).copy()

    def gravity_as_computed(self, q: np.ndarray) -> np.ndarray:
        """g(q) (nv,) [N·m] to the bit as :meth:`compute` returns it, without the rest of its
        pass (about a third of its time). computeAllTerms forms g as −A_linᵀ·gravity from
        the composite inertias' centroidal map A, which computeCentroidalMap builds by the
        same arithmetic (tested bit for bit); RNEA's :meth:`gravity` differs in the last
        bits."""
        centroidal = pin.computeCentroidalMap(self.model, self.data, q)
        return -(centroidal[:3].T @ self.model.gravity.linear)

    def forward_dynamics(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Joint accelerations (nv,) [rad/s²] under torques ``tau`` (nv,) [N·m]:
        M⁻¹(tau − damping·v − c − g), armature included (ABA), damping explicit."""
        return pin.aba(self.model, self.data, q, v, tau - self.damping * v).copy()

    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> float:
        """½ vᵀ M(q) v [J], armature (rotor kinetic energy) included."""
        return 0.5 * float(v @ self.mass_matrix(q) @ v)

    def integrate(self, q: np.ndarray, v: np.ndarray, dt: float) -> np.ndarray:
        """Configuration (nq,) reached from ``q`` moving at ``v`` (nv,) [rad/s] for ``dt`` [s]."""
        return pin.integrate(self.model, q, v * dt)

    # ----------------------------------------------------------------- kinematics
    def frame_placement(self, q: np.ndarray, frame_id: int) -> pin.SE3:
        """World placement ``oMf`` of frame ``frame_id`` at ``q`` (a copy)."""
        pin.forwardKinematics(self.model, self.data, q)
        return pin.updateFramePlacement(self.model, self.data, frame_id).copy()

    def pusher_placement(self, q: np.ndarray) -> pin.SE3:
        """World placement of the pusher frame (origin at the prongs' midpoint)."""
        return self.frame_placement(q, self.pusher_frame_id)

    def frame_jacobian(
        self, q: np.ndarray, frame_id: int, reference: pin.ReferenceFrame | None = None
    ) -> np.ndarray:
        """Frame Jacobian (6, nv), rows [linear; angular]; default axes LOCAL_WORLD_ALIGNED."""
        reference = pin.LOCAL_WORLD_ALIGNED if reference is None else reference
        return pin.computeFrameJacobian(self.model, self.data, q, frame_id, reference).copy()

    def pusher_jacobian(self, q: np.ndarray) -> np.ndarray:
        """Pusher-frame Jacobian (6, nv) at its origin, world-aligned axes."""
        return self.frame_jacobian(q, self.pusher_frame_id)

    def frame_id(self, name: str) -> int:
        """Index of a named frame; ConfigError if the model has none of that name."""
        if not self.model.existFrame(name):
            raise ConfigError(f"arm {self.name!r} has no frame {name!r}")
        return self.model.getFrameId(name)

    def inverse_kinematics(
        self,
        target: pin.SE3,
        q_seed: np.ndarray,
        frame_id: int | None = None,
        q_posture: np.ndarray | None = None,
        settings: IKSettings | None = None,
    ) -> IKResult:
        """Joint angles putting ``frame_id`` (default: the pusher frame) at world pose
        ``target``; damped least squares from ``q_seed`` within the joint limits."""
        frame_id = self.pusher_frame_id if frame_id is None else frame_id
        return solve_frame_ik(self.model, self.data, frame_id, target, q_seed, q_posture, settings)

    def pusher_condition_number(self, q: np.ndarray) -> float:
        """cond of the pusher Jacobian (6, nv) (world-aligned, m and rad mixed) [-]."""
        return float(np.linalg.cond(self.pusher_jacobian(q)))

    def total_mass(self) -> float:
        """Mass of every body including the fixed base and the pusher [kg]."""
        return math.fsum(inertia.mass for inertia in self.model.inertias)


def _centre_full_turn_joints(q: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """Wrap the angles beyond ±π of joints that may turn ±2π into (−π, π], mid-range.

    docs/kinova-facts.md §7 pose A has q7 = 6.2757 rad, 8 mrad from the +2π limit; the same
    posture with q7 − 2π leaves the joint a full turn of travel either way.
    """
    wrapped = np.mod(q + math.pi, 2.0 * math.pi) - math.pi
    full_turn = (upper - lower) >= 4.0 * math.pi - 1e-6
    return np.where(full_turn & (np.abs(q) > math.pi), wrapped, q)


def load_arm(config: ArmConfig | None = None) -> ArmModel:
    """Build the arm of ``config`` (default: the Kinova Gen2 7-DOF with the default pusher)."""
    return ArmModel(config or ArmConfig())

"""The arm's settings (:class:`ArmConfig`) and the values an :class:`~pushctl.arm.model.
ArmModel` computes for the simulator (:class:`ArmTerms`, :class:`PusherFrame`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from pushctl.arm.specs import arm_spec
from pushctl.config import PusherConfig
from pushctl.errors import ConfigError


def _joint_parameter(name: str, values, nv: int, arm: str) -> tuple[float, ...] | None:
    """Validate an optional per-joint parameter: None, or nv finite numbers >= 0."""
    if values is None:
        return None
    accepted = f"{name} must be {nv} finite numbers >= 0 for arm {arm!r} (or None)"
    try:
        array = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ConfigError(f"{accepted}, got {values!r}") from None
    if array.shape != (nv,) or not np.all(np.isfinite(array)) or np.any(array < 0.0):
        raise ConfigError(f"{accepted}, got {values!r}")
    return tuple(float(x) for x in array)


@dataclass(frozen=True)
class ArmConfig:
    """Which arm to simulate and its joint and pusher parameters.

    ``name``: one of ``ARM_NAMES``. ``armature`` (nv,) [kg·m²] is the reflected rotor inertia
    added to the diagonal of M(q); ``damping`` (nv,) [N·m·s/rad] is viscous joint damping.
    ``None`` selects the arm's documented default (see :mod:`pushctl.arm.specs`: Kinova
    armature = 160²·J_rotor with estimated rotor inertias, 0.128 kg·m² for joints with the
    large actuator and 0.0512 kg·m² for the small one, damping 0; Panda armature 0.1 kg·m²,
    damping 0.003 N·m·s/rad). ``pusher``: the plate fixed to the end effector.
    """

    name: str = "kinova-gen2-7dof"
    armature: tuple[float, ...] | None = None
    damping: tuple[float, ...] | None = None
    pusher: PusherConfig = field(default_factory=PusherConfig)

    def __post_init__(self) -> None:
        spec = arm_spec(self.name)
        for key in ("armature", "damping"):
            value = _joint_parameter(key, getattr(self, key), spec.nv, self.name)
            object.__setattr__(self, key, value)
        if not isinstance(self.pusher, PusherConfig):
            raise ConfigError(f"pusher must be a PusherConfig, got {type(self.pusher).__name__}")

    def resolved_armature(self) -> np.ndarray:
        """Armature (nv,) [kg·m²], with the arm's default filled in."""
        return np.array(self.armature or arm_spec(self.name).armature, dtype=float)

    def resolved_damping(self) -> np.ndarray:
        """Damping (nv,) [N·m·s/rad], with the arm's default filled in."""
        return np.array(self.damping or arm_spec(self.name).damping, dtype=float)


class PusherFrame(NamedTuple):
    """A pusher frame at one state: ``position`` (3,) [m] and ``rotation`` (3, 3) its world
    placement, ``jacobian`` (6, nv) rows [linear; angular], world-aligned axes."""

    position: np.ndarray
    rotation: np.ndarray
    jacobian: np.ndarray


class ArmTerms(NamedTuple):
    """Dynamics and prong kinematics at one state (arrays owned by the caller: a world's
    step never writes into terms a caller holds, :mod:`pushctl.contact.recycle`).

    ``M`` (nv, nv) [kg·m², kg·m, kg] symmetric mass matrix including armature;
    ``nle`` (nv,) [N·m] c(q, v) + g(q), without joint damping;
    ``g`` (nv,) [N·m] g(q) alone;
    ``prong_positions`` (k, 3) [m] prong points in the world frame;
    ``prong_jacobians`` (k, 3, nv) [m/rad] linear-velocity Jacobians of those points,
    world-aligned axes: ``prong_velocity[i] = prong_jacobians[i] @ v``;
    ``pusher_position`` (3,) [m] and ``pusher_rotation`` (3, 3) the pusher frame's world
    placement; ``pusher_jacobian`` (6, nv) its Jacobian, rows [linear; angular], world-aligned
    axes (what the controller needs, computed in the same pass).
    """

    M: np.ndarray
    nle: np.ndarray
    g: np.ndarray
    prong_positions: np.ndarray
    prong_jacobians: np.ndarray
    pusher_position: np.ndarray
    pusher_rotation: np.ndarray
    pusher_jacobian: np.ndarray


TermArrays = tuple[
    np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray
]
"""The eight arrays of an :class:`ArmTerms`, in its field order (:meth:`ArmModel.empty_terms`)."""

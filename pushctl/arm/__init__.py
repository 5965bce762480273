"""Arm models (the only Pinocchio importer): M(q), c(q, v), g(q), prong Jacobians, IK.

``load_arm(ArmConfig(name=...))`` builds one of ``ARM_NAMES`` with the pusher on its end
effector; see :mod:`pushctl.arm.model`.
"""

from pushctl.arm.believed import BelievedTerms
from pushctl.arm.model import ArmConfig, ArmModel, ArmTerms, PusherFrame, load_arm
from pushctl.arm.specs import ARM_NAMES

__all__ = [
    "ARM_NAMES",
    "ArmConfig",
    "ArmModel",
    "ArmTerms",
    "BelievedTerms",
    "PusherFrame",
    "load_arm",
]

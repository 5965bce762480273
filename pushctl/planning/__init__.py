"""Planning: the ICR arc with its angular profiles, the force distribution (eq. 11–13) and
the workspace checks. ``make_plan`` ties them together."""

from pushctl.planning.forces import ForcePlan, ForceSettings, distribute_forces, required_wrench
from pushctl.planning.plan import Plan, make_plan
from pushctl.planning.profiles import PROFILE_NAMES, AngularProfile, make_profile
from pushctl.planning.trajectory import Trajectory, instant_centre, plan_icr
from pushctl.planning.workspace import default_start

__all__ = [
    "PROFILE_NAMES",
    "AngularProfile",
    "ForcePlan",
    "ForceSettings",
    "Plan",
    "Trajectory",
    "default_start",
    "distribute_forces",
    "instant_centre",
    "make_plan",
    "make_profile",
    "plan_icr",
    "required_wrench",
]

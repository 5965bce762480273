"""Control: the PD baseline (operational-space IK + joint PD, docs/design.md §5) and its
references."""

from pushctl.control.gains import DEFAULT_GAINS_FILE, PDGains, load_gains
from pushctl.control.pd import PDCommand, PDController
from pushctl.control.reference import PusherReference, minimum_jerk, push_reference

__all__ = [
    "DEFAULT_GAINS_FILE",
    "PDCommand",
    "PDController",
    "PDGains",
    "PusherReference",
    "load_gains",
    "minimum_jerk",
    "push_reference",
]

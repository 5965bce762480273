"""A toy controller, registered in this one module and nowhere else: PD-only plus a
constant-zero residual, sent through the environment's gate and residual path like a
policy's action. Importing the module registers it (tests remove it again)."""

from __future__ import annotations

import numpy as np

from pushctl.controllers import ControllerRun, PushSetup, Start, register_controller
from pushctl.controllers.drive import push_with_actor

NAME = "toy"


@register_controller(
    NAME, label="toy (zero residual)", colour="#8c564b", summary="PD + a zero residual"
)
class ZeroResidual:
    """Pushes in a copy of the start's environment with an actor that always says 0."""

    def __init__(self, setup: PushSetup) -> None:
        del setup  # nothing to build: no gains, no policy

    def push(self, start: Start) -> tuple[ControllerRun, ...]:
        return (push_with_actor(start.environment(), lambda observation: np.zeros(3)),)

"""``rl``: PD plus a learned residual policy (docs/design.md §6), its actor deterministic;
the policy file keeps the environment settings it was trained with."""

from __future__ import annotations

from dataclasses import replace

from pushctl.controllers.base import ControllerRun, PushSetup, Start, register_controller
from pushctl.errors import ConfigError


@register_controller(
    "rl",
    label="RL-assisted",
    colour="#d62728",
    width=1.2,
    summary="PD + policy",
    needs_policy=True,
    any_pusher=False,
    paper=True,
)
class PolicyController:
    """Each of the setup's policies pushes in the start's environment (the policy's
    settings: the evaluation builds the start from them), from its own copy but the last,
    and adds its own run, named by its training seed."""

    def __init__(self, setup: PushSetup) -> None:
        if not setup.policies:
            raise ConfigError("RL-assisted trials need a policy")
        self.policies = setup.policies

    def push(self, start: Start) -> tuple[ControllerRun, ...]:
        from pushctl.controllers.drive import push_with_actor

        last = len(self.policies) - 1
        return tuple(
            replace(push_with_actor(start.environment(k == last), actor), policy_seed=seed)
            for k, (actor, seed) in enumerate(self.policies)
        )

"""The one driver: registered controllers push a scenario's episode, in turn, from one reset.

``pushctl simulate`` (:func:`push_scenario`: one controller, one scenario) and ``pushctl
evaluate`` (:func:`pushctl.evaluation.trials.run_trial`: the trial's controllers, paired)
both call :func:`push_controllers`. Every controller starts from the end of the same
approach (the reset's), so paired pushes share the plan, the plant and, on the proxy, the
camera's noise.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from pushctl.controllers.base import (
    Controller,
    ControllerRun,
    PushSetup,
    Start,
    controller_entry,
)

if TYPE_CHECKING:
    from pushctl.episode.scenario import Scenario
    from pushctl.episode.trace import Trace
    from pushctl.planning import Plan
    from pushctl.task.env import PushEnv

__all__ = ["build_controllers", "push_controllers", "push_scenario", "push_with_actor", "reset"]


def build_controllers(names: tuple[str, ...], setup: PushSetup) -> dict[str, Controller]:
    """The registered controllers ``names``, each built once from ``setup``."""
    return {name: controller_entry(name).factory(setup) for name in names}


def reset(env: PushEnv, options: Mapping[str, Any]) -> Start:
    """Reset ``env`` with ``options`` (:data:`pushctl.task.env.RESET_OPTIONS`): the start
    every controller of a trial pushes from."""
    _, info = env.reset(options=dict(options))
    return Start(env, options, int(info["goals_redrawn"]))


def push_controllers(
    controllers: Mapping[str, Controller], start: Start
) -> dict[str, tuple[ControllerRun, ...]]:
    """Each of ``controllers`` pushes ``start``'s scenario, in the order given; the last
    may push in ``start``'s own environment (:meth:`Start.environment`), so ``start.env``
    is spent afterwards. Each controller's runs (one per policy for a policy's)."""
    runs: dict[str, tuple[ControllerRun, ...]] = {}
    names = list(controllers)
    for i, name in enumerate(names):
        if i == len(names) - 1:
            start.hand_over()
        runs[name] = tuple(controllers[name].push(start))
    return runs


def push_with_actor(env: PushEnv, actor: Callable[[np.ndarray], np.ndarray]) -> ControllerRun:
    """The push of the episode ``env`` was just reset to, with the deterministic ``actor``
    (observation → action in [−1, 1]³: a policy, the feedback law) through the
    environment's gate, action scale and residual path; the share of its steps the gate
    was open."""
    from pushctl.rl.policy import finish_with_policy

    assert env.episode is not None
    opened = finish_with_policy(env, actor)
    return ControllerRun(env.episode.trace(), opened / max(env.episode.n_steps, 1))


def push_scenario(name: str, scenario: Scenario, setup: PushSetup) -> tuple[Trace, Plan]:
    """The push of ``scenario`` by controller ``name`` (``pushctl simulate``), in the
    environment ``setup.config`` sets up with the scenario's push length and step: its
    trace and plan (the first run's, for a controller with several policies)."""
    from pushctl.task.env import PushEnv

    config = replace(setup.config, duration=scenario.duration, dt=scenario.dt)
    setup = replace(setup, config=config)
    controllers = build_controllers((name,), setup)
    env = PushEnv(config, setup.gains)
    start = reset(env, {"scenario": scenario})
    plan = env.plan
    run = push_controllers(controllers, start)[name][0]
    return run.trace, plan

"""Choosing which actor a training run keeps: the deterministic policy on a fixed validation
set drawn from the *tuning* stream (never the evaluation stream), scored against PD-only on
the same scenarios.

DDPG's actor wanders from checkpoint to checkpoint (on this task, the mean validation force
error of successive checkpoints 80 episodes apart moved between 0.75× and 2× PD-only's), so
the last weights are a lottery. The run scores its actor every ``validate_every`` episodes
and keeps the best, the way a held-out validation set picks an epoch in supervised learning.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from pushctl.control.gains import PDGains
from pushctl.episode.metrics import compute_metrics
from pushctl.episode.runner import Episode
from pushctl.rl.env import PushEnv
from pushctl.rl.env_config import EnvConfig
from pushctl.rl.networks import ActorPolicy
from pushctl.rl.policy import run_policy

VALIDATION_STREAM = "tuning"


@dataclass(frozen=True)
class ValidationScore:
    """Means over the validation set of DESIGN.md §7's force error [N] and translation error
    [%], for the policy and for PD-only; ``score`` = force ratio + translation ratio (2 for
    a policy that changes nothing, lower is better)."""

    force_error: float
    translation_error_pct: float
    pd_force_error: float
    pd_translation_error_pct: float

    @property
    def score(self) -> float:
        return (
            self.force_error / self.pd_force_error
            + self.translation_error_pct / self.pd_translation_error_pct
        )


class Validator:
    """The validation set of ``per_cell`` scenarios (tuning-stream seeds 0 … per_cell − 1)
    per object × profile of ``env_config``; PD-only's metrics are computed once."""

    def __init__(self, env_config: EnvConfig, gains: PDGains, per_cell: int) -> None:
        self.env = PushEnv(replace(env_config, stream=VALIDATION_STREAM), gains)
        self.options = [
            {"object": obj, "profile": profile, "scenario_seed": seed}
            for obj in env_config.objects
            for profile in env_config.profiles
            for seed in range(per_cell)
        ]
        self._pd: list[tuple[float, float]] | None = None

    def score(self, actor_state: dict[str, Any]) -> ValidationScore:
        """Run the actor of ``actor_state`` (``DDPGAgent.actor_state()``) on the set."""
        actor = ActorPolicy.from_state(actor_state)
        rl = np.array([self._metrics(run_policy(self.env, actor, o)) for o in self.options])
        pd = np.array(self._pd_metrics())
        return ValidationScore(
            force_error=float(rl[:, 0].mean()),
            translation_error_pct=float(rl[:, 1].mean()),
            pd_force_error=float(pd[:, 0].mean()),
            pd_translation_error_pct=float(pd[:, 1].mean()),
        )

    def _pd_metrics(self) -> list[tuple[float, float]]:
        if self._pd is None:
            self._pd = []
            for options in self.options:
                self.env.reset(options=options)
                baseline = Episode(self.env.scenario, self.env.gains, plan=self.env.plan)
                self._pd.append(self._metrics(baseline.run()))
        return self._pd

    @staticmethod
    def _metrics(trace) -> tuple[float, float]:
        metrics = compute_metrics(trace)
        return metrics.force_error, metrics.translation_error_pct

"""Choosing which actor a training run keeps: the deterministic policy on a fixed validation
set drawn from the *tuning* stream (never the evaluation stream), scored against PD-only on
the same scenarios.

DDPG's actor wanders from checkpoint to checkpoint (on this task, the mean validation force
error of successive checkpoints 80 episodes apart moved between 0.75× and 2× PD-only's), so
the last weights are a lottery. The run scores its actor every ``validate_every`` episodes
and keeps the best that beats PD-only on both force and translation error, the way a
held-out validation set picks an epoch in supervised learning. The set must be large enough
to hold the baseline's failures: with 3 scenarios per object × profile PD-only's mean
translation error was 0.028 %, with 10 it was 0.100 % (the trapezoid's break-away, which
the residual learns to fix, is in a third of the pushes).

The scenarios are independent, so a run spreads them over its collector processes
(:func:`validation_metrics` on chunks of :attr:`Validator.options`) and the learner only
combines the results (:meth:`Validator.score_metrics`).
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy import stats

from pushctl.control.gains import PDGains
from pushctl.episode.metrics import compute_metrics, push_failed
from pushctl.episode.trace import Trace
from pushctl.rl.networks import ActorPolicy
from pushctl.rl.policy import finish_with_policy, pd_only_episode, run_policy
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig

VALIDATION_STREAM = "tuning"

Metrics = tuple[float, float, float]
"""One validation push's (force error [N], translation error [%], angle error [%])."""

SELECTION_RULES = ("force_and_translation", "tracking", "paired")
"""What a kept actor must beat PD-only on: ``force_and_translation``, the mean force and
translation errors (score: the sum of their ratios to PD-only's); ``tracking``, the mean
translation and angle errors, Table III's claim (score: the sum of the translation, angle and
force ratios, so the force error still ranks the actors that track); ``paired``, as
``tracking``, and besides it must beat the law (the run's episode-0 actor: the zero residual
on the base law, or on PD alone, re-landed like every actor) in a paired test over the
validation pushes (:class:`PairedTest`): a validation set of 30-60 pushes picked actors by
margins of 4-5 % that the evaluation stream did not confirm (docs/learning-the-residual.md §6)."""

CONFIDENCE = 0.95
"""The paired test's two-sided confidence level."""


@dataclass(frozen=True)
class PairedTest:
    """An actor against the law on the same validation pushes: the mean per-push difference
    (RL − law) of the translation and angle errors [percentage points] with the bounds of its
    two-sided :data:`CONFIDENCE` Student-t interval across the n pushes, and each one's
    failed pushes (:func:`~pushctl.episode.metrics.push_failed`)."""

    n: int
    translation_diff: float
    translation_low: float
    translation_high: float
    angle_diff: float
    angle_low: float
    angle_high: float
    failed: int
    law_failed: int

    @property
    def beats_law(self) -> bool:
        """Both intervals wholly below zero and no more failed pushes than the law."""
        return (
            self.translation_high < 0.0 and self.angle_high < 0.0 and self.failed <= self.law_failed
        )

    def as_row(self) -> dict[str, Any]:
        """The test as ``validation.csv`` columns."""
        return {
            "pushes": self.n,
            "translation_diff": self.translation_diff,
            "translation_diff_low": self.translation_low,
            "translation_diff_high": self.translation_high,
            "angle_diff": self.angle_diff,
            "angle_diff_low": self.angle_low,
            "angle_diff_high": self.angle_high,
            "failed": self.failed,
            "law_failed": self.law_failed,
        }


def paired_test(rl: list[Metrics], law: list[Metrics]) -> PairedTest:
    """The :class:`PairedTest` of the pushes' ``rl`` and ``law`` metrics, in the same order
    (at least two)."""
    a, b = np.array(rl, dtype=float), np.array(law, dtype=float)
    if a.shape != b.shape or len(a) < 2:
        raise ValueError(
            f"paired_test needs two equal lists of >= 2 pushes, got {a.shape}, {b.shape}"
        )
    n = len(a)
    quantile = float(stats.t.ppf(0.5 + 0.5 * CONFIDENCE, n - 1))
    bounds = []
    for column in (1, 2):  # translation, angle error [%]
        diff = a[:, column] - b[:, column]
        mean, half = float(diff.mean()), quantile * float(diff.std(ddof=1)) / math.sqrt(n)
        bounds.append((mean, mean - half, mean + half))
    (t_mean, t_low, t_high), (a_mean, a_low, a_high) = bounds
    return PairedTest(
        n=n,
        translation_diff=t_mean,
        translation_low=t_low,
        translation_high=t_high,
        angle_diff=a_mean,
        angle_low=a_low,
        angle_high=a_high,
        failed=int(push_failed(a[:, 1], a[:, 2]).sum()),
        law_failed=int(push_failed(b[:, 1], b[:, 2]).sum()),
    )


@dataclass(frozen=True)
class ValidationScore:
    """Means over the validation set of docs/design.md §7's force error [N] and translation error
    [%], for the policy and for PD-only; ``score`` = force ratio + translation ratio (2 for
    a policy that changes nothing, lower is better)."""

    force_error: float
    translation_error_pct: float
    pd_force_error: float
    pd_translation_error_pct: float
    angle_error_pct: float = math.nan
    pd_angle_error_pct: float = math.nan
    rule: str = "force_and_translation"
    """The selection rule (:data:`SELECTION_RULES`)."""

    @property
    def force_ratio(self) -> float:
        return self.force_error / self.pd_force_error

    @property
    def translation_ratio(self) -> float:
        return self.translation_error_pct / self.pd_translation_error_pct

    @property
    def angle_ratio(self) -> float:
        return self.angle_error_pct / self.pd_angle_error_pct

    @property
    def score(self) -> float:
        if self.rule in ("tracking", "paired"):
            return self.translation_ratio + self.angle_ratio + self.force_ratio
        return self.force_ratio + self.translation_ratio

    @property
    def beats_pd(self) -> bool:
        """``force_and_translation``: lower force error *and* lower translation error than
        PD-only, what the trained controller is required to achieve (a lower sum alone could
        trade one for the other); ``tracking``: lower translation and angle error."""
        if self.rule in ("tracking", "paired"):
            return self.translation_ratio < 1.0 and self.angle_ratio < 1.0
        return self.force_ratio < 1.0 and self.translation_ratio < 1.0

    def no_worse_than(self, row: dict[str, Any] | None) -> bool:
        """Whether the two errors the rule selects on (``tracking``: translation and angle;
        ``force_and_translation``: force and translation) are each at most ``row``'s (a
        ``validation.csv`` row; None: nothing to compare with, True)."""
        if row is None:
            return True
        if self.rule in ("tracking", "paired"):
            return (
                self.translation_error_pct <= row["translation_error_pct"]
                and self.angle_error_pct <= row["angle_error_pct"]
            )
        return (
            self.force_error <= row["force_error"]
            and self.translation_error_pct <= row["translation_error_pct"]
        )


def validation_env(env_config: EnvConfig, gains: PDGains) -> PushEnv:
    """The environment validation pushes run in: ``env_config`` on the tuning stream."""
    return PushEnv(replace(env_config, stream=VALIDATION_STREAM), gains)


def validation_metrics(
    env: PushEnv, actor_state: dict[str, Any], options: list[dict[str, Any]]
) -> list[Metrics]:
    """The actor of ``actor_state`` (``DDPGAgent.actor_state()``, tensors or numpy arrays)
    on the scenarios ``options`` (a chunk of :attr:`Validator.options`) in ``env`` (a
    :func:`validation_env`)."""
    actor = ActorPolicy.from_state(actor_state)
    return [_metrics(run_policy(env, actor, o)) for o in options]


class ValidationPushes:
    """A collector's validation pushes: :func:`validation_metrics`, bit for bit, with each
    scenario's reset (draw, plan, plant force plan, world, approach: nearly as long as
    the push after it) made once per process and every push of that scenario started
    from a copy of it, as the evaluation pushes each further policy
    (:func:`~pushctl.evaluation.trials.run_trial`): a run scores its actor on the same set
    every ``validate_every`` episodes. A kept reset pickles to about 2 MB, so the 60
    scenarios of the ``paper`` preset's set hold about 120 MB in each collector."""

    def __init__(self, env_config: EnvConfig, gains: PDGains) -> None:
        self.env = validation_env(env_config, gains)
        self._reset: dict[tuple[tuple[str, Any], ...], PushEnv] = {}

    def metrics(self, actor_state: dict[str, Any], options: list[dict[str, Any]]) -> list[Metrics]:
        """The actor of ``actor_state`` (tensors) on the scenarios ``options``."""
        actor = ActorPolicy.from_state(actor_state)
        return [_metrics(self._push(actor, o)) for o in options]

    def _push(self, actor: ActorPolicy, options: dict[str, Any]) -> Trace:
        key = tuple(sorted(options.items()))
        start = self._reset.get(key)
        if start is None:
            self.env.reset(options=options)
            start = self._reset[key] = copy.deepcopy(self.env)
        env = copy.deepcopy(start)
        finish_with_policy(env, actor)
        assert env.episode is not None
        return env.episode.trace()


class Validator:
    """The validation set of ``per_cell`` scenarios (tuning-stream seeds first … first +
    per_cell − 1) per object × profile of ``env_config``; PD-only's metrics are computed
    once. A run picks its actor on ``first`` 0; a sweep scores the picked actors on the
    next seeds, a set the pick never saw. ``rule``: the selection rule of its scores
    (:data:`SELECTION_RULES`)."""

    def __init__(
        self,
        env_config: EnvConfig,
        gains: PDGains,
        per_cell: int,
        first: int = 0,
        rule: str = "force_and_translation",
    ) -> None:
        self.rule = rule
        self.env = validation_env(env_config, gains)
        self.options = [
            {"object": obj, "profile": profile, "scenario_seed": seed}
            for obj in env_config.objects
            for profile in env_config.profiles
            for seed in range(first, first + per_cell)
        ]
        self._pd: list[Metrics] | None = None
        self.law: list[Metrics] | None = None
        """The law's metrics on :attr:`options` (the ``paired`` rule's reference): set from
        the run's episode-0 validation, or :meth:`law_metrics`."""

    def chunks(self, n: int) -> list[list[dict[str, Any]]]:
        """:attr:`options` in ``n`` contiguous chunks (some empty if n > the set's size)."""
        bounds = np.linspace(0, len(self.options), n + 1).round().astype(int)
        return [self.options[a:b] for a, b in zip(bounds[:-1], bounds[1:], strict=True)]

    def score(self, actor_state: dict[str, Any]) -> ValidationScore:
        """Run the actor of ``actor_state`` on the whole set in this process."""
        return self.score_metrics(validation_metrics(self.env, actor_state, self.options))

    def score_metrics(self, rl_metrics: list[Metrics]) -> ValidationScore:
        """The score of a policy whose metrics on :attr:`options`, in order, are
        ``rl_metrics``."""
        if len(rl_metrics) != len(self.options):
            raise ValueError(f"{len(rl_metrics)} results for {len(self.options)} scenarios")
        rl = np.array(rl_metrics)
        pd = np.array(self._pd_metrics())
        return ValidationScore(
            force_error=float(rl[:, 0].mean()),
            translation_error_pct=float(rl[:, 1].mean()),
            pd_force_error=float(pd[:, 0].mean()),
            pd_translation_error_pct=float(pd[:, 1].mean()),
            angle_error_pct=float(rl[:, 2].mean()),
            pd_angle_error_pct=float(pd[:, 2].mean()),
            rule=self.rule,
        )

    def paired(
        self, episode: int, metrics: list[Metrics], actor_state: dict[str, Any]
    ) -> PairedTest:
        """The ``paired`` rule's test of the actor validated at ``episode`` (its ``metrics``
        on :attr:`options`, its state ``actor_state``) against the law: episode 0's actor,
        the zero residual (on the base law, or on PD alone), pushed under the same
        conditions as every actor; a resumed run that lost its metrics pushes the zero
        residual of ``actor_state`` again (the same metrics)."""
        if episode == 0:
            self.law = list(metrics)
        return paired_test(metrics, self.law_metrics(ActorPolicy.zero_residual(actor_state)))

    def law_metrics(self, zero_residual: dict[str, Any]) -> list[Metrics]:
        """The law's metrics on the set: those set in :attr:`law`, else the actor state
        ``zero_residual`` pushed here, as every validated actor is."""
        if self.law is None:
            self.law = validation_metrics(self.env, zero_residual, self.options)
        return self.law

    def _pd_metrics(self) -> list[Metrics]:
        if self._pd is None:
            env, self._pd = self.env, []
            for options in self.options:
                env.reset(options=options)
                self._pd.append(_metrics(pd_only_episode(env).finish()))
        return self._pd


def _metrics(trace) -> Metrics:
    metrics = compute_metrics(trace)
    return metrics.force_error, metrics.translation_error_pct, metrics.angle_error_pct

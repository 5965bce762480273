"""The training loop: episodes from :mod:`pushctl.rl.collect`, DDPG updates, checkpoints,
and the per-episode training curves (the paper's Fig. 5).

Schedule (the same with or without collector processes, and with any number of them): the
episodes run in rounds of ``episodes_per_round``; the episodes of round r run with the actor
as it was after the updates credited to rounds ≤ r − 2, and while they run the learner does
the updates credited to round r − 1 and then submits round r + 1, so two rounds are in
flight and the collectors do not wait for the learner. A checkpoint after a round holds
everything that schedule needs, so a resumed run continues bit for bit. Each collector steps
its contiguous share of a round together in a vector env, one batched actor forward per
step (:func:`~pushctl.rl.collect.collect_episodes`), whose rows do not depend on the share's
size: no result depends on the number of collectors.

Files in a run directory: ``checkpoint.pt`` (atomic, every ``checkpoint_every`` episodes and
at the end), ``curve.csv`` (one row per episode, rewritten atomically with each checkpoint),
``policy.pt`` (the actor to evaluate: when the preset validates, the best of the actors
that beat PD-only and episode 0's actor on the validation set, or, if none did, episode 0's
actor: the zero residual under the run's own settings, its base law and landing; else the
last),
``policy_last.pt`` (the last actor) and ``validation.csv``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from concurrent.futures import Future
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from pushctl.control.feedback import load_feedback_gains
from pushctl.control.gains import PDGains, load_gains
from pushctl.errors import ConfigError, reason
from pushctl.files.provenance import write_csv
from pushctl.rl.checkpoint import CHECKPOINT_FORMAT, read_checkpoint
from pushctl.rl.collect import Behaviour, EpisodeRecord, curve_row, portable
from pushctl.rl.collectors import Collector
from pushctl.rl.critic_side import critic_warmup_due, n_step_rows, warm_critic
from pushctl.rl.ddpg import DDPGAgent, configure_torch
from pushctl.rl.networks import ActorPolicy
from pushctl.rl.policy import holds_actor, save_atomic, write_policy
from pushctl.rl.presets import Preset
from pushctl.rl.validate import Metrics, Validator
from pushctl.task.spaces import observation_entries, scales

CHECKPOINT = "checkpoint.pt"
CURVE = "curve.csv"
POLICY = "policy.pt"
LAST_POLICY = "policy_last.pt"
VALIDATION = "validation.csv"


@dataclass(frozen=True)
class Progress:
    """What the loop reports after each episode: the record, the episodes done, the target,
    env steps and updates so far and their rates [1/s] over this session."""

    record: EpisodeRecord
    episodes_done: int
    episodes_total: int
    env_steps: int
    updates: int
    env_steps_per_s: float
    updates_per_s: float
    elapsed: float


class Trainer:
    """A training run of ``preset`` with ``seed``, writing to ``out``. Build a new one with
    :meth:`start` or continue a stopped one with :meth:`resume`."""

    def __init__(self, preset: Preset, seed: int, out: Path, gains: PDGains) -> None:
        self.preset, self.seed, self.out, self.gains = preset, seed, out, gains
        self._demonstrator = (
            load_feedback_gains() if preset.ddpg.demonstrator == "feedback" else None
        )
        """The warm-up's demonstrator: the feedback controller's gains (DDPGConfig)."""
        entries = observation_entries(
            2, reference_offset=preset.env.offset_observed, context=preset.env.observe_context
        )
        self.agent = DDPGAgent(len(entries), 3, preset.ddpg, seed, obs_scale=scales(entries))
        self.next_episode = 0
        self.pending_updates = 0
        self.rows: list[dict[str, Any]] = []
        self.validation: list[dict[str, Any]] = []
        self.best_actor: dict[str, Any] | None = None
        self.made_by = ""
        self.episodes: int | None = None  # the episodes asked for, kept in the checkpoint
        self.collectors = preset.train.workers
        """Collector processes this session (no result depends on it; see TrainConfig)."""
        self._validator: Validator | None = None

    @classmethod
    def start(cls, preset: Preset, seed: int, out: Path, gains: PDGains | None = None) -> Trainer:
        return cls(preset, seed, out, gains if gains is not None else load_gains())

    @classmethod
    def resume(cls, out: Path, gains: PDGains | None = None, *, trust: bool = False) -> Trainer:
        """The run stopped in ``out``; ConfigError (one line) if there is no checkpoint or it
        is corrupt, of another format, or without its digest (unless ``trust``)."""
        state = read_checkpoint(out / CHECKPOINT, trust_undigested=trust)
        try:
            preset = Preset.from_dict(state["preset"])
            trainer = cls(preset, int(state["seed"]), out, gains or load_gains())
            trainer.agent.load_state_dict(state["agent"])
            trainer.next_episode = int(state["next_episode"])
            trainer.pending_updates = int(state["pending_updates"])
            trainer.rows = [dict(row) for row in state["rows"]]
            trainer.made_by = str(state["made_by"])
            trainer.episodes = state.get("episodes")
            trainer.validation = [dict(row) for row in state["validation"]]
            trainer.best_actor = state["best_actor"]
        except ConfigError as exc:
            raise ConfigError(f"checkpoint {out / CHECKPOINT} is incompatible: {exc}") from None
        except (KeyError, TypeError, ValueError, RuntimeError) as exc:
            raise ConfigError(
                f"checkpoint {out / CHECKPOINT} is incompatible: {reason(exc)}"
            ) from None
        return trainer

    def run(
        self,
        episodes: int,
        on_episode: Callable[[Progress], None] | None = None,
        made_by: str = "",
    ) -> None:
        """Run episodes until ``episodes`` are done in all (counting those before a resume),
        checkpointing on the way and at the end. ``made_by`` (a provenance line) heads the
        curve CSV; a resumed run keeps the first run's line and adds its own command."""
        if made_by and self.made_by and made_by != self.made_by:
            command = made_by.removeprefix("# made by: ").split("; ")[0]
            self.made_by = f"{self.made_by}; resumed: {command}"
        else:
            self.made_by = made_by or self.made_by
        self.episodes = episodes
        self.out.mkdir(parents=True, exist_ok=True)
        configure_torch(self.preset.ddpg.torch_threads)
        clock = _Rates(self.agent)
        train = self.preset.train
        with Collector(self.preset, self.gains, self.seed, self.collectors) as collector:
            flight = self._submit_round(collector, self.next_episode, episodes)
            while flight is not None:
                # The collectors run this round (and queue its validation pushes) while the
                # learner does the updates credited to the round before; the actor is then
                # the one the next round runs with, so that round is submitted before this
                # one is waited for, and the collectors never wait for the learner.
                self._do_pending_updates()
                following = self._submit_round(collector, flight.episodes.stop, episodes)
                episodes_ = flight.episodes
                records = [record for future in flight.futures for record in future.result()]
                for record in records:
                    self._absorb(record)
                    if on_episode is not None:
                        on_episode(clock.progress(record, self.next_episode, episodes))
                if flight.validation is not None:
                    self._record_validation(flight.validation)
                every = train.checkpoint_every
                if self.next_episode // every > episodes_.start // every:
                    self.save()  # a resume resubmits the round in flight, with the same actor
                flight = following
            if self.preset.train.validate_every and self.next_episode not in self._validated:
                # the last actor (also when a finished run is resumed: scored once)
                self._record_validation(self._submit_validation(collector, self.next_episode))
        self.save()
        last = self.agent.shipped_state()
        env, made_by = self.preset.env, self.made_by
        if not self.preset.train.validate_every:
            chosen = last
        elif self.best_actor is not None:
            chosen = self.best_actor
        else:  # no actor qualified: ship episode 0's actor, the zero residual under the
            # run's own settings (its base law, its landing), which every actor was scored
            # against
            chosen = ActorPolicy.zero_residual(last)
            made_by += "; shipped: episode 0's zero residual (no actor beat it)"
        write_policy(self.out / POLICY, chosen, env, made_by)  # the last actor last: finished()
        write_policy(self.out / LAST_POLICY, last, self.preset.env, self.made_by)

    # ------------------------------------------------------------------ checkpoints

    def target(self, episodes: int | None = None) -> int:
        """``episodes`` if given, else the run's own (:attr:`episodes`), else the preset's."""
        return episodes or self.episodes or self.preset.train.episodes

    def finished(self, episodes: int) -> bool:
        """Whether ``episodes`` are done and the run's end is written: both policies of this
        checkpoint's actor and, when the preset validates, the last actor's score. A run killed
        after its last checkpoint lacks that end (or has an earlier target's): run() writes it."""
        if self.next_episode < episodes:
            return False
        last = holds_actor(self.out / LAST_POLICY, self.agent.shipped_state(), self.made_by)
        shipped = (self.out / POLICY).is_file() and last
        return shipped and (
            not self.preset.train.validate_every or self.next_episode in self._validated
        )

    def state_dict(self) -> dict[str, Any]:
        return {
            "format": CHECKPOINT_FORMAT,
            "preset": self.preset.to_dict(),
            "seed": self.seed,
            "next_episode": self.next_episode,
            "pending_updates": self.pending_updates,
            "rows": self.rows,
            "made_by": self.made_by,
            "episodes": self.episodes,
            "validation": self.validation,
            "best_actor": self.best_actor,
            "agent": self.agent.state_dict(),
        }

    def save(self) -> None:
        """The checkpoint, then the curve CSV, each written to a temporary file and renamed."""
        save_atomic(self.out / CHECKPOINT, self.state_dict())
        write_csv(self.out / CURVE, self.curve(), self.made_by)
        if self.validation:
            write_csv(self.out / VALIDATION, pd.DataFrame(self.validation), self.made_by)

    def curve(self) -> pd.DataFrame:
        """One row per episode: its scenario, RL errors ``rl_*``, PD-only errors ``pd_*``
        (empty where PD-only was not run), the gate's open share and the return."""
        return pd.DataFrame(self.rows)

    # ------------------------------------------------------------------ internals

    def _behaviour(self, episode: int) -> Behaviour:
        config = self.preset.ddpg
        steps_before = episode * self._steps_per_episode
        warmup = steps_before < config.warmup_steps
        return Behaviour(
            warmup=warmup,
            actor_state=None if warmup else portable(self.agent.actor_state()),
            ou_theta=config.ou_theta,
            ou_sigma=config.ou_sigma,
            ou_dt=config.ou_dt,
            demonstrator=self._demonstrator if warmup else None,
            privileged=config.privileged_critic,
        )

    @property
    def _steps_per_episode(self) -> int:
        """Transitions per episode: one per decision (every ``action_repeat`` steps)."""
        env = self.preset.env
        return -(-round(env.duration / env.dt) // env.action_repeat)

    def _validate_due(self, episode: int) -> bool:
        """A multiple of ``validate_every`` (episode 0 among them) not yet validated.
        Episode 0's row scores the zero residual under exactly the conditions of the later
        actors (the base law, or none, and the re-landing): the start every kept actor must
        beat (:meth:`_record_validation`), and the policy shipped if none does."""
        every = self.preset.train.validate_every
        return every > 0 and episode % every == 0 and episode not in self._validated

    @property
    def _validated(self) -> set[int]:
        """The episodes whose actor has been scored."""
        return {row["episode"] for row in self.validation}

    def _submit_round(
        self, collector: Collector, first: int, episodes: int
    ) -> _RoundInFlight | None:
        """Submit the round starting at episode ``first`` (None past ``episodes``) with the
        current actor, and its validation if one is due."""
        if first >= episodes:
            return None
        round_ = range(first, min(first + self.preset.train.episodes_per_round, episodes))
        behaviour = self._behaviour(first)
        futures = collector.submit(round_, behaviour, [e for e in round_ if self._run_pd(e)])
        due = [e for e in round_ if self._validate_due(e)]
        validation = self._submit_validation(collector, due[0]) if due else None
        return _RoundInFlight(round_, futures, validation)

    def _submit_validation(self, collector: Collector, episode: int) -> _PendingValidation:
        """Start scoring the current actor (the one episode ``episode`` runs with) on the
        validation set, spread over the collectors."""
        if self._validator is None:
            train = self.preset.train
            self._validator = Validator(
                self.preset.env, self.gains, train.validation_per_cell, rule=train.select_on
            )
        actor = self.agent.shipped_state()
        if episode == 0:  # the start: the zero residual, whatever the actor's initialisation
            actor = ActorPolicy.zero_residual(actor)
        chunks = self._validator.chunks(3 * max(1, self.collectors))
        futures = [collector.validate(portable(actor), chunk) for chunk in chunks]
        return _PendingValidation(episode, self.agent.n_updates, actor, futures)

    def _record_validation(self, pending: _PendingValidation) -> None:
        """Wait for a validation's results; keep its actor (past episode 0) if it beats
        PD-only (the selection rule's two errors), scores better than every actor kept
        before, and is no worse on those two errors than episode 0's zero residual (the law
        itself on a base law, re-landed like every actor). A lower score alone could trade
        one error for another: on the feedback law a quick run kept an actor with a 4 %
        lower score and a 21 % higher angle error, which did not beat the law on the
        evaluation stream (docs/learning-the-residual.md §6). A run whose actors never
        qualify ships episode 0's zero residual."""
        assert self._validator is not None
        metrics = [m for future in pending.futures for m in future.result()]
        result = self._validator.score_metrics(metrics)
        best = min((row["score"] for row in self.validation if row["kept"]), default=math.inf)
        base = next((row for row in self.validation if row["episode"] == 0), None)
        start = pending.episode == 0
        kept = not start and result.beats_pd and result.score < best
        kept = kept and result.no_worse_than(base)
        paired = None
        if self.preset.train.select_on == "paired":  # and beat episode 0 beyond the CI
            paired = self._validator.paired(pending.episode, metrics, pending.actor)
            kept = kept and paired.beats_law
        if kept:
            self.best_actor = pending.actor
        self.validation.append(
            {
                "episode": pending.episode,
                "updates": pending.updates,
                "force_error": result.force_error,
                "pd_force_error": result.pd_force_error,
                "translation_error_pct": result.translation_error_pct,
                "pd_translation_error_pct": result.pd_translation_error_pct,
                "angle_error_pct": result.angle_error_pct,
                "pd_angle_error_pct": result.pd_angle_error_pct,
                "score": result.score,
                "kept": kept,
                **({} if paired is None else paired.as_row()),
            }
        )

    def _run_pd(self, episode: int) -> bool:
        return episode % self.preset.train.pd_every == 0

    def _do_pending_updates(self) -> None:
        if self.agent.imitation_due:  # the warm-up's demonstrations, once, before any update
            self.agent.imitate()
        if critic_warmup_due(self.agent):  # the critic alone on the law's transitions, once
            warm_critic(self.agent)
        for _ in range(self.pending_updates):
            self.agent.update()
        self.pending_updates = 0

    def _absorb(self, record: EpisodeRecord) -> None:
        ddpg = self.preset.ddpg
        rows = n_step_rows(record.transitions, ddpg.n_step, ddpg.gamma)
        self.agent.observe(
            rows["obs"], rows["action"], rows["reward"], rows["next_obs"], rows["done"],
            rows.get("priv"), rows.get("next_priv"),
        )  # fmt: skip
        self.pending_updates += self.agent.updates_due(len(rows["reward"]))
        self.rows.append(curve_row(record))
        self.next_episode = record.episode + 1


@dataclass(frozen=True)
class _RoundInFlight:
    """A submitted round: its episodes, the futures of their records (one per collector,
    each a list in episode order), and its validation (if due)."""

    episodes: range
    futures: list[Future[list[EpisodeRecord]]]
    validation: _PendingValidation | None


@dataclass(frozen=True)
class _PendingValidation:
    """A validation under way: the episode and update count it scores, the actor, and the
    futures of its chunks' metrics."""

    episode: int
    updates: int
    actor: dict[str, Any]
    futures: list[Future[list[Metrics]]]


class _Rates:
    """Env steps and updates per second since the session started."""

    def __init__(self, agent: DDPGAgent) -> None:
        self.agent = agent
        self.started = time.perf_counter()
        self.steps0, self.updates0 = agent.env_steps, agent.n_updates

    def progress(self, record: EpisodeRecord, done: int, total: int) -> Progress:
        elapsed = max(time.perf_counter() - self.started, 1e-9)
        steps, updates = self.agent.env_steps, self.agent.n_updates
        return Progress(
            record=record,
            episodes_done=done,
            episodes_total=total,
            env_steps=steps,
            updates=updates,
            env_steps_per_s=(steps - self.steps0) / elapsed,
            updates_per_s=(updates - self.updates0) / elapsed,
            elapsed=elapsed,
        )

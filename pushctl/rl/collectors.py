"""Where a training run's episodes and validation pushes run: in the learner's process
(``workers`` 0) or in ``workers`` Ray worker processes, each holding a
:class:`CollectorWorker`. A round's episodes are split into one contiguous share per
collector, each share stepped together in a vector env
(:func:`~pushctl.rl.collect.collect_episodes`); no record depends on the split.
"""

from __future__ import annotations

from concurrent.futures import Future
from contextlib import ExitStack
from typing import Any

import torch

from pushctl.control.gains import PDGains
from pushctl.rl.collect import Behaviour, EpisodeRecord, collect_episodes, tensors
from pushctl.rl.presets import Preset
from pushctl.rl.validate import Metrics, ValidationPushes
from pushctl.task.env import PushEnv
from pushctl.task.vector_env import PushVectorEnv


class CollectorWorker:
    """What a collector process holds: the training environment and, once needed, the
    validation one."""

    def __init__(self, preset: Preset, gains: PDGains) -> None:
        self.env = PushEnv(preset.env, gains)
        self._vectors: dict[int, PushVectorEnv] = {}
        self._validation: ValidationPushes | None = None

    def collect(
        self, seed: int, episodes: list[int], behaviour: Behaviour, pd_only: list[int]
    ) -> list[EpisodeRecord]:
        """The records of ``episodes``, stepped together in a vector env of their number;
        those in ``pd_only`` with PD-only's errors too."""
        vector = self._vectors.get(len(episodes))
        if vector is None:
            env = self.env
            more = [PushEnv(env.config, env.gains) for _ in range(len(episodes) - 1)]
            vector = self._vectors[len(episodes)] = PushVectorEnv.of([env, *more])
        return collect_episodes(vector, seed, episodes, behaviour, pd_only)

    def validate(self, actor_state: dict[str, Any], options: list[dict[str, Any]]) -> list[Metrics]:
        if self._validation is None:
            self._validation = ValidationPushes(self.env.config, self.env.gains)
        return self._validation.metrics(tensors(actor_state), options)


class Collector:
    """Runs episodes in this process (``workers`` 0) or in ``workers`` Ray worker processes
    (:class:`~pushctl.distributed.engine.WorkerPool`; Ray is started here if this process
    is not connected yet)."""

    def __init__(self, preset: Preset, gains: PDGains, seed: int, workers: int) -> None:
        self.preset, self.gains, self.seed, self.workers = preset, gains, seed, workers
        self._stack = ExitStack()
        self._pool: Any = None
        self._local: CollectorWorker | None = None

    def __enter__(self) -> Collector:
        if self.workers > 0:
            from pushctl.distributed.engine import WorkerPool, session  # Ray only when used

            self._stack.enter_context(session())
            self._pool = self._stack.enter_context(
                WorkerPool(self.workers, collector_process, (self.preset, self.gains))
            )
        else:
            self._local = CollectorWorker(self.preset, self.gains)
        return self

    def __exit__(self, *exc: object) -> None:
        self._stack.close()

    def submit(
        self, episodes: range, behaviour: Behaviour, pd_only: list[int]
    ) -> list[Future[list[EpisodeRecord]]]:
        """Run ``episodes`` with ``behaviour``, and PD-only on the scenarios of those in
        ``pd_only`` (the training curves'): split into one contiguous share per collector,
        each stepping its share together (results in episode order; no record depends on
        the split, :func:`~pushctl.rl.collect.collect_episodes`)."""
        if self._pool is None:
            assert self._local is not None
            return [_done(self._local.collect(self.seed, list(episodes), behaviour, pd_only))]
        shares = min(self.workers, len(episodes))
        bounds = [episodes.start + len(episodes) * i // shares for i in range(shares + 1)]
        futures = []
        for a, b in zip(bounds, bounds[1:], strict=False):
            share_pd = [e for e in pd_only if a <= e < b]
            futures.append(
                self._pool.submit("collect", self.seed, list(range(a, b)), behaviour, share_pd)
            )
        return futures

    def validate(
        self, actor_state: dict[str, Any], options: list[dict[str, Any]]
    ) -> Future[list[Metrics]]:
        """The metrics of the actor of ``actor_state`` (numpy arrays, :func:`portable`) on
        the validation scenarios ``options``."""
        if self._pool is not None:
            return self._pool.submit("validate", actor_state, options)
        assert self._local is not None
        return _done(self._local.validate(actor_state, options))


def collector_process(preset: Preset, gains: PDGains) -> CollectorWorker:
    """A collector in a worker process of its own: torch on one thread, as the learner's
    results do not depend on it and the cores are the workers'."""
    torch.set_num_threads(1)
    return CollectorWorker(preset, gains)


def _done(value: Any) -> Future[Any]:
    """A future that already holds ``value``."""
    future: Future[Any] = Future()
    future.set_result(value)
    return future

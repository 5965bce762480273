"""One training run per seed, each a Ray task writing its own ``RUN/seed-K/``.

A task builds its :class:`~pushctl.rl.train.Trainer` from the run directory's checkpoint when
there is one, else from the job's preset. So a task that Ray retries after its worker died
(``kill -9``, a node lost) continues from the last checkpoint, and since an episode is a
pure function of (seed, episode, actor weights) (:mod:`pushctl.rl.collect`), it ends with
the files of a run that was never interrupted.

How the cores are shared (:func:`core_plan`): the seeds are the parallel work. While there
are at least two cores for each unfinished seed, each seed's learner runs the preset's
collectors on them, as a one-seed ``pushctl train`` does; with fewer, every seed runs its
episodes in its task's own process (``collectors`` 0), all at once on an equal share of the
cores when there are at most twice as many seeds as cores (3 seeds on 2 cores do not leave
a core idle while the third trains alone), else one core each in turn. A task never waits
for cores held by its siblings. The collectors' number changes no result
(:class:`~pushctl.rl.presets.TrainConfig`).
"""

from __future__ import annotations

import json
import re
import time
from collections.abc import Callable
from dataclasses import astuple, dataclass
from pathlib import Path
from typing import Any

from pushctl.control.gains import PDGains
from pushctl.distributed.engine import cluster_cpus, run_tasks, session
from pushctl.errors import ConfigError
from pushctl.files.provenance import write_atomic
from pushctl.rl.presets import Preset
from pushctl.rl.train import CHECKPOINT, POLICY, Progress, Trainer

SEED_DIR = "seed-{seed}"
"""A seed's run directory inside the runs' directory."""
MAX_SEEDS = 1000
TIMING = "timing.json"
"""A seed's training wall time, beside its run's files: ``seconds`` summed over every
session that trained it (a stopped one up to its last finished episode: the file is
rewritten after each), ``sessions``, ``episodes`` and ``env_steps``. A record of this
machine's speed, so not part of the run's byte-for-byte results (``make reproduce-tables``
reads it for its budgets)."""


def parse_seeds(text: str) -> tuple[int, ...]:
    """``"0,1,2"``, ``"0-4"`` or a mix (``"0-2,7"``) → the seeds, in order, each once;
    ConfigError (one line) for anything else."""
    seeds: list[int] = []
    for part in text.split(","):
        match = re.fullmatch(r"\s*(\d+)\s*(?:-\s*(\d+)\s*)?", part)
        if match is None:
            raise ConfigError(
                f"--seeds {text!r}: expected integers >= 0 and ranges, e.g. 0,1,2 or 0-4"
            )
        first = int(match.group(1))
        last = int(match.group(2)) if match.group(2) is not None else first
        if last < first:
            raise ConfigError(f"--seeds {text!r}: the range {part.strip()} runs backwards")
        seeds.extend(range(first, last + 1))
    if len(set(seeds)) < len(seeds):
        raise ConfigError(f"--seeds {text!r}: each seed may be named once")
    if len(seeds) > MAX_SEEDS:
        raise ConfigError(f"--seeds {text!r}: at most {MAX_SEEDS} seeds, got {len(seeds)}")
    return tuple(seeds)


def seed_dir(out: Path, seed: int) -> Path:
    return Path(out) / SEED_DIR.format(seed=seed)


@dataclass(frozen=True)
class TrainJob:
    """One run: ``preset`` with ``seed`` into ``out`` (absolute: a worker on another node
    writes there, so it must be a shared file system) until ``episodes`` (None: the
    preset's); ``check_preset``: refuse a checkpoint of another preset (False when the
    user resumes without naming one); ``made_by``: the provenance line; ``label``: its
    name in progress reports (default ``seed K``)."""

    preset: Preset
    seed: int
    out: Path
    episodes: int | None
    made_by: str
    gains: PDGains
    check_preset: bool = True
    label: str = ""

    @property
    def name(self) -> str:
        return self.label or f"seed {self.seed}"


@dataclass(frozen=True)
class JobResult:
    """A finished run: its seed, directory, episodes in all, env steps, gradient updates,
    and this session's wall time [s] (for a resumed run, the part after the resume)."""

    seed: int
    out: Path
    episodes: int
    env_steps: int
    updates: int
    seconds: float


@dataclass(frozen=True)
class SeedStatus:
    """A run's progress as last reported: episodes done of in all, and its rates line."""

    done: int
    total: int
    rates: str = ""


def open_trainer(job: TrainJob) -> Trainer:
    """The job's trainer: resumed from ``job.out``'s checkpoint if there is one (ConfigError
    if it was made with another seed, or with another preset when ``check_preset``), else
    new."""
    if not (job.out / CHECKPOINT).is_file():
        return Trainer.start(job.preset, job.seed, job.out, job.gains)
    trainer = Trainer.resume(job.out, job.gains)
    saved = trainer.preset.name, trainer.seed
    if trainer.seed != job.seed or (job.check_preset and saved[0] != job.preset.name):
        raise ConfigError(
            f"checkpoint {job.out / CHECKPOINT} is incompatible: it was made with preset "
            f"{saved[0]!r} and seed {saved[1]}, not {job.preset.name!r} and seed {job.seed}"
        )
    return trainer


@dataclass(frozen=True)
class CorePlan:
    """What each seed's task asks of Ray: ``cpus`` for its own process (0 when its
    ``collectors`` hold the cores, as a one-seed run's learner holds none)."""

    cpus: float
    collectors: int


def core_plan(cores: float, unfinished: int, workers: int) -> CorePlan:
    """How ``unfinished`` seeds share ``cores``, each preset allowing ``workers``
    collectors: a seed with at least two cores runs ``min(workers, its cores)`` collectors;
    else each runs alone in its process, on an equal share of the cores while that share is
    at least half a core (all seeds at once), else on one core (in turn)."""
    share = cores / max(1, unfinished)
    collectors = min(workers, int(share))
    if collectors >= 2:
        return CorePlan(cpus=0.0, collectors=collectors)
    return CorePlan(cpus=min(1.0, share) if share >= 0.5 else 1.0, collectors=0)


def unfinished(job: TrainJob) -> bool:
    """False if ``job``'s run has written its policy and its :data:`TIMING` says it reached
    its episodes."""
    timing = read_timing(job.out / TIMING)
    total = job.episodes if job.episodes is not None else job.preset.train.episodes
    if timing is None or not (job.out / POLICY).is_file():
        return True
    return int(timing.get("episodes", 0)) < total


def run_job(
    job: TrainJob,
    report: Callable[[str, SeedStatus], None] | None = None,
    finish: Callable[[Trainer], Any] | None = None,
    collectors: int = 0,
) -> tuple[JobResult, Any]:
    """Train ``job`` in this process with ``collectors`` collector processes (0: its
    episodes in this process too), reporting each episode to ``report``; then
    ``finish(trainer)`` (e.g. a validation score) is returned beside the result."""
    clock = time.perf_counter()
    trainer = open_trainer(job)
    trainer.collectors = collectors
    total = trainer.target(job.episodes)  # a resumed run: its own target unless asked
    before = read_timing(job.out / TIMING) or {"seconds": 0.0, "sessions": 0}

    def show(update: Progress) -> None:
        write_timing(job.out, before, time.perf_counter() - clock, trainer)
        if report is not None:
            rates = f"{update.env_steps_per_s:,.0f} steps/s {update.updates_per_s:,.1f} upd/s"
            report(job.name, SeedStatus(update.episodes_done, total, rates))

    if report is not None:  # where the run starts (a finished one: where it ended)
        report(job.name, SeedStatus(min(trainer.next_episode, total), total))
    if not trainer.finished(total):  # also a run killed after its last checkpoint
        trainer.run(total, on_episode=show, made_by=job.made_by)
        write_timing(job.out, before, time.perf_counter() - clock, trainer)
    extra = finish(trainer) if finish is not None else None
    result = JobResult(
        seed=job.seed,
        out=job.out,
        episodes=trainer.next_episode,
        env_steps=trainer.agent.env_steps,
        updates=trainer.agent.n_updates,
        seconds=time.perf_counter() - clock,
    )
    return result, extra


def write_timing(out: Path, before: dict[str, Any], seconds: float, trainer: Trainer) -> None:
    """Write ``out``'s :data:`TIMING` (atomic): ``before`` (the file as this session found
    it) plus this session's ``seconds`` so far and the trainer's progress."""
    timing = {
        "seconds": float(before["seconds"]) + seconds,
        "sessions": int(before["sessions"]) + 1,
        "episodes": trainer.next_episode,
        "env_steps": trainer.agent.env_steps,
    }
    path = Path(out) / TIMING
    write_atomic(path, lambda tmp: tmp.write_text(json.dumps(timing, indent=1) + "\n"))


def read_timing(path: Path) -> dict[str, Any] | None:
    """A :data:`TIMING` file's contents, or None if it is missing or not one."""
    try:
        timing = json.loads(Path(path).read_text())
        float(timing["seconds"]), int(timing["sessions"])
    except (OSError, ValueError, KeyError, TypeError):
        return None
    return timing


def _job_task(
    job: TrainJob,
    finish: Callable[[Trainer], Any] | None,
    collectors: int,
    post: Callable[[str, Any], None],
) -> tuple[JobResult, Any]:
    # plain tuples on the board: its process then needs none of this module's imports
    return run_job(job, lambda key, status: post(key, astuple(status)), finish, collectors)


def run_jobs(
    jobs: list[TrainJob],
    address: str | None = None,
    on_progress: Callable[[dict[str, SeedStatus]], None] | None = None,
    finish: Callable[[Trainer], Any] | None = None,
) -> list[tuple[JobResult, Any]]:
    """Run every job as a Ray task (see :func:`run_job`; retried from its checkpoint if
    its worker dies), the cores shared as :func:`core_plan` says for the jobs not yet
    finished, calling ``on_progress`` with every job's last status (by
    :attr:`TrainJob.name`) every :data:`~pushctl.distributed.engine.POLL` s; results in the
    jobs' order. A job that fails raises its error (a PushctlError keeps its one line,
    prefixed by the job's name)."""
    with session(address):
        workers = min(job.preset.train.workers for job in jobs) if jobs else 0
        plan = core_plan(cluster_cpus(), sum(unfinished(job) for job in jobs), workers)
        calls = [(job.name, (job, finish, plan.collectors)) for job in jobs]
        show = None
        if on_progress is not None:
            show = lambda posted: on_progress(  # noqa: E731
                {key: SeedStatus(*value) for key, value in posted.items()}
            )
        return run_tasks(_job_task, calls, plan.cpus, show)

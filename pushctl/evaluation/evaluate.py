"""``pushctl evaluate``'s core: every trial of a :class:`~pushctl.evaluation.trials.TrialSpec`,
in this process or in worker processes, gathered into the two tables it writes.

Workers: ``workers`` > 1 runs the jobs (one trial on one plant, every controller) in
that many Ray worker processes, each building its environments and policy once (Ray starts
on this machine unless this process is connected or ``RAY_ADDRESS`` names a cluster). A job's
result
depends on the job alone (the scenario comes from its seed, every episode starts from a fresh
world, the proxy's noise is seeded from the scenario), and results are gathered in job order,
so any number of workers writes the same bytes.

Outputs (``DIR/trials.csv`` and ``DIR/steps.csv``, see :func:`write_evaluation` and the
docs/evaluation.md for the columns) are written only once every trial has run.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import torch

from pushctl.config import PusherConfig
from pushctl.control.gains import PDGains, load_gains
from pushctl.controllers import PushSetup, entries
from pushctl.controllers.drive import build_controllers
from pushctl.episode.metrics import EpisodeMetrics
from pushctl.errors import ConfigError
from pushctl.evaluation.columns import STEP_COLUMNS, STEPS_FILE, TRIAL_COLUMNS, TRIALS_FILE
from pushctl.evaluation.trials import (
    Job,
    TrialResult,
    TrialSpec,
    run_trial,
)
from pushctl.files.provenance import write_csv
from pushctl.rl.collect import portable, tensors
from pushctl.rl.networks import ActorPolicy
from pushctl.rl.policy import TrainedPolicy, load_policy
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig
from pushctl.task.spaces import ACTION_ENTRIES, observation_entries

DEFAULT_POLICY = Path(__file__).resolve().parents[2] / "results" / "training" / "policy.pt"
"""The shipped policy (``results/training/policy.pt`` of the checkout)."""
MAX_WORKERS = 8
"""Worker processes at most (this machine has 2 cores; more only queue)."""
STEPS_FLOAT_FORMAT = "%.6g"
"""``steps.csv`` holds per-step means for figures: 6 significant figures keep the 1200-episode
file under 5 MB (9 made it 6.2 MB) and are far finer than any figure draws."""
METRIC_COLUMNS = tuple(EpisodeMetrics.__dataclass_fields__)
SUMMARY_METRICS = (
    "translation_error_pct",
    "angle_error_pct",
    "force_error",
    "torque_error",
    "slip_fraction",
    "contact_loss_fraction",
)
"""The metrics of :func:`summary`."""

OnTrial = Callable[[TrialResult, int, int], None]
"""Called after each job, in job order, with its result, jobs done and jobs in all."""


@dataclass(frozen=True)
class Evaluation:
    """An evaluation's results: ``trials`` (``trials.csv``'s rows), ``steps`` (``steps.csv``'s),
    and ``redrawn``, the goals redrawn as infeasible over its distinct targets (an object ×
    profile × trial's goal is the same on both plants, and counted once)."""

    spec: TrialSpec
    trials: pd.DataFrame
    steps: pd.DataFrame
    redrawn: int


def load_evaluation_policy(path: str | Path, *, trust_undigested: bool = False) -> TrainedPolicy:
    """:func:`~pushctl.rl.policy.load_policy`, then ConfigError (one line) unless the actor
    fits the environment: its observation and action sizes."""
    policy = load_policy(path, trust_undigested=trust_undigested)
    actor = policy.actor.actor
    n_obs = len(
        observation_entries(
            PusherConfig().n_prongs,
            reference_offset=policy.env.offset_observed,
            context=policy.env.observe_context,
        )
    )
    if (actor.obs_dim, actor.act_dim) != (n_obs, len(ACTION_ENTRIES)):
        raise ConfigError(
            f"policy file {path} is incompatible: its actor takes {actor.obs_dim} observations "
            f"and gives {actor.act_dim} actions; the environment has {n_obs} and "
            f"{len(ACTION_ENTRIES)}"
        )
    return policy


def evaluate(
    spec: TrialSpec,
    policy: TrainedPolicy | Sequence[TrainedPolicy] | None = None,
    gains: PDGains | None = None,
    workers: int = 1,
    env_config: EnvConfig | None = None,
    on_trial: OnTrial | None = None,
    controller_gains: Mapping[str, Any] | None = None,
    start: dict[str, Any] | None = None,
    keep: Callable[[Callable[[], dict[str, Any]]], None] | None = None,
) -> Evaluation:
    """Run every trial of ``spec`` and gather the tables.

    ``policy``: needed when ``spec.controllers`` holds one that pushes with a policy
    (``rl``); its environment settings (push duration, step, residual path, scale, gate)
    are RL's, and its push (duration, step) everyone's. Several policies (a sequence, see
    :func:`policy_seeds`) each push every trial and add their own ``rl`` rows; the other
    controllers still run once. Without one, ``env_config`` (default :class:`EnvConfig`'s)
    sets the push. ``gains``: the PD baseline's (default ``pushctl/defaults/pd_gains.toml``).
    ``controller_gains``: controllers' own gains by name (default: each registered
    controller's ``load_gains()``, read only when it runs; the feedback law's is
    ``pushctl/defaults/feedback_gains.toml``). ``workers``: 1 … 8 processes.
    ``keep`` is handed, after each job, a function returning what the jobs so far gathered
    (plain values and tensors, for ``torch.save``); ``start``, such a state, makes a resumed
    evaluation run only the jobs after it, to the same bytes as one run straight through.
    """
    check_workers(workers)
    none = policy is None or (not isinstance(policy, TrainedPolicy) and len(policy) == 0)
    needing = [entry for entry in entries(spec.controllers) if entry.needs_policy]
    if needing and none:
        others = "|".join(entry.name for entry in entries() if not entry.needs_policy)
        raise ConfigError(
            f"{needing[0].label} trials need a policy: pass --policy or --controller {others}"
        )
    gains = gains if gains is not None else load_gains()
    own_gains = dict(controller_gains or {})
    for entry in entries(spec.controllers):
        if entry.load_gains is not None and entry.name not in own_gains:
            own_gains[entry.name] = entry.load_gains()
    policies: list[TrainedPolicy]
    if policy is None:
        policies = []
    elif isinstance(policy, TrainedPolicy):
        policies = [policy]
    else:
        policies = list(policy)
    seeds = policy_seeds(policies)
    config = policies[0].env if policies else (env_config or EnvConfig())
    actor_states = tuple(
        (portable(p.actor.state()), seed) for p, seed in zip(policies, seeds, strict=True)
    )
    setup = (
        config, gains, actor_states, spec.plants, spec.controllers, own_gains, spec.pusher,
        spec.stream,
    )  # fmt: skip
    jobs = spec.jobs()
    gathered = _Gathered(spec) if start is None else _Gathered.restored(spec, start, len(jobs))
    kept = gathered.done  # a resumed evaluation's jobs already gathered
    for done, result in enumerate(_results(jobs[kept:], setup, workers), start=kept + 1):
        gathered.add(result)
        if on_trial is not None:
            on_trial(result, done, len(jobs))
        if keep is not None:
            keep(gathered.state)
    return gathered.evaluation()


def policy_seeds(policies: Sequence[TrainedPolicy]) -> list[int | None]:
    """Each policy's training seed (from its provenance line), once ConfigError (one line)
    has ruled out what several policies in one evaluation cannot be: trained with different
    environment settings (they push the same trials) or sharing a seed (their ``rl`` rows
    would be indistinguishable), or, for several, a policy that names no seed."""
    seeds = [p.seed for p in policies]
    if len(policies) < 2:
        return seeds
    if None in seeds:
        raise ConfigError(
            "with several policies each must name its training seed in its provenance "
            "(`pushctl train` writes it); one names none"
        )
    repeated = sorted({s for s in seeds if s is not None and seeds.count(s) > 1})
    if repeated:
        raise ConfigError(f"several policies were trained with seed {repeated[0]}; give each once")
    first = policies[0].env
    for p, seed in zip(policies[1:], seeds[1:], strict=True):
        if p.env != first:
            raise ConfigError(
                f"the policy of training seed {seed} was trained with other environment "
                f"settings than seed {seeds[0]}'s; evaluate policies of one preset together"
            )
    return seeds


def check_workers(workers: int) -> None:
    """ConfigError unless ``workers`` is an integer in 1 … :data:`MAX_WORKERS`."""
    if isinstance(workers, bool) or not isinstance(workers, int) or not 1 <= workers <= MAX_WORKERS:
        raise ConfigError(f"--workers must be an integer in 1 … {MAX_WORKERS}, got {workers!r}")


def write_evaluation(out: Path, evaluation: Evaluation, made_by: str) -> None:
    """``out/trials.csv`` and ``out/steps.csv`` under ``made_by``, each atomically; the
    trials file appears only once the steps file is written. ``out`` is created if needed."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    write_csv(
        out / TRIALS_FILE,
        evaluation.trials,
        made_by,
        before_rename=lambda: write_csv(
            out / STEPS_FILE, evaluation.steps, made_by, float_format=STEPS_FLOAT_FORMAT
        ),
    )


def summary(trials: pd.DataFrame) -> pd.DataFrame:
    """Means of :data:`SUMMARY_METRICS` per object × profile × plant (rows, in the table's
    order) and metric × controller (columns)."""
    keys = ["object", "profile", "plant"]
    means = trials.groupby([*keys, "controller"], sort=False)[list(SUMMARY_METRICS)].mean()
    # unstack sorts the rows by name; put them back in the trials' order
    return means.unstack("controller").reindex(
        pd.MultiIndex.from_frame(trials[keys].drop_duplicates())
    )


# ---------------------------------------------------------------------------- running jobs


class _Context:
    """What a process needs to run jobs: per plant, the environment each trial resets and
    the controllers built once from the registry."""

    def __init__(
        self,
        config: EnvConfig,
        gains: PDGains,
        actor_states: tuple[tuple[dict[str, Any], int | None], ...],
        plants: tuple[str, ...],
        controllers: tuple[str, ...],
        controller_gains: Mapping[str, Any],
        pusher: PusherConfig | None = None,
        stream: str = "evaluation",
    ) -> None:
        self.pusher = pusher
        actors = tuple(
            (ActorPolicy.from_state(tensors(state)), seed) for state, seed in actor_states
        )
        self.envs: dict[str, PushEnv] = {}
        self.controllers = {}
        for plant in plants:
            setup = PushSetup(
                replace(config, stream=stream, plant=plant), gains, actors, controller_gains
            )
            self.envs[plant] = PushEnv(setup.config, gains)
            self.controllers[plant] = build_controllers(controllers, setup)

    def run(self, job: Job) -> TrialResult:
        return run_trial(self.envs[job.plant], self.controllers[job.plant], job, self.pusher)


def _results(jobs: list[Job], setup: tuple, workers: int) -> Iterator[TrialResult]:
    """The jobs' results in job order, from this process or from ``workers`` Ray worker
    processes (:class:`~pushctl.distributed.engine.WorkerPool`). torch runs the actor on one
    thread either way (so float sums cannot depend on it)."""
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        if workers == 1:
            context = _Context(*setup)
            for job in jobs:
                yield context.run(job)
            return
        from pushctl.distributed.engine import WorkerPool, session  # Ray only when used

        with session(), WorkerPool(workers, _worker_context, setup) as pool:
            yield from pool.ordered("run", jobs)
    finally:
        torch.set_num_threads(threads)


def _worker_context(*setup: Any) -> _Context:
    """A worker process's context, torch on one thread."""
    torch.set_num_threads(1)
    return _Context(*setup)


# ---------------------------------------------------------------------------- gathering


def _plain(value: Any) -> Any:
    """A numpy scalar as the Python value it holds (the same number), anything else as is."""
    return value.item() if isinstance(value, np.generic) else value


class _Gathered:
    """Rows and per-step sums, filled in job order."""

    def __init__(self, spec: TrialSpec) -> None:
        self.spec = spec
        self.rows: list[dict[str, Any]] = []
        self.sums: dict[tuple[str, str, str, str], np.ndarray] = {}
        self.counts: dict[tuple[str, str, str, str], int] = {}
        self.t: np.ndarray | None = None
        self.redrawn: dict[tuple[str, str, int], int] = {}
        self.done = 0
        """Jobs gathered so far (the first ones, in job order)."""

    def state(self) -> dict[str, Any]:
        """What the jobs so far gathered, as plain values and tensors (exact: float64)."""
        return {
            "done": self.done,
            "rows": [{k: _plain(v) for k, v in row.items()} for row in self.rows],
            "sums": {key: torch.from_numpy(value.copy()) for key, value in self.sums.items()},
            "counts": dict(self.counts),
            "t": None if self.t is None else torch.from_numpy(self.t.copy()),
            "redrawn": dict(self.redrawn),
        }

    @classmethod
    def restored(cls, spec: TrialSpec, state: dict[str, Any], jobs: int) -> _Gathered:
        """The gathering :meth:`state` describes; ConfigError if it does not fit ``jobs``."""
        gathered = cls(spec)
        try:
            gathered.done = int(state["done"])
            gathered.rows = [dict(row) for row in state["rows"]]
            gathered.sums = {tuple(k): v.numpy().copy() for k, v in state["sums"].items()}
            gathered.counts = {tuple(k): int(v) for k, v in state["counts"].items()}
            gathered.t = None if state["t"] is None else state["t"].numpy().copy()
            gathered.redrawn = {tuple(k): int(v) for k, v in state["redrawn"].items()}
        except (KeyError, TypeError, AttributeError, ValueError) as exc:
            raise ConfigError(f"the kept trials are not an evaluation's ({exc})") from None
        if not 0 <= gathered.done <= jobs:
            raise ConfigError(f"the kept trials number {gathered.done}, the evaluation {jobs}")
        return gathered

    def add(self, result: TrialResult) -> None:
        self.done += 1
        job = result.job
        self.rows.extend(result.rows)
        self.redrawn[(job.object, job.profile, job.trial)] = result.redrawn
        self.t = result.t
        for controller, quantities in result.steps.items():
            key = (job.object, job.profile, job.plant, controller)
            if key in self.sums:
                self.sums[key] = self.sums[key] + quantities
                self.counts[key] += 1
            else:
                self.sums[key] = quantities.copy()
                self.counts[key] = 1

    def evaluation(self) -> Evaluation:
        """The tables, rows in the spec's order of objects, profiles, plants, controllers
        (then trials)."""
        spec = self.spec
        names = (spec.objects, spec.profiles, spec.plants, spec.controllers)

        def rank(cell: tuple[str, ...]) -> tuple[int, ...]:
            return tuple(order.index(name) for order, name in zip(names, cell, strict=True))

        cell_keys = ("object", "profile", "plant", "controller")
        rows = sorted(
            self.rows, key=lambda row: (*rank(tuple(row[k] for k in cell_keys)), row["trial"])
        )
        trials = pd.DataFrame(rows, columns=[*TRIAL_COLUMNS, *METRIC_COLUMNS])
        assert self.t is not None
        frames = []
        for cell in sorted(self.sums, key=rank):
            frame = pd.DataFrame(self.sums[cell] / self.counts[cell], columns=list(STEP_COLUMNS))
            frame.insert(0, "t", self.t)
            frame.insert(0, "step", np.arange(len(self.t)))
            for i, name in enumerate(cell_keys):
                frame.insert(i, name, cell[i])
            frames.append(frame)
        steps = pd.concat(frames, ignore_index=True)
        return Evaluation(spec, trials, steps, sum(self.redrawn.values()))

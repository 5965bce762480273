"""``pushctl sweep``'s core: every configuration of a sweep
(:class:`~pushctl.runs.sweep_config.Sweep`) × every seed trained as a Ray task
(:mod:`pushctl.runs.seeds`), then scored on the validation set.

Scoring (tuning stream, never the evaluation stream): each run's ``policy.pt`` (the actor
the run kept on its own validation set, tuning seeds 0 … n − 1) is scored against PD-only
on the *next* n tuning seeds per object × profile (:class:`~pushctl.rl.validate.Validator`
with ``first`` = n), so the sweep's numbers are not those the run's own pick was made on.
``score`` = force ratio + translation ratio to PD-only: 2 changes nothing, lower is better.

Files in the sweep's directory: ``trial-NNN/seed-K/`` (each a run directory, resumable),
``trials.csv`` (one row per configuration × seed), ``summary.csv`` (one row per
configuration: the score's mean, standard deviation, min and max over seeds) and
``sweep.png`` (:func:`pushctl.report.sweep_figure.sweep_figure`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd
import torch

from pushctl.control.gains import load_gains
from pushctl.rl.train import POLICY, Trainer
from pushctl.rl.validate import ValidationScore, Validator
from pushctl.runs.seeds import JobResult, TrainJob
from pushctl.runs.sweep_config import Sweep

TRIALS_FILE = "trials.csv"
SUMMARY_FILE = "summary.csv"
FIGURE_FILE = "sweep.png"
TRIAL_DIR = "trial-{index:03d}"
SCORE_COLUMNS = (
    "score",
    "force_ratio",
    "translation_ratio",
    "force_error",
    "pd_force_error",
    "translation_error_pct",
    "pd_translation_error_pct",
    "beats_pd",
)


@dataclass(frozen=True)
class SweepResult:
    """``trials``: one row per configuration × seed (``trial``, ``seed``, the swept keys,
    ``episodes``, :data:`SCORE_COLUMNS`, ``wall_time_s``, ``run``); ``summary``: one row
    per configuration."""

    sweep: Sweep
    trials: pd.DataFrame
    summary: pd.DataFrame


def sweep_jobs(sweep: Sweep, out: Path, made_by: str) -> list[TrainJob]:
    """One job per configuration × seed, into ``out/trial-NNN/seed-K/`` (absolute)."""
    gains = load_gains()
    jobs = []
    for index, configuration in enumerate(sweep.configurations()):
        preset = sweep.preset_for(configuration)
        trial = TRIAL_DIR.format(index=index)
        for seed in sweep.seeds:
            jobs.append(
                TrainJob(
                    preset=preset,
                    seed=seed,
                    out=(Path(out) / trial / f"seed-{seed}").absolute(),
                    episodes=sweep.episodes,
                    made_by=f"{made_by}; {trial}, seed {seed} (training stream)",
                    gains=gains,
                    label=f"{trial} seed {seed}",
                )
            )
    return jobs


def score_policy(trainer: Trainer) -> ValidationScore:
    """The run's ``policy.pt`` on the sweep's validation set (see the module's docstring)."""
    per_cell = trainer.preset.train.validation_per_cell
    validator = Validator(trainer.preset.env, trainer.gains, per_cell, first=per_cell)
    actor = torch.load(trainer.out / POLICY, weights_only=True)["actor"]
    return validator.score(actor)


def gather(sweep: Sweep, results: list[tuple[JobResult, ValidationScore]]) -> SweepResult:
    """The tables from the jobs' results, in :func:`sweep_jobs`' order."""
    configurations = sweep.configurations()
    rows: list[dict[str, Any]] = []
    for i, (result, score) in enumerate(results):
        index = i // len(sweep.seeds)
        row: dict[str, Any] = {"trial": index, "seed": result.seed, **configurations[index]}
        row["episodes"] = result.episodes
        row.update({name: getattr(score, name) for name in SCORE_COLUMNS})
        row["wall_time_s"] = result.seconds
        row["run"] = str(result.out.relative_to(result.out.parents[1]))
        rows.append(row)
    trials = pd.DataFrame(rows)
    return SweepResult(sweep, trials, summarise(trials, sweep.keys))


def summarise(trials: pd.DataFrame, keys: list[str]) -> pd.DataFrame:
    """Per configuration: its values, seeds, the score's mean, standard deviation (ddof 1;
    empty for one seed), min and max, the runs that beat PD-only, and the mean wall time;
    best mean score first."""
    grouped = trials.groupby("trial", sort=True)
    summary = grouped[keys].first()
    summary["seeds"] = grouped["seed"].count()
    for name in ("mean", "std", "min", "max"):
        summary[f"score_{name}"] = grouped["score"].agg(name)
    summary["beats_pd"] = grouped["beats_pd"].sum()
    summary["wall_time_s"] = grouped["wall_time_s"].mean()
    return summary.reset_index().sort_values(["score_mean", "trial"], kind="stable")

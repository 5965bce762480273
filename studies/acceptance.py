"""The acceptance of the learned residual, read from an evaluation's ``trials.csv``: per
cell, plant and training seed, RL-assisted against PD-only (and against ``feedback``) on
translation and angle error, as paired differences over the cell's trials with their 95 %
confidence interval, and the ratio of the means.

Run ``python -m studies.acceptance results/evaluation/trials.csv``: Markdown tables
per plant, then a per-cell summary (:func:`cell_summary`: RL over every policy against
PD-only, and each controller's failed pushes). A cell *passes* on a metric when the paired
difference's whole interval is below zero (RL lower on these trials beyond their noise).
Beside it the table gives in how many of the cell's trials RL was lower: the interval is a
mean's, so one trial where RL rescued a push PD-only failed (a difference of −100 % among
differences of −2 %) can widen it past zero while RL is lower in nearly every trial
(docs/results.md).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from pushctl.episode.metrics import push_failed
from pushctl.report.tables import OBJECT_ORDER, PROFILE_ORDER, ci95_halfwidth

METRICS = ("translation_error_pct", "angle_error_pct", "force_error", "force_error_landed")
"""The metrics compared (``force_error_landed`` only where the trials have it)."""
HEADINGS = {
    "translation_error_pct": "translation",
    "angle_error_pct": "angle",
    "force_error": "force",
    "force_error_landed": "force vs landed",
}
KEYS = ["object", "profile", "plant", "trial"]


def paired(trials: pd.DataFrame, plant: str, other: str = "pd") -> pd.DataFrame:
    """One row per (object, profile, policy seed) on ``plant``: for each metric of
    :data:`METRICS`, RL's mean, ``other``'s mean, their ratio, the paired difference
    RL − other (mean and 95 % half-width over the trials both ran), and in how many of those
    trials RL was lower (``_lower_in`` of ``_trials``); metrics ``trials`` lacks are left out."""
    on_plant = trials[trials["plant"] == plant]
    base = on_plant[on_plant["controller"] == other].set_index(KEYS)
    rl = on_plant[on_plant["controller"] == "rl"]
    seeds = sorted(pd.to_numeric(rl["policy_seed"]).dropna().astype(int).unique())
    rows = []
    for obj in OBJECT_ORDER:
        for profile in PROFILE_ORDER:
            for seed in seeds:
                mine = rl[
                    (rl["object"] == obj)
                    & (rl["profile"] == profile)
                    & (pd.to_numeric(rl["policy_seed"]) == seed)
                ].set_index(KEYS)
                if mine.empty:
                    continue
                row: dict[str, object] = {"object": obj, "profile": profile, "policy_seed": seed}
                joined = mine.join(base, how="inner", suffixes=("_rl", "_other"))
                for metric in _present(trials):
                    a = joined[f"{metric}_rl"].to_numpy(float)
                    b = joined[f"{metric}_other"].to_numpy(float)
                    keep = np.isfinite(a) & np.isfinite(b)
                    diff = a[keep] - b[keep]
                    mean_rl, mean_other = float(np.mean(a[keep])), float(np.mean(b[keep]))
                    row[f"{metric}_rl"], row[f"{metric}_{other}"] = mean_rl, mean_other
                    row[f"{metric}_ratio"] = mean_rl / mean_other
                    row[f"{metric}_diff"] = float(np.mean(diff))
                    row[f"{metric}_diff_ci95"] = ci95_halfwidth(diff)
                    row[f"{metric}_lower_in"] = int(np.sum(diff < 0.0))
                    row[f"{metric}_trials"] = int(diff.size)
                rows.append(row)
    return pd.DataFrame(rows)


def _present(frame: pd.DataFrame) -> list[str]:
    """The metrics of :data:`METRICS` with a column in ``frame`` (as in trials.csv, or as
    ``{metric}_ratio`` in a :func:`paired` table)."""
    return [m for m in METRICS if m in frame.columns or f"{m}_ratio" in frame.columns]


def passes(table: pd.DataFrame, metric: str) -> pd.Series:
    """Whether each row's paired difference on ``metric`` is below zero with its interval."""
    return (table[f"{metric}_diff"] + table[f"{metric}_diff_ci95"]) < 0.0


def markdown(table: pd.DataFrame, other: str) -> str:
    """The rows as Markdown: ratios of the means, whether RL is lower beyond the CI, and in
    how many trials it was lower."""
    metrics = _present(table)
    headings = "".join(f" {HEADINGS[m]} RL/{other} | lower?, in |" for m in metrics)
    lines = [
        f"| object | profile | seed |{headings}",
        "|---|---|---|" + "---|---|" * len(metrics),
    ]
    for _, row in table.iterrows():
        cells = [str(row["object"]), str(row["profile"]), str(row["policy_seed"])]
        for metric in metrics:
            lower = row[f"{metric}_diff"] + row[f"{metric}_diff_ci95"] < 0.0
            count = f"{row[f'{metric}_lower_in']}/{row[f'{metric}_trials']}"
            cells += [f"{row[f'{metric}_ratio']:.2f}", ("yes, " if lower else "no, ") + count]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def cell_summary(trials: pd.DataFrame, plant: str) -> pd.DataFrame:
    """One row per (object, profile) on ``plant``: RL's mean over every policy's trials
    against PD-only's, as the ratio of the means of each metric of :data:`METRICS` the
    trials have (``{metric}_ratio``), and per controller the failed pushes
    (:func:`~pushctl.episode.metrics.push_failed`) and all its pushes (``{controller}_failed``,
    ``{controller}_pushes``)."""
    on_plant = trials[trials["plant"] == plant].assign(
        failed=lambda t: push_failed(t["translation_error_pct"], t["angle_error_pct"])
    )
    controllers = [c for c in ("pd", "feedback", "rl") if (on_plant["controller"] == c).any()]
    rows = []
    for obj in OBJECT_ORDER:
        for profile in PROFILE_ORDER:
            cell = on_plant[(on_plant["object"] == obj) & (on_plant["profile"] == profile)]
            if not cell.empty:
                rows.append(_cell_row(cell, obj, profile, _present(trials), controllers))
    return pd.DataFrame(rows)


def _cell_row(
    cell: pd.DataFrame, obj: str, profile: str, metrics: list[str], controllers: list[str]
) -> dict[str, object]:
    """:func:`cell_summary`'s row of one cell's trials."""
    by = cell.groupby("controller")
    row: dict[str, object] = {"object": obj, "profile": profile}
    for metric in metrics:
        means = by[metric].mean()
        row[f"{metric}_ratio"] = means.get("rl", np.nan) / means.get("pd", np.nan)
    failed, pushes = by["failed"].sum(), by.size()
    for controller in controllers:
        row[f"{controller}_failed"] = int(failed.get(controller, 0))
        row[f"{controller}_pushes"] = int(pushes.get(controller, 0))
    return row


def summary_markdown(table: pd.DataFrame) -> str:
    """:func:`cell_summary`'s rows as Markdown: the RL/PD ratios, then failed of all pushes
    per controller."""
    metrics = _present(table)
    controllers = [c[: -len("_failed")] for c in table.columns if c.endswith("_failed")]
    header = [f"{HEADINGS[m]} RL/pd" for m in metrics] + [f"failed {c}" for c in controllers]
    lines = ["| object | profile | " + " | ".join(header) + " |",
             "|---|---|" + "---|" * len(header)]  # fmt: skip
    for _, row in table.iterrows():
        cells = [str(row["object"]), str(row["profile"])]
        cells += [f"{row[f'{m}_ratio']:.2f}" for m in metrics]
        cells += [f"{row[f'{c}_failed']}/{row[f'{c}_pushes']}" for c in controllers]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m studies.acceptance")
    parser.add_argument("trials", type=Path, help="an evaluation's trials.csv")
    args = parser.parse_args(argv)
    if not args.trials.is_file():
        print(
            f"acceptance: no file {args.trials}; give an evaluation's trials.csv", file=sys.stderr
        )
        return 2
    trials = pd.read_csv(args.trials, comment="#")
    if "policy_seed" not in trials.columns or not (trials["controller"] == "rl").any():
        print(f"acceptance: {args.trials} has no rl rows with a policy_seed", file=sys.stderr)
        return 2
    for plant in [p for p in ("sim", "proxy", "mujoco") if p in set(trials["plant"])]:
        for other in ("pd", "feedback"):
            if not (trials["controller"] == other).any():
                continue
            table = paired(trials, plant, other)
            print(f"\n### {plant}: RL-assisted against {other} (paired, 95 % CI)\n")
            print(markdown(table, other))
        print(f"\n### {plant}: per cell, RL over every policy against pd; failed pushes\n")
        print(summary_markdown(cell_summary(trials, plant)))
    return 0


if __name__ == "__main__":
    sys.exit(main())

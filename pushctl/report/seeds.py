"""Several training seeds in the report (docs/several-seeds.md).

An evaluation of several policies (``pushctl evaluate --policy A --policy B …``) holds one
set of ``rl`` rows per policy, told apart by ``policy_seed``; PD-only and feedback ran once
per trial. With two or more seeds:

- each RL column of Tables III and IV is the mean over the trials of the per-trial mean
  over the seeds (:func:`trial_means`), and its ``_ci95`` the half-width of the 95 %
  confidence interval of that mean *over the trials*, as PD-only's and feedback's: the same
  name means the same interval in every column;
- the spread across seeds has its own column, ``<column>_seed_sd``: the sample standard
  deviation (S − 1) of the S seeds' own cell means (how much training varies from seed to
  seed, which the trial interval does not show);
- PD-only and feedback columns keep their means and intervals over the trials;
- :func:`paired_differences` gives, per cell and plant, RL − feedback on each trial (RL's
  per-trial mean over the seeds), with its 95 % interval over the trials (``tables.md``);
- each seed's own RL/PD and RL/feedback ratio per cell is a row of :func:`seed_ratios`
  (``table3_seeds.csv``); the ratio a table shows is their mean (PD's and feedback's means do
  not depend on the seed, so it equals the ratio of the means), with its interval across
  seeds (the S seeds' own ratios) from :func:`ratio_intervals`.

With one seed (or files without ``policy_seed``) the tables are those of
:func:`~pushctl.report.tables.table3` and :func:`~pushctl.report.tables.table4` unchanged.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from pushctl.report.tables import ResultTable, cells, ci95_halfwidth, table3, table4

RL_COLUMN = re.compile(r"(^|_)rl(_|$)")
"""A table column holding an RL-assisted mean (``translation_error_rl``, ``force_error_rl_sim``,
``angle_error_rl_mujoco``)."""

SEED_RATIOS = (
    ("translation_rl_pd", "translation_error_rl", "translation_error_pd"),
    ("translation_rl_feedback", "translation_error_rl", "translation_error_feedback"),
    ("angle_rl_pd", "angle_error_rl", "angle_error_pd"),
    ("angle_rl_feedback", "angle_error_rl", "angle_error_feedback"),
)
"""The per-seed ratios of ``table3_seeds.csv``: (name, numerator, denominator column of
Table III)."""

MakeTable = Callable[[pd.DataFrame], ResultTable]


@dataclass(frozen=True)
class SeedTables:
    """Tables III and IV as the report shows them, the per-seed ratios (``per_seed``:
    ``table3_seeds.csv``), the training seeds found (``seeds``, sorted; empty when the
    trials name none) and whether the tables are across seeds (``several``)."""

    table3: ResultTable
    table4: ResultTable
    per_seed: pd.DataFrame
    seeds: tuple[int, ...]
    ratio_ci: dict[tuple[str, str, str, str], float]
    """Across seeds: the CI half-width of each RL/PD and RL/feedback ratio, by (object,
    profile, RL column, PD or feedback column); empty with one seed."""
    paired: pd.DataFrame
    """RL − feedback paired over the trials, per cell and plant (:func:`paired_differences`)."""

    @property
    def several(self) -> bool:
        return len(self.seeds) > 1


def seed_tables(trials: pd.DataFrame) -> SeedTables:
    """Tables III and IV of ``trials`` (``trials.csv``'s columns) and the per-seed ratios:
    across seeds when the ``rl`` rows name two or more ``policy_seed`` values, else as
    :func:`table3` and :func:`table4` give them."""
    seeds = policy_seeds(trials)
    paired = paired_differences(trials)
    if len(seeds) < 2:
        ratios = seed_ratios(trials, seeds)
        return SeedTables(table3(trials), table4(trials), ratios, (), {}, paired)
    intervals: dict[tuple[str, str, str, str], float] = {}
    tables: list[ResultTable] = []
    for make in (table3, table4):
        table = across_seeds(trials, make, seeds)
        pairs = [
            (column, RL_COLUMN.sub(rf"\g<1>{other}\g<2>", column, count=1))
            for column in table.value_columns
            if RL_COLUMN.search(column)
            for other in ("pd", "feedback")
        ]
        intervals |= ratio_intervals(trials, make, seeds, pairs)
        tables.append(table)
    third, fourth = tables
    per_seed = seed_ratios(trials, seeds)
    return SeedTables(third, fourth, per_seed, tuple(seeds), intervals, paired)


def policy_seeds(trials: pd.DataFrame) -> list[int]:
    """The distinct training seeds of the ``rl`` rows, sorted (none without the column)."""
    if "policy_seed" not in trials.columns:
        return []
    named = pd.to_numeric(trials.loc[trials["controller"] == "rl", "policy_seed"])
    return sorted({int(seed) for seed in named.dropna()})


def one_seed(trials: pd.DataFrame, seed: int | None) -> pd.DataFrame:
    """``trials`` with only ``seed``'s ``rl`` rows (every ``rl`` row for None)."""
    if seed is None:
        return trials
    return trials[(trials["controller"] != "rl") | (trials["policy_seed"] == seed)]


def _by_cell(table: ResultTable) -> pd.DataFrame:
    return table.values.set_index(["object", "profile"])


TRIAL_KEYS = ["object", "profile", "plant", "trial"]
"""A trial: PD-only, feedback and each seed's policy pushed the same scenario."""


def trial_means(trials: pd.DataFrame) -> pd.DataFrame:
    """``trials`` with the ``rl`` rows of every seed replaced by one row per trial: each
    numeric column (any column with a number in it) the mean over the seeds of its finite
    values (NaN if none), the others the first seed's; ``policy_seed`` empty."""
    rl = trials["controller"] == "rl"
    if not rl.any():
        return trials
    rows = trials[rl].copy()
    numeric = []
    for column in rows.columns.difference([*TRIAL_KEYS, "controller", "policy_seed"]):
        # the tables read a column as floats whatever its dtype (a reader may leave text)
        values = pd.to_numeric(rows[column], errors="coerce")
        if values.notna().any():
            rows[column] = values.replace([np.inf, -np.inf], np.nan)
            numeric.append(column)
    grouped = rows.groupby(TRIAL_KEYS, sort=False)
    merged = grouped.first()
    merged[numeric] = grouped[numeric].mean()
    merged = merged.reset_index()[list(trials.columns)].assign(policy_seed=math.nan)
    return pd.concat([trials[~rl], merged], ignore_index=True)


def across_seeds(trials: pd.DataFrame, make: MakeTable, seeds: Sequence[int]) -> ResultTable:
    """``make(trials)`` with each RL column's mean, ``_ci95`` and count those of the
    per-trial means over the seeds (:func:`trial_means`): the interval over the trials, as
    every other column's; after the table's columns, each RL column's ``_seed_sd``, the
    sample standard deviation of the seeds' own cell means (NaN seeds, say a cell a seed
    has no finite value in, left out)."""
    pooled = make(trials)
    averaged = make(trial_means(trials))
    index = pd.MultiIndex.from_frame(pooled.values[["object", "profile"]])
    per_seed = [_by_cell(make(one_seed(trials, seed))).reindex(index) for seed in seeds]
    values, counts = pooled.values.copy(), pooled.counts.copy()
    spread = {}
    for column in pooled.value_columns:
        if not RL_COLUMN.search(column):
            continue
        values[column] = averaged.values[column]
        values[f"{column}_ci95"] = averaged.values[f"{column}_ci95"]
        counts[column] = averaged.counts[column]
        means = np.column_stack([table[column].to_numpy(float) for table in per_seed])
        spread[f"{column}_seed_sd"] = [_finite_sd(row) for row in means]
    return ResultTable(values=pd.concat([values, pd.DataFrame(spread)], axis=1), counts=counts)


PAIRED_METRICS = ("translation_error_pct", "angle_error_pct")
"""The metrics :func:`paired_differences` compares (Table III's)."""


def paired_differences(trials: pd.DataFrame, other: str = "feedback") -> pd.DataFrame:
    """One row per (object, profile, plant) with ``rl`` and ``other`` rows: for each metric
    of :data:`PAIRED_METRICS`, the mean over the trials both have a finite value in of RL's
    per-trial mean over the seeds minus ``other``'s (``<metric>_diff``), the half-width of
    its 95 % confidence interval over those trials (``_diff_ci95``), and their number
    (``_diff_n``)."""
    averaged = trial_means(trials)
    rl = averaged[averaged["controller"] == "rl"].set_index(TRIAL_KEYS)
    base = averaged[averaged["controller"] == other].set_index(TRIAL_KEYS)
    joined = rl.join(base, how="inner", suffixes=("_rl", "_other")).reset_index()
    rows: list[dict[str, object]] = []
    if joined.empty:
        return pd.DataFrame(rows)
    plants = [p for p in ("sim", "proxy", "mujoco") if (joined["plant"] == p).any()]
    for obj, profile in cells(joined):
        for plant in plants:
            cell = joined[
                (joined["object"] == obj)
                & (joined["profile"] == profile)
                & (joined["plant"] == plant)
            ]
            if cell.empty:
                continue
            row: dict[str, object] = {"object": obj, "profile": profile, "plant": plant}
            for metric in PAIRED_METRICS:
                diff = (cell[f"{metric}_rl"] - cell[f"{metric}_other"]).to_numpy(float)
                diff = diff[np.isfinite(diff)]
                row[f"{metric}_diff"] = float(diff.mean()) if diff.size else math.nan
                row[f"{metric}_diff_ci95"] = ci95_halfwidth(diff)
                row[f"{metric}_diff_n"] = int(diff.size)
            rows.append(row)
    return pd.DataFrame(rows)


def seed_ratios(trials: pd.DataFrame, seeds: Sequence[int]) -> pd.DataFrame:
    """``table3_seeds.csv``: per (object, profile) and seed (in that order; one row per
    cell with an empty seed when the trials name none), the seed's own RL means of Table III
    [%] and its :data:`SEED_RATIOS`."""
    rows = []
    chosen: list[int | None] = [*seeds] or [None]
    tables = {seed: _by_cell(table3(one_seed(trials, seed))) for seed in chosen}
    for obj, profile in next(iter(tables.values())).index:
        for seed, table in tables.items():
            cell = table.loc[(obj, profile)]
            row: dict[str, object] = {"object": obj, "profile": profile, "policy_seed": seed}
            row["translation_error_rl"] = float(cell["translation_error_rl"])
            row["angle_error_rl"] = float(cell["angle_error_rl"])
            for name, above, below in SEED_RATIOS:
                row[name] = _ratio(float(cell[above]), float(cell[below]))
            rows.append(row)
    frame = pd.DataFrame(rows)
    frame["policy_seed"] = frame["policy_seed"].astype("Int64")  # integers, empty for none
    return frame


def ratio_intervals(
    trials: pd.DataFrame, make: MakeTable, seeds: Sequence[int], pairs: Sequence[tuple[str, str]]
) -> dict[tuple[str, str, str, str], float]:
    """The 95 % CI half-width across ``seeds`` of each seed's own ratio ``above / below``
    (columns of ``make``'s table), by (object, profile, above, below)."""
    tables = [_by_cell(make(one_seed(trials, seed))) for seed in seeds]
    intervals = {}
    for obj, profile in tables[0].index:
        for above, below in pairs:
            ratios = [
                _ratio(float(t.loc[(obj, profile), above]), float(t.loc[(obj, profile), below]))
                for t in tables
            ]
            intervals[(obj, profile, above, below)] = ci95_halfwidth(np.array(ratios))
    return intervals


def seeds_markdown(per_seed: pd.DataFrame) -> list[str]:
    """Lines of ``tables.md``'s per-seed table: each seed's own Table III ratios per cell."""
    header = ["object", "profile", "seed", *(name for name, _, _ in SEED_RATIOS)]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for row in per_seed.itertuples(index=False):
        cells = [str(row.object), str(row.profile), str(row.policy_seed)]
        cells += [_shown(getattr(row, name)) for name, _, _ in SEED_RATIOS]
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def _shown(value: float) -> str:
    return "–" if not math.isfinite(value) else f"{value:.2f}"


def _ratio(numerator: float, denominator: float) -> float:
    if not (math.isfinite(numerator) and math.isfinite(denominator)) or denominator == 0.0:
        return math.nan
    return numerator / denominator


def _finite_sd(values: np.ndarray) -> float:
    finite = values[np.isfinite(values)]
    return float(np.std(finite, ddof=1)) if finite.size >= 2 else math.nan

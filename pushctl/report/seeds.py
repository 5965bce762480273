"""Several training seeds in the report (docs/several-seeds.md).

An evaluation of several policies (``pushctl evaluate --policy A --policy B …``) holds one
set of ``rl`` rows per policy, told apart by ``policy_seed``; PD-only and feedback ran once
per trial. With two or more seeds:

- each RL column of Tables III and IV is the mean over seeds of the seed's own cell mean
  (over its trials), and its ``_ci95`` the half-width of the 95 % confidence interval
  *across seeds*: t(0.975, S − 1) · s / √S over the S per-seed cell means (the spread a
  reader needs to judge whether training is reliable, not the trial noise of one policy);
- PD-only and feedback columns keep their means and intervals over the trials;
- each seed's own RL/PD and RL/feedback ratio per cell is a row of :func:`seed_ratios`
  (``table3_seeds.csv``); the ratio a table shows is their mean (PD's and feedback's means do
  not depend on the seed, so it equals the ratio of the means), with its interval across
  seeds from :func:`ratio_intervals`.

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

from pushctl.report.tables import ResultTable, ci95_halfwidth, table3, table4

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

    @property
    def several(self) -> bool:
        return len(self.seeds) > 1


def seed_tables(trials: pd.DataFrame) -> SeedTables:
    """Tables III and IV of ``trials`` (``trials.csv``'s columns) and the per-seed ratios:
    across seeds when the ``rl`` rows name two or more ``policy_seed`` values, else as
    :func:`table3` and :func:`table4` give them."""
    seeds = policy_seeds(trials)
    if len(seeds) < 2:
        return SeedTables(table3(trials), table4(trials), seed_ratios(trials, seeds), (), {})
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
    return SeedTables(third, fourth, seed_ratios(trials, seeds), tuple(seeds), intervals)


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


def across_seeds(trials: pd.DataFrame, make: MakeTable, seeds: Sequence[int]) -> ResultTable:
    """``make(trials)`` with each RL column replaced by the mean over ``seeds`` of the
    seed's own cell mean and its ``_ci95`` by the interval across seeds (NaN seeds, say a
    cell a seed has no finite value in, left out); counts stay the trials behind the
    values (every seed's)."""
    pooled = make(trials)
    cells = pd.MultiIndex.from_frame(pooled.values[["object", "profile"]])
    per_seed = [_by_cell(make(one_seed(trials, seed))).reindex(cells) for seed in seeds]
    values = pooled.values.copy()
    for column in pooled.value_columns:
        if not RL_COLUMN.search(column):
            continue
        means = np.column_stack([table[column].to_numpy(float) for table in per_seed])
        values[column] = [_finite_mean(row) for row in means]
        values[f"{column}_ci95"] = [ci95_halfwidth(row) for row in means]
    return ResultTable(values=values, counts=pooled.counts)


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


def _finite_mean(values: np.ndarray) -> float:
    finite = values[np.isfinite(values)]
    return float(finite.mean()) if finite.size else math.nan

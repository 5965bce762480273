"""``tables.md``: Tables III and IV in Markdown, ours (mean ± 95 % CI half-width) beside the
paper's published values, with the trial counts, the RL/PD ratios (the one comparison that
survives the differences of units and normalisation), the RL/feedback ratios (the paper has
no feedback baseline) and notes on what differs.

Force and torque errors are shown in mN and mN·m, ours and the paper's alike (the CSVs hold
N and N·m; the paper prints 10⁻¹ N and 10⁻³ N·m).
"""

from __future__ import annotations

import math

from pushctl.controllers import entries
from pushctl.report import paper_values
from pushctl.report.seeds import PAIRED_METRICS, SeedTables, seeds_markdown
from pushctl.report.tables import ResultTable

MILLI = 1e3

NOTES = (
    "Paper Table III was measured on the paper's **real robot** (camera poses, 50 trials per "
    "row); ours on the `sim` plant. The paper does not define its percentages; ours are the "
    "mean ‖p − p_des‖ over the push relative to the planned arc length, and the mean "
    "|θ − θ_des| relative to |Δθ| (docs/design.md §7).",
    "Paper Table IV prints force in 10⁻¹ N and torque in 10⁻³ N·m; both are converted to mN "
    "and mN·m here. Its *real* columns are the real robot's internal force/torque estimates; "
    "our `proxy` plant (wider parameter ranges, latency, joint friction, a noisy 30 Hz camera) "
    "stands in for that robot and is not one.",
    "Two force references: `force_error_plan` is against the nominal plan's forces (the "
    "paper's), `force_error` against what the plant needed to follow the plan with its true "
    "parameters and plant unknowns (support loads, friction field). A controller that follows "
    "the plan cannot remove the part of `force_error_plan` that comes from parameters it does "
    "not know; `force_error` measures only what the controller could have done "
    "(docs/plant-unknowns.md). `force_error` puts the prongs at the plan's spot on the face; "
    "`force_error_landed` puts them where they landed (0.5 s into the push), which a placement "
    "error moves across the face and no controller moves back without sliding: the split of "
    "the normal forces that spot needs is then the plant's, not the controller's.",
    "Definitions differ: our force error is the mean over steps and prongs of the Euclidean "
    "‖F_des,i − λ_i‖₂ and our torque error |Σ τ_des − Σ τ| of the totals about the centre of "
    "mass; the paper averages 'absolute force and torque deviations' (its eq. 17 weighs "
    "|ΔF_n|, |ΔF_t| and |Δτ_z| per prong). So compare the RL/PD ratios rather than the "
    "absolute values.",
)


def _number(value: float, scale: float = 1.0) -> str:
    return "–" if not math.isfinite(value) else f"{value * scale:.3g}"


def _ours(table: ResultTable, row: int, column: str, scale: float = 1.0) -> str:
    mean = float(table.values[column].iloc[row])
    ci = float(table.values[f"{column}_ci95"].iloc[row])
    if not math.isfinite(mean):
        return "–"
    return _number(mean, scale) + ("" if not math.isfinite(ci) else f" ± {ci * scale:.2g}")


def _counts(table: ResultTable, row: int, columns: list[str]) -> str:
    counts = [int(table.counts[c].iloc[row]) for c in columns]
    return str(counts[0]) if len(set(counts)) == 1 else " / ".join(map(str, counts))


def _ratio(numerator: float, denominator: float) -> str:
    if not (math.isfinite(numerator) and math.isfinite(denominator)) or denominator == 0.0:
        return "–"
    return f"{numerator / denominator:.2f}"


def _cells(table: ResultTable) -> list[tuple[str, str]]:
    return list(zip(table.values["object"], table.values["profile"], strict=True))


def _grid(header: list[str], rows: list[list[str]]) -> list[str]:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return lines + ["| " + " | ".join(r) + " |" for r in rows]


def _value_table(
    table: ResultTable,
    paper: dict[tuple[str, str], dict[str, float]],
    columns: list[tuple[str, str, str | None]],
    scale: float,
    paper_format: str,
) -> list[str]:
    """Rows of object, profile, n, then per (column, heading, paper heading): ours ± CI and
    the paper's value (formatted with ``paper_format``, as printed in the paper; no paper
    column where the paper heading is None: the feedback baseline). Any other controller
    in ``table`` follows, ours only (:func:`_with_others`)."""
    columns = _with_others(table, columns)
    header = ["object", "profile", "n"]
    for _, heading, paper_heading in columns:
        header += [heading] if paper_heading is None else [heading, paper_heading]
    rows = []
    for i, (obj, profile) in enumerate(_cells(table)):
        published = paper.get((obj, profile), {})
        row = [obj, profile, _counts(table, i, [c for c, _, _ in columns])]
        for column, _, paper_heading in columns:
            row.append(_ours(table, i, column, scale))
            if paper_heading is not None:
                row.append(_paper(published.get(column, math.nan) * scale, paper_format))
        rows.append(row)
    return _grid(header, rows)


def _with_others(
    table: ResultTable, columns: list[tuple[str, str, str | None]]
) -> list[tuple[str, str, str | None]]:
    """``columns``, then PD-only's of them for each registered controller outside the
    paper's comparison that ``table`` has, headed by its label (no paper column)."""
    others = []
    for entry in entries():
        for column, heading, _ in columns:
            mine = column.replace("_pd", f"_{entry.name}", 1)
            if not entry.paper and "PD-only" in heading and mine in table.values.columns:
                others.append((mine, heading.replace("PD-only", entry.label), None))
    return columns + others


def _paper(value: float, spec: str) -> str:
    return "–" if not math.isfinite(value) else format(value, spec)


def _ratio_table(
    table: ResultTable,
    paper: dict[tuple[str, str], dict[str, float]],
    pairs: list[tuple[str, str, str]],
    intervals: dict[tuple[str, str, str, str], float] | None = None,
) -> list[str]:
    """Ratio of means per (heading, numerator column, denominator column), ours and, for
    RL/PD, the paper's (the paper has no feedback baseline: RL/feedback is ours only);
    ``intervals``: a CI half-width per (object, profile, numerator, denominator), shown
    as ± (several seeds, :mod:`pushctl.report.seeds`)."""
    header = ["object", "profile"]
    for heading, _, below in pairs:
        header += [f"{heading} (ours)"] + (["paper"] if below.endswith(_PD_SUFFIXES) else [])
    rows = []
    for i, (obj, profile) in enumerate(_cells(table)):
        published = paper.get((obj, profile), {})
        row = [obj, profile]
        for _, above, below in pairs:
            ratio = _ratio(float(table.values[above].iloc[i]), float(table.values[below].iloc[i]))
            ci = (intervals or {}).get((obj, profile, above, below), math.nan)
            row.append(ratio + (f" ± {ci:.2g}" if ratio != "–" and math.isfinite(ci) else ""))
            if below.endswith(_PD_SUFFIXES):
                row.append(_ratio(published.get(above, math.nan), published.get(below, math.nan)))
        rows.append(row)
    return _grid(header, rows)


_PD_SUFFIXES = ("_pd", "_pd_sim", "_pd_proxy")


def _per_seed(seeds: SeedTables | None) -> list[str]:
    """The per-seed section of Table III (also ``table3_seeds.csv``)."""
    assert seeds is not None
    return [
        "Each training seed's own ratios (its RL mean over the trials / PD-only's or "
        "feedback's; also `table3_seeds.csv`):",
        "",
        *seeds_markdown(seeds.per_seed),
        "",
    ]


def _paired(seeds: SeedTables) -> list[str]:
    """The paired RL − feedback section of Table III (:func:`paired_differences`)."""
    table = seeds.paired
    if table.empty:
        return []
    header = ["object", "profile", "plant", "n", "translation RL − feedback", "angle RL − feedback"]
    rows = []
    for row in table.to_dict("records"):
        cells = [str(row["object"]), str(row["profile"]), str(row["plant"])]
        counts = {int(row[f"{metric}_diff_n"]) for metric in PAIRED_METRICS}
        cells.append(" / ".join(str(n) for n in sorted(counts)))
        for metric in PAIRED_METRICS:
            mean, ci = float(row[f"{metric}_diff"]), float(row[f"{metric}_diff_ci95"])
            shown = "–" if not math.isfinite(mean) else f"{mean:+.4f}"
            if math.isfinite(mean) and math.isfinite(ci):
                shown += f" ± {ci:.4f}" + (" (below 0)" if mean + ci < 0.0 else "")
            cells.append(shown)
        rows.append(cells)
    return [
        "RL-assisted − feedback, paired over the trials [percentage points]: the mean over "
        "the cell's n trials of RL's error (its mean over the training seeds) minus "
        "feedback's on the same push, ± the half-width of its 95 % confidence interval over "
        "those trials; '(below 0)': RL lower beyond the interval:",
        "",
        *_grid(header, rows),
        "",
    ]


_T3: list[tuple[str, str, str | None]] = [
    ("translation_error_pd", "translation PD-only", "paper"),
    ("translation_error_feedback", "translation feedback", None),
    ("translation_error_rl", "translation RL", "paper"),
    ("angle_error_pd", "angle PD-only", "paper"),
    ("angle_error_feedback", "angle feedback", None),
    ("angle_error_rl", "angle RL", "paper"),
]
_T3_RATIOS = [
    ("translation RL/PD", "translation_error_rl", "translation_error_pd"),
    ("translation RL/feedback", "translation_error_rl", "translation_error_feedback"),
    ("angle RL/PD", "angle_error_rl", "angle_error_pd"),
    ("angle RL/feedback", "angle_error_rl", "angle_error_feedback"),
]


def _ours_only(columns: list[tuple[str, str, str | None]]) -> list[tuple[str, str, str | None]]:
    """``columns`` without their paper columns (a quantity the paper does not report)."""
    return [(column, heading, None) for column, heading, _ in columns]


def _t4(metric: str) -> list[tuple[str, str, str | None]]:
    return [
        (f"{metric}_pd_sim", "PD-only sim", "paper sim"),
        (f"{metric}_pd_proxy", "PD-only proxy", "paper real"),
        (f"{metric}_feedback_sim", "feedback sim", None),
        (f"{metric}_feedback_proxy", "feedback proxy", None),
        (f"{metric}_rl_sim", "RL sim", "paper sim"),
        (f"{metric}_rl_proxy", "RL proxy", "paper real"),
    ]


_T4_RATIOS = [
    ("force vs plan sim RL/PD", "force_error_plan_rl_sim", "force_error_plan_pd_sim"),
    (
        "force vs plan proxy RL/PD (paper: real)",
        "force_error_plan_rl_proxy",
        "force_error_plan_pd_proxy",
    ),
    ("force vs plan sim RL/feedback", "force_error_plan_rl_sim", "force_error_plan_feedback_sim"),
    (
        "force vs plan proxy RL/feedback",
        "force_error_plan_rl_proxy",
        "force_error_plan_feedback_proxy",
    ),
    ("force vs landed sim RL/PD", "force_error_landed_rl_sim", "force_error_landed_pd_sim"),
    (
        "force vs landed proxy RL/PD",
        "force_error_landed_rl_proxy",
        "force_error_landed_pd_proxy",
    ),
    (
        "force vs landed sim RL/feedback",
        "force_error_landed_rl_sim",
        "force_error_landed_feedback_sim",
    ),
    (
        "force vs landed proxy RL/feedback",
        "force_error_landed_rl_proxy",
        "force_error_landed_feedback_proxy",
    ),
    ("force vs plant sim RL/PD", "force_error_rl_sim", "force_error_pd_sim"),
    ("force vs plant proxy RL/PD", "force_error_rl_proxy", "force_error_pd_proxy"),
    ("force vs plant sim RL/feedback", "force_error_rl_sim", "force_error_feedback_sim"),
    ("force vs plant proxy RL/feedback", "force_error_rl_proxy", "force_error_feedback_proxy"),
    ("torque sim RL/PD", "torque_error_rl_sim", "torque_error_pd_sim"),
    ("torque proxy RL/PD (paper: real)", "torque_error_rl_proxy", "torque_error_pd_proxy"),
    ("torque sim RL/feedback", "torque_error_rl_sim", "torque_error_feedback_sim"),
    ("torque proxy RL/feedback", "torque_error_rl_proxy", "torque_error_feedback_proxy"),
]


def tables_markdown(
    table3: ResultTable,
    table4: ResultTable,
    made_by: str,
    inputs: list[str],
    seeds: SeedTables | None = None,
) -> str:
    """The text of ``tables.md``: its first line the provenance ``made_by`` (the report's
    own ``# made by:`` line) in an HTML comment, then the ``inputs`` with theirs, both
    tables beside the paper's, the RL/PD ratios, and notes on what differs; with
    ``seeds`` of several training seeds, the RL cells and ratios across seeds and a
    per-seed ratio table (:mod:`pushctl.report.seeds`)."""
    cell = (
        "each cell: our mean over the trials ± the half-width of its 95 % confidence "
        "interval over the trials (Student t, n − 1 degrees of freedom), for every controller"
    )
    several = seeds is not None and seeds.several
    intervals = seeds.ratio_ci if seeds is not None and seeds.several else None
    if several:
        assert seeds is not None
        cell += (
            f"; RL's per-trial value is the mean over the {len(seeds.seeds)} training seeds "
            f"({', '.join(map(str, seeds.seeds))}); the spread across seeds is in the CSVs' "
            "`_seed_sd` columns (the seeds' own cell means' standard deviation) and in the "
            "ratio tables' ± (across the seeds' own ratios, Student t, S − 1 degrees of "
            "freedom; docs/several-seeds.md)"
        )
    lines = [
        f"<!-- {made_by.removeprefix('#').strip()} -->",
        "# Tables III and IV: ours beside the paper's",
        "",
        "Inputs:",
        "",
        *[f"- {source}" for source in inputs],
        "",
        f"n: trials behind each mean (finite values; several counts when they differ); {cell}.",
        "",
        "## Table III: tracking error [%], `sim` plant (paper: real robot)",
        "",
        *_value_table(table3, paper_values.TABLE3, _T3, 1.0, ".1f"),
        "",
        "RL-assisted / PD-only and RL-assisted / feedback, the ratios of the means (< 1: "
        "RL-assisted better; the paper has no feedback baseline):",
        "",
        *_ratio_table(table3, paper_values.TABLE3, _T3_RATIOS, intervals),
        "",
        *(_paired(seeds) if seeds is not None else []),
        *(_per_seed(seeds) if several else []),
        "## Table IV: force error [mN] and torque error [mN·m], `sim` and `proxy` plants",
        "",
        "Force error against the nominal plan [mN] (the paper's definition, `force_error_plan`):",
        "",
        *_value_table(table4, paper_values.TABLE4, _t4("force_error_plan"), MILLI, ".0f"),
        "",
        "Force error against what the plant needed [mN] (its true parameters and unknowns, "
        "`force_error`; the paper has no such column):",
        "",
        *_value_table(table4, {}, _ours_only(_t4("force_error")), MILLI, ".0f"),
        "",
        "Force error against what the plant needed with the prongs where they landed [mN] "
        "(`force_error_landed`; the paper has no such column):",
        "",
        *_value_table(table4, {}, _ours_only(_t4("force_error_landed")), MILLI, ".0f"),
        "",
        "Torque error [mN·m]:",
        "",
        *_value_table(table4, paper_values.TABLE4, _t4("torque_error"), MILLI, ".2f"),
        "",
        "RL-assisted / PD-only and RL-assisted / feedback, the ratios of the means (< 1: "
        "RL-assisted better):",
        "",
        *_ratio_table(table4, paper_values.TABLE4, _T4_RATIOS, intervals),
        "",
        "## How to read the comparison",
        "",
        *[f"- {note}" for note in NOTES],
        "- The paper's values are transcribed from its text in `pushctl/report/paper_values.py`.",
        "",
    ]
    return "\n".join(lines)

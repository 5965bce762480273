"""``pushctl report``: Tables III and IV, ``tables.md`` and Figs. 5, 6 and 8 from a results
directory (Fig. 5 only when it holds a training curve). The command is
:mod:`pushctl.cli.report`.

Every input is read and checked, both tables computed and all three figures rendered to
PNG bytes before the first file is written; the files are then written each to a temporary
file, and renamed over the old ones only once all are written (see :func:`write_chain`),
so a failure anywhere leaves the output directory as it was.
"""

from __future__ import annotations

import io
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
from matplotlib.figure import Figure
from rich.table import Table

from pushctl.controllers import controller_entry, controller_names
from pushctl.errors import ConfigError
from pushctl.files.provenance import provenance_line, write_atomic, write_csv
from pushctl.report.figures import force_error_figure, tracking_figure, training_figure
from pushctl.report.inputs import CURVE, ReportInputs, ResultsTable, read_report_inputs, summary
from pushctl.report.markdown import tables_markdown
from pushctl.report.seeds import across_seeds, seed_tables
from pushctl.report.tables import (
    INTERVALS_NOTE,
    ResultTable,
    behaviour_table,
    table3_proxy,
)

TABLE3_FILE = "table3.csv"
TABLE4_FILE = "table4.csv"
SEEDS_FILE = "table3_seeds.csv"
TABLE3_PROXY_FILE = "table3_proxy.csv"
BEHAVIOUR_FILE = "behaviour.csv"
"""Each training seed's own Table III means and RL/PD, RL/feedback ratios per cell."""
MARKDOWN_FILE = "tables.md"
FIG5_FILE = "fig5_training.png"
FIG6_FILE = "fig6_tracking.png"
FIG8_FILE = "fig8_force_error.png"
DPI = 150


@dataclass(frozen=True)
class Report:
    """Everything ``pushctl report`` writes, held in memory: the two tables and their
    ``# made by:`` line, the Markdown text, and each figure's PNG bytes by file name."""

    table3: ResultTable
    table4: ResultTable
    table_provenance: str
    markdown: str
    figures: dict[str, bytes]
    notes: tuple[str, ...] = ()
    """What the inputs could not give, one line each (Fig. 5 without a training curve)."""
    warnings: tuple[str, ...] = ()
    """What mixes results that do not belong together (another run's Fig. 5), one line each."""
    per_seed: pd.DataFrame | None = None
    """``table3_seeds.csv`` (:func:`~pushctl.report.seeds.seed_ratios`), written only when
    the trials hold several training seeds."""
    more: dict[str, ResultTable] | None = None
    """``table3_proxy.csv`` (Table III on the proxy, RL across seeds as Table III) and
    ``behaviour.csv`` (slip, contact-loss and gate-open shares), by file name."""

    @property
    def files(self) -> list[str]:
        seeds = [SEEDS_FILE] if self.per_seed is not None else []
        more = list(self.more or {})
        return [TABLE3_FILE, TABLE4_FILE, *more, *seeds, MARKDOWN_FILE, *self.figures]


def hidden_lines(steps: pd.DataFrame) -> str | None:
    """Which controller's lines in Figs. 6 and 8 lie exactly on another's (equal values at
    every step of every cell, so only the one drawn last shows), or None."""
    keys = ["object", "profile", "plant", "step"]
    values = [c for c in steps.columns if c not in (*keys, "controller", "t")]
    frames = {
        name: group.set_index(keys)[values].sort_index()
        for name, group in steps.groupby("controller", sort=False)
    }
    pairs = []
    names = [n for n in controller_names() if n in frames]
    for i, under in enumerate(names):
        for over in names[i + 1 :]:
            a, b = frames[under], frames[over]
            if a.index.equals(b.index) and a.equals(b):
                pairs.append(
                    f"{controller_entry(over).label}'s lie exactly on "
                    f"{controller_entry(under).label}'s"
                )
    if not pairs:
        return None
    return f"in Figs. 6 and 8, {'; '.join(pairs)} (equal values): one line shows for both"


def unmatched_training(inputs: ReportInputs) -> str | None:
    """Why Fig. 5's training run is not the one whose policy the tables evaluated (the
    trials' provenance names each evaluated policy's own line, the curve's run has one), or
    None when it is, or when no policy was evaluated or there is no curve."""
    trials, curve = inputs.trials, inputs.curve
    if curve is None or trials.made_by is None or "; policy " not in trials.made_by:
        return None
    if curve.made_by is not None and curve.made_by in trials.made_by:
        return None
    return (
        f"Fig. 5 shows the training run of {curve.path} ({summary(curve.made_by, 120)}), but "
        f"the tables' RL rows evaluated another policy (see {trials.path}'s first line): "
        "report them apart, or evaluate that run's policy.pt"
    )


def _source(table: ResultsTable) -> str:
    """``path [its made-by line, shortened]``, for another file's provenance."""
    return f"{table.path} [{summary(table.made_by)}]"


def _png(figure: Figure, description: str) -> bytes:
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=DPI, metadata={"Description": description})
    return buffer.getvalue()


def make_report(in_dir: Path, command: str, trust_undigested: bool = False) -> Report:
    """Read and check ``in_dir``'s inputs, compute the tables and render the figures;
    ``command`` is the invocation for the provenance lines. Raises
    :class:`~pushctl.report.inputs.ResultsFileError` for a bad input; writes nothing."""
    inputs = read_report_inputs(in_dir, trust_undigested=trust_undigested)
    made_by = provenance_line(command)
    seeds = seed_tables(inputs.trials.frame)
    three, four = seeds.table3, seeds.table4
    sources = [_source(t) for t in inputs.tables()]
    markdown = tables_markdown(three, four, made_by, sources, seeds)
    drawings = [
        (FIG6_FILE, tracking_figure(inputs.steps.frame), inputs.steps),
        (FIG8_FILE, force_error_figure(inputs.steps.frame), inputs.steps),
    ]
    notes, warnings = [], []
    hidden = hidden_lines(inputs.steps.frame)
    if hidden is not None:
        notes.append(hidden)
    other_run = unmatched_training(inputs)
    if other_run is not None:
        warnings.append(other_run)
    if inputs.curve is not None:
        drawings.insert(0, (FIG5_FILE, training_figure(inputs.curve.frame), inputs.curve))
    else:
        notes.append(f"no {CURVE} in {in_dir}: Fig. 5 (training curves) not drawn")
    figures = {}
    for name, figure, source in drawings:
        title = " ".join(figure.get_suptitle().split())
        hides = f" Note: {hidden}." if hidden is not None and name != FIG5_FILE else ""
        figures[name] = _png(figure, f"{title}.{hides} {made_by}; input: {_source(source)}")
    return Report(
        table3=three,
        table4=four,
        table_provenance=f"{made_by}; inputs: {_source(inputs.trials)}\n{INTERVALS_NOTE}",
        markdown=markdown,
        figures=figures,
        notes=tuple(notes),
        warnings=tuple(warnings),
        per_seed=seeds.per_seed if seeds.several else None,  # one seed: as before
        more={
            TABLE3_PROXY_FILE: (
                across_seeds(inputs.trials.frame, table3_proxy, seeds.seeds)
                if seeds.several
                else table3_proxy(inputs.trials.frame)
            ),
            BEHAVIOUR_FILE: (
                across_seeds(inputs.trials.frame, behaviour_table, seeds.seeds)
                if seeds.several
                else behaviour_table(inputs.trials.frame)
            ),
        },
    )


def write_chain(steps: list[Callable[[Callable[[], None]], None]]) -> None:
    """Run ``steps`` nested: each writes its temporary file, calls the next, and renames its
    file only when the next has returned. Every file is written before the first rename,
    and a failure while writing renames none."""

    def run(i: int) -> None:
        if i < len(steps):
            steps[i](lambda: run(i + 1))

    run(0)


def check_out_dir(out_dir: Path) -> None:
    """ConfigError if ``out_dir`` exists and is not a directory (checked before the work)."""
    if out_dir.exists() and not out_dir.is_dir():
        raise ConfigError(f"--out {out_dir} is a file; give a directory")


def report_paths(out_dir: Path) -> list[Path]:
    """Every file ``pushctl report`` writes into ``out_dir`` (its results directory also
    holds its inputs, so the check is per file, not on the directory)."""
    names = (
        TABLE3_FILE,
        TABLE4_FILE,
        TABLE3_PROXY_FILE,
        BEHAVIOUR_FILE,
        SEEDS_FILE,
        MARKDOWN_FILE,
        FIG5_FILE,
        FIG6_FILE,
        FIG8_FILE,
    )
    return [out_dir / name for name in names]


def write_report(report: Report, out_dir: Path) -> list[Path]:
    """Write ``report`` into ``out_dir`` (created if missing); returns the paths written."""
    check_out_dir(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    steps: list[Callable[[Callable[[], None]], None]] = []
    tables = [(TABLE3_FILE, report.table3), (TABLE4_FILE, report.table4)]
    for name, table in [*tables, *(report.more or {}).items()]:
        steps.append(_csv_step(out_dir / name, table.values, report.table_provenance))
    if report.per_seed is not None:
        steps.append(_csv_step(out_dir / SEEDS_FILE, report.per_seed, report.table_provenance))
    steps.append(_bytes_step(out_dir / MARKDOWN_FILE, report.markdown.encode()))
    for name, data in report.figures.items():
        steps.append(_bytes_step(out_dir / name, data))
    write_chain(steps)
    return [out_dir / name for name in report.files]


def _csv_step(
    path: Path, frame: pd.DataFrame, made_by: str
) -> Callable[[Callable[[], None]], None]:
    def step(then: Callable[[], None]) -> None:
        write_csv(path, frame, made_by, before_rename=then)

    return step


def _bytes_step(path: Path, data: bytes) -> Callable[[Callable[[], None]], None]:
    def step(then: Callable[[], None]) -> None:
        def write(tmp: Path) -> None:
            tmp.write_bytes(data)
            then()

        write_atomic(path, write)

    return step


def counts_table(report: Report) -> Table:
    """Trials behind the tables, per (object, profile): Table III's sim and Table IV's sim
    and proxy columns (the smallest count of each group's columns that have trials)."""
    table = Table(title="trials per table cell")
    for column in ("object", "profile", "Table III (sim)", "Table IV (sim + proxy)"):
        table.add_column(column, justify="left" if column in ("object", "profile") else "right")
    c3, c4 = report.table3.counts, report.table4.counts
    for i in range(len(c3)):
        n3 = _fewest([int(c3[c].iloc[i]) for c in report.table3.value_columns])
        n4 = _fewest([int(c4[c].iloc[i]) for c in report.table4.value_columns])
        table.add_row(str(c3["object"].iloc[i]), str(c3["profile"].iloc[i]), str(n3), str(n4))
    return table


def _fewest(counts: list[int]) -> int:
    """The smallest count of the columns that have trials (an evaluation without, say, the
    feedback controller leaves its columns at 0); 0 if none has."""
    present = [n for n in counts if n > 0]
    return min(present) if present else 0

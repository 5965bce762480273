"""Reading and checking the CSVs ``pushctl report`` is made from.

``IN/evaluation/trials.csv`` and ``IN/evaluation/steps.csv`` come from ``pushctl evaluate``
and ``IN/training/curve.csv``, when there is one, from ``pushctl train`` (their columns:
docs/evaluation.md, *Tables and figures* section). ``IN`` may also be the evaluation
directory itself (``IN/trials.csv``), with no training beside it. Every file is read whole
and checked before anything is computed: a missing, empty or malformed file (a missing
column, no data rows, a value that is not a number, a plant or controller name not in the
interface, a duplicated row) raises :class:`ResultsFileError` with one line naming the file
and what is wrong.

Only the columns the report uses are required, so a file with extra columns still works.
"""

from __future__ import annotations

import csv
import gzip
import io
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from pushctl.config import PLANT_KINDS
from pushctl.controllers import controller_names
from pushctl.errors import ConfigError
from pushctl.evaluation.columns import STEP_COLUMNS
from pushctl.files.provenance import csv_digest_problem
from pushctl.report.completeness import check_complete

TRIALS = Path("evaluation") / "trials.csv"
STEPS = Path("evaluation") / "steps.csv"
CURVE = Path("training") / "curve.csv"

PLANTS = PLANT_KINDS  # pushctl.config: one definition for the simulator and the report
CURVE_METRICS = ("force_n_error", "force_t_error", "torque_error")
"""The per-episode errors of Fig. 5 [N, N, N·m], each as ``rl_<m>`` and ``pd_<m>``."""


PUSHCTL_MADE_BY = b"# made by: pushctl "
"""How a CSV that pushctl wrote begins (:func:`pushctl.files.provenance.provenance_line`)."""
TRUST_OPTION = "--trust-undigested"


class ResultsFileError(ConfigError):
    """A results file the report cannot use; the message names the file and the problem."""


@dataclass(frozen=True)
class CsvSpec:
    """The columns a results file must have: ``labels`` (non-empty text), ``numbers``
    (finite), ``optional_numbers`` (numbers or empty: NaN), ``choices`` (column → accepted
    values, or a function giving them when a file is read: the registered controllers) and
    ``key`` (columns no two rows may share)."""

    what: str
    labels: tuple[str, ...]
    numbers: tuple[str, ...]
    optional_numbers: tuple[str, ...] = ()
    choices: tuple[tuple[str, tuple[str, ...] | Callable[[], tuple[str, ...]]], ...] = ()
    key: tuple[str, ...] = ()
    if_present: tuple[str, ...] = ()
    """Numbers or empty, in files that have the column (older ones lack it); part of the
    key there."""
    rest_numbers: bool = False
    """Every other column holds numbers or empty cells (the report may use any of them)."""

    @property
    def columns(self) -> tuple[str, ...]:
        return self.labels + self.numbers + self.optional_numbers


_GROUP = ("object", "profile", "plant", "controller")
_CHOICES = (("plant", PLANTS), ("controller", controller_names))

TRIALS_SPEC = CsvSpec(
    what="per-trial metrics from `pushctl evaluate`",
    labels=_GROUP,
    numbers=("trial", "force_error", "torque_error"),
    # NaN by definition for a straight push (angle) or a zero-length arc (translation)
    optional_numbers=("translation_error_pct", "angle_error_pct"),
    choices=_CHOICES,
    key=(*_GROUP, "trial"),
    if_present=("policy_seed",),  # several policies: one rl row per trial and seed
    rest_numbers=True,
)
STEPS_SPEC = CsvSpec(
    what="per-step means from `pushctl evaluate`",
    labels=_GROUP,
    numbers=("step", "t"),
    optional_numbers=STEP_COLUMNS,
    choices=_CHOICES,
    key=(*_GROUP, "step"),
)
CURVE_SPEC = CsvSpec(
    what="training curve from `pushctl train`",
    labels=(),
    numbers=("episode", *(f"rl_{m}" for m in CURVE_METRICS)),
    # PD-only runs on every n-th episode only: empty elsewhere
    optional_numbers=tuple(f"pd_{m}" for m in CURVE_METRICS),
    key=("episode",),
)


@dataclass(frozen=True)
class ResultsTable:
    """One checked input: its ``frame`` (numbers as float64, labels as str), its ``path``
    and its ``# made by:`` line without the ``#`` (None if it has none)."""

    path: Path
    frame: pd.DataFrame
    made_by: str | None


@dataclass(frozen=True)
class ReportInputs:
    """The inputs of the report: the evaluation's two tables and, when the results
    directory holds a training run, its curve (None without one)."""

    trials: ResultsTable
    steps: ResultsTable
    curve: ResultsTable | None

    def tables(self) -> tuple[ResultsTable, ...]:
        curve = () if self.curve is None else (self.curve,)
        return (self.trials, self.steps, *curve)


def read_report_inputs(directory: Path, *, trust_undigested: bool = False) -> ReportInputs:
    """Read and check ``directory``'s trials, steps and (if present) curve CSVs (see the
    module docstring); raises :class:`ResultsFileError` for the first problem found."""
    directory = Path(directory)
    if not directory.is_dir():
        raise ResultsFileError(
            f"{directory}: no such directory; expected a results directory holding "
            f"{TRIALS} and {STEPS} (and {CURVE} for Fig. 5), or an evaluation directory"
        )
    evaluation = directory / TRIALS.parent
    if not (evaluation / TRIALS.name).exists() and (directory / TRIALS.name).is_file():
        evaluation = directory  # the evaluation directory itself
    steps = evaluation / STEPS.name
    if not steps.exists() and _gzipped(steps).is_file():
        steps = _gzipped(steps)  # a shipped results directory keeps it compressed (11 MB → 3.5)
    curve = directory / CURVE
    trust = trust_undigested
    trials = read_results_csv(evaluation / TRIALS.name, TRIALS_SPEC, trust_undigested=trust)
    check_complete(trials.path, trials.frame, trials.made_by)  # not cut short
    return ReportInputs(
        trials=trials,
        steps=read_results_csv(steps, STEPS_SPEC, trust_undigested=trust),
        curve=read_results_csv(curve, CURVE_SPEC, trust_undigested=trust)
        if curve.exists()
        else None,
    )


def _gzipped(path: Path) -> Path:
    return path.with_name(path.name + ".gz")


def read_results_csv(path: Path, spec: CsvSpec, *, trust_undigested: bool = False) -> ResultsTable:
    """Read ``path`` (a CSV with an optional leading ``# made by:`` line; gzip-compressed if
    its name ends in ``.gz``) and check it against ``spec``; raises :class:`ResultsFileError`.
    A file pushctl wrote (its first line ``# made by: pushctl …``) must end in its digest,
    unless ``trust_undigested``; a file made by hand (no such line) is taken as it is."""
    if not path.is_file():
        problem = "is a directory" if path.is_dir() else "no such file"
        raise ResultsFileError(f"{path}: {problem}; expected the {spec.what}")
    try:
        data = gzip.decompress(path.read_bytes()) if path.suffix == ".gz" else path.read_bytes()
        ours = data.startswith(PUSHCTL_MADE_BY)
        damage = csv_digest_problem(data, required=ours and not trust_undigested)
        if damage is not None:
            advice = f"; pass {TRUST_OPTION} if you trust it" if "no digest" in damage else ""
            raise ResultsFileError(f"{path}: {damage}{advice}; expected the {spec.what}")
        text = data.decode()
        first = text.partition("\n")[0].strip()
        _check_row_lengths(path, text)
        raw = pd.read_csv(
            io.StringIO(text), comment="#", dtype=str, keep_default_na=False, index_col=False
        )
    except (UnicodeDecodeError, gzip.BadGzipFile, EOFError):
        raise ResultsFileError(f"{path}: not a text file; expected the {spec.what}") from None
    except pd.errors.EmptyDataError:
        raise ResultsFileError(
            f"{path}: empty file; expected the {spec.what} with a header line"
        ) from None
    except (pd.errors.ParserError, csv.Error) as error:
        detail = str(error).strip().splitlines()[-1]
        raise ResultsFileError(f"{path}: not a well-formed CSV ({detail})") from None
    except OSError as error:
        raise ResultsFileError(f"{path}: cannot read it ({error.strerror})") from None
    made_by = first[1:].strip() if first.startswith("# made by:") else None
    frame = _checked(path, raw.fillna(""), spec)
    return ResultsTable(path=path, frame=frame, made_by=made_by)


def _check_row_lengths(path: Path, text: str) -> None:
    """Every data row of ``path``'s ``text`` has as many fields as the header (pandas would
    silently turn extra leading fields into an index, or pad a short row)."""
    lines = (line for line in text.splitlines(True) if line.strip() and not line.startswith("#"))
    rows = csv.reader(lines)
    header = next(rows, None)
    if header is None:
        return  # empty: pandas names it
    for number, row in enumerate(rows, start=1):
        if len(row) != len(header):
            raise ResultsFileError(
                f"{path}: not a well-formed CSV (data row {number} has {len(row)} fields, "
                f"the header {len(header)})"
            )


def _checked(path: Path, raw: pd.DataFrame, spec: CsvSpec) -> pd.DataFrame:
    """``raw`` (all text) with its numbers parsed, once every rule of ``spec`` holds."""
    missing = [c for c in spec.columns if c not in raw.columns]
    if missing:
        raise ResultsFileError(
            f"{path}: missing column(s) {', '.join(missing)}; expected the {spec.what} "
            f"with columns {', '.join(spec.columns)}"
        )
    if raw.empty:
        raise ResultsFileError(f"{path}: no data rows; expected the {spec.what}")
    frame = raw.copy()
    for column in spec.labels:
        values = frame[column].str.strip()
        _reject(path, column, values == "", values, "an empty value")
        frame[column] = values
    for column, choices in spec.choices:
        accepted = choices() if callable(choices) else choices
        bad = ~frame[column].isin(accepted)
        _reject(path, column, bad, frame[column], f"not one of {'|'.join(accepted)}")
    for column in spec.numbers + spec.optional_numbers:
        frame[column] = _numbers(path, column, frame[column], column in spec.numbers)
    present = [c for c in spec.if_present if c in frame.columns]
    for column in present:
        frame[column] = _numbers(path, column, frame[column], False)
    if spec.rest_numbers:
        named = {*spec.labels, *spec.columns, *present}
        for column in [c for c in frame.columns if c not in named]:
            _numbers(path, column, frame[column], False)  # checked; the text is kept
    if spec.key:
        key_columns = [*spec.key, *present]
        duplicated = frame.duplicated(key_columns, keep="first")
        if duplicated.any():
            row = int(np.flatnonzero(duplicated.to_numpy())[0])
            key = ", ".join(f"{c}={frame[c].iloc[row]}" for c in key_columns)
            raise ResultsFileError(f"{path}: data row {row + 1} repeats ({key})")
    return frame


def _numbers(path: Path, column: str, text: pd.Series, required: bool) -> pd.Series:
    """``text`` as float64; an empty cell is NaN if not ``required``; anything else that is
    not a finite number is an error."""
    text = text.str.strip()
    empty = text.isin(("", "nan", "NaN"))
    values = pd.to_numeric(text.where(~empty, "nan"), errors="coerce").astype(float)
    _reject(path, column, values.isna() & ~empty, text, "not a number")
    _reject(path, column, np.isinf(values.to_numpy()), text, "not finite")
    if required:
        _reject(path, column, empty, text, "an empty value")
    return values


def _reject(
    path: Path, column: str, bad: pd.Series | np.ndarray, text: pd.Series, why: str
) -> None:
    """Raise for the first row where ``bad`` holds, quoting the cell."""
    flags = np.asarray(bad, dtype=bool)
    if flags.any():
        row = int(np.flatnonzero(flags)[0])
        cell = str(text.iloc[row])
        shown = cell if len(cell) <= 40 else cell[:37] + "..."
        raise ResultsFileError(f"{path}: column {column}, data row {row + 1}: {shown!r} is {why}")


def summary(made_by: str | None, limit: int = 400) -> str:
    """A ``# made by:`` line shortened for another file's provenance: without the leading
    ``made by:`` and the pushctl version field (the command, commit, seeds and the rest
    kept), cut at ``limit`` characters; ``no provenance line`` if there is none."""
    if made_by is None:
        return "no provenance line"
    fields = made_by.removeprefix("made by:").strip().split("; ")
    text = "; ".join(f for f in fields if not re.fullmatch(r"pushctl \d[\w.+-]*", f))
    return text if len(text) <= limit else text[: limit - 1] + "…"

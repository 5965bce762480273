"""``python -m benchmarks.realdata_replay``: bad arguments are one-line errors; a small run
times each facet count against the first."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from benchmarks.realdata_replay import main, study

REAL_DATA = Path(
    os.environ.get(
        "PUSHCTL_REALDATA", Path(__file__).resolve().parents[2] / ".." / "shared" / "realdata"
    )
)


@pytest.mark.parametrize("argv", [["--per-group", "0"], ["--repeats", "0"], ["--facets", "8,x"]])
def test_bad_arguments_are_one_line_errors(capsys, tmp_path, argv) -> None:
    assert main(["--data", str(tmp_path), *argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --per-group and --repeats") and err.count("\n") == 1


def test_a_missing_data_directory_is_a_one_line_error(capsys, tmp_path) -> None:
    assert main(["--data", str(tmp_path / "none")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --data:") and err.count("\n") == 1


def test_each_facet_count_is_timed_against_the_first() -> None:
    if not (REAL_DATA / "mit" / "pushes.csv").is_file():
        pytest.skip(f"the recorded pushes are not at {REAL_DATA}")
    table = study(REAL_DATA, per_group=1, facets=[8, 16], repeats=1)
    assert list(table["facets"]) == [8, 16]
    assert (table["pushes"] == 20).all() and (table["ms_per_push"] > 0).all()
    assert table["over_8_gon"].iloc[0] == 1.0

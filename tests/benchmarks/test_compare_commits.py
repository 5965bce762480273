"""``python -m benchmarks.compare_commits``: one entry for the side-by-side comparisons with
another commit, each forwarded its own arguments; none of it is part of ``make bench``."""

from __future__ import annotations

from pathlib import Path

import pytest

from benchmarks import compare_commits

ROOT = Path(__file__).resolve().parents[2]


def test_what_to_compare_is_required_and_named(capsys) -> None:
    assert compare_commits.main([]) == 2
    assert compare_commits.main(["speed"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err == [
        "error: give what to compare, one of step, evaluate, train; got nothing",
        "error: give what to compare, one of step, evaluate, train; got 'speed'",
    ]


@pytest.mark.parametrize("what", sorted(compare_commits.BENCHES))
def test_each_comparison_gets_its_arguments_and_needs_a_commit(what: str, capsys) -> None:
    with pytest.raises(SystemExit) as stopped:  # argparse: --against is required
        compare_commits.main([what, "--repeats", "1"])
    assert stopped.value.code == 2
    assert "--against" in capsys.readouterr().err
    assert compare_commits.main([what, "--against", "HEAD", "--repeats", "0"]) == 2


def test_make_bench_compares_with_no_other_commit() -> None:
    """``make bench`` works in a shallow clone: it names no commit and runs no comparison."""
    makefile = (ROOT / "Makefile").read_text()
    recipe = makefile.split("\nbench:", 1)[1].split("\n\n", 1)[0]
    assert "benchmarks.suite" in recipe
    assert "compare_commits" not in recipe and "--against" not in recipe
